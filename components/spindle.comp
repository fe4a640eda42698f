component spindle "Spindle drive control: speed ramps, speed limits and gear ranges for a drive with forward and reverse inputs";

description """
Drives a spindle that has no servo loop of its own, such as an inverter or a
DC drive with separate forward and reverse inputs, from a commanded speed in
RPM.  The speed sent to the drive (\\fBoutput\\fR) changes at a limited rate
so that the spindle speeds up at the acceleration and slows down at the
deceleration of the selected gear.

\\fBNote:\\fR the motion controller creates pins with very similar names
(\\fBspindle.\\fIN\\fB.*\\fR); this is a separate component.  See motion(9)
for those.

\\fBWith an encoder\\fR (\\fBsimulate-encoder\\fR FALSE) the speed measured
on \\fBactual-speed\\fR is the starting point of every step: each period the
drive is sent the measured speed plus \\fBaccel.\\fIx\\fR (or minus
\\fBdecel.\\fIx\\fR), in RPM, never beyond the commanded speed.  A heavily
loaded spindle that lags behind is therefore not driven far ahead of what
it can do.  \\fBWithout an encoder\\fR (\\fBsimulate-encoder\\fR TRUE) the
speed sent in the previous period stands in for the measured one and
\\fBaccel.\\fIx\\fR and \\fBdecel.\\fIx\\fR are rates in RPM per second.
An acceleration or deceleration of 0 (or less) means no limit: the speed
goes straight to its target.

A spindle running against the commanded direction is first slowed down to
0 at the deceleration, then sped up the other way at the acceleration.
When the measured speed is within \\fBspeed-tolerance.\\fIx\\fR of the
commanded speed, \\fBat-speed\\fR is TRUE and the target speed is sent as
it is.  When \\fBenable\\fR is FALSE the commanded speed counts as 0.

The commanded speed is limited, whatever its sign, to at least
\\fBmin.\\fIx\\fR (a command of 0 stays 0) and at most \\fBmax.\\fIx\\fR
(\\fBmax.\\fIx\\fR 0: no upper limit); \\fBlimited\\fR tells when that
changed it.  \\fBat-speed\\fR compares with the command before this
limiting.

\\fBoutput\\fR is (|speed| + \\fBoffset.\\fIx\\fR) * \\fBscale.\\fIx\\fR:
the direction goes to the drive on \\fBforward\\fR and \\fBreverse\\fR.
\\fBforward\\fR is TRUE while the speed sent is above 0 and \\fBreverse\\fR
while it is below 0.  With a command of 0 (or \\fBenable\\fR FALSE)
\\fBreverse\\fR is FALSE and \\fBforward\\fR may only stay TRUE while the
spindle slows down from forward (as LinuxCNC's spindle component does).
""";

notes """
The load line takes \\fBnumgears=\\fR, the number of gears of each instance
(1 to 16, comma separated; an instance without a value has 1 gear), e.g.
\\fBloadrt spindle count=2 numgears=3,2\\fR.  Each gear \\fIx\\fR (from 0)
of an instance has these input pins:
.TP
\\fBspindle.\\fIN\\fB.scale.\\fIx\\fR float in (default: 1)
Factor from speed (RPM) to \\fBoutput\\fR in gear \\fIx\\fR; negative to
make the output negative.
.TP
\\fBspindle.\\fIN\\fB.offset.\\fIx\\fR float in (default: 0)
Added to the absolute speed (RPM) before scaling.
.TP
\\fBspindle.\\fIN\\fB.min.\\fIx\\fR float in (default: 0)
Lowest speed (RPM) a non-zero command is raised to.
.TP
\\fBspindle.\\fIN\\fB.max.\\fIx\\fR float in (default: 0)
Highest speed (RPM) allowed; 0 for no limit.
.TP
\\fBspindle.\\fIN\\fB.accel.\\fIx\\fR float in (default: 0)
Speed increase: RPM per period above the measured speed with an encoder,
RPM per second without; 0 for no limit.
.TP
\\fBspindle.\\fIN\\fB.decel.\\fIx\\fR float in (default: 0)
Speed decrease, in the same units as \\fBaccel.\\fIx\\fR.
.TP
\\fBspindle.\\fIN\\fB.speed-tolerance.\\fIx\\fR float in (default: 20)
\\fBat-speed\\fR is TRUE when the speed is within this many RPM of the command.
.TP
\\fBspindle.\\fIN\\fB.zero-tolerance.\\fIx\\fR float in (default: 20)
\\fBzero-speed\\fR is TRUE when the speed is within this many RPM of 0.
.TP
\\fBspindle.\\fIN\\fB.select.\\fIx\\fR bit in (default: TRUE for a single gear, else FALSE)
Selects gear \\fIx\\fR while \\fBselect-gear\\fR is 0; of several, the highest wins.
""";

pin in u32 select_gear "Gear to use (0 to gears - 1); when 0, the select.x pins choose";
pin in float commanded_speed "Commanded speed, RPM; negative for reverse";
pin in float actual_speed "Speed measured by a spindle encoder, in revolutions per second (not RPM)";
pin in bit simulate_encoder "TRUE when there is no encoder: the speed sent stands in for the measured one";
pin in bit enable "FALSE makes the commanded speed 0: the spindle slows down to a stop";
pin in float spindle_lpf "Smoothing of spindle-rpm-abs while at speed, in 1/s (e.g. 1 to 20); 0 for none";

pin out float spindle_rpm "Spindle speed, RPM, signed: measured with an encoder, else the speed sent";
pin out float spindle_rpm_abs "Absolute measured (or, without encoder, last sent) speed, RPM, smoothed by spindle-lpf while at speed; for speed displays";
pin out float output "Speed command for the drive: (|speed| + offset) * scale of the current gear";
pin out u32 current_gear "The gear in use";
pin out bit at_speed "TRUE when the speed is within speed-tolerance of the command";
pin out bit forward "TRUE to run the drive forward";
pin out bit reverse "TRUE to run the drive in reverse; forward and reverse are both FALSE when stopped";
pin out bit brake "Always FALSE: kept for compatibility with LinuxCNC's spindle component, which never sets it";
pin out bit zero_speed "TRUE when the speed is within zero-tolerance of 0";
pin out bit limited "TRUE when min or max of the gear changed the commanded speed";

variable int ngears;
variable float speed;     /* measured speed, or without encoder the last one sent */
variable hal_float_t *g_scale[16];
variable hal_float_t *g_min[16];
variable hal_float_t *g_max[16];
variable hal_float_t *g_accel[16];
variable hal_float_t *g_decel[16];
variable hal_float_t *g_stol[16];
variable hal_float_t *g_ztol[16];
variable hal_float_t *g_offset[16];
variable hal_bit_t *g_select[16];

modparam dummy numgears "Number of gears of each instance, 1 to 16, comma separated (default 1)";

function _ "Select the gear, ramp the speed and update the outputs";

option extra_setup;

see_also "motion(9)";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

#define MAX_GEARS 16

/* entries not given on the load line keep 1 gear */
static int numgears[MAX_GEARS] = {1, 1, 1, 1, 1, 1, 1, 1,
                                  1, 1, 1, 1, 1, 1, 1, 1};
RTAPI_MP_ARRAY_INT(numgears, MAX_GEARS, "number of gears of each instance");

static int float_pin(hal_float_t **p, char *prefix, const char *name,
                     int i, double dflt)
{
    int r = hal_pin_float_newf(HAL_IN, p, comp_id, "%s.%s.%d",
                               prefix, name, i);
    if (r == 0)
        **p = dflt;
    return r;
}

EXTRA_SETUP() {
    int n, i, r = 0;

    n = extra_arg < MAX_GEARS ? numgears[extra_arg] : 1;
    if (n < 1 || n > MAX_GEARS) {
        rtapi_print_msg(RTAPI_MSG_ERR, "Number of gears is out of range\n");
        return -EINVAL;
    }
    ngears = n;
    for (i = 0; i < n && r == 0; i++) {
        r = float_pin(&g_scale[i], prefix, "scale", i, 1.0);
        if (!r) r = float_pin(&g_min[i], prefix, "min", i, 0.0);
        if (!r) r = float_pin(&g_max[i], prefix, "max", i, 0.0);
        if (!r) r = float_pin(&g_accel[i], prefix, "accel", i, 0.0);
        if (!r) r = float_pin(&g_decel[i], prefix, "decel", i, 0.0);
        if (!r) r = float_pin(&g_stol[i], prefix, "speed-tolerance", i, 20.0);
        if (!r) r = float_pin(&g_ztol[i], prefix, "zero-tolerance", i, 20.0);
        if (!r) r = float_pin(&g_offset[i], prefix, "offset", i, 0.0);
        if (!r) {
            r = hal_pin_bit_newf(HAL_IN, &g_select[i], comp_id, "%s.select.%d",
                                 prefix, i);
            if (!r)
                *g_select[i] = (n == 1);    /* a lone gear is selected */
        }
    }
    return r;
}

FUNCTION(_) {
    unsigned g = select_gear;
    float cmd, t, a, r, up, dn, mn, mx;
    double k;
    int i, sim = simulate_encoder, was_at = at_speed, at;

    /* the gear: select-gear, else the highest select.x pin */
    if (g == 0) {
        for (i = 0; i < ngears; i++)
            if (*g_select[i])
                g = i;
    }
    if (g >= (unsigned)ngears)
        g = ngears - 1;
    current_gear = g;

    /* the command, then the target limited to min..max of the gear */
    cmd = enable ? commanded_speed : 0.0;
    t = cmd;
    limited = 0;
    if (t != 0.0) {
        mn = *g_min[g];
        mx = *g_max[g];
        if (fabs(t) < mn) {
            t = t > 0 ? mn : -mn;
            limited = 1;
        }
        if (mx > 0 && fabs(t) > mx) {
            t = t > 0 ? mx : -mx;
            limited = 1;
        }
    }

    /* the speed now: measured, or the one sent last period; like the
       reference, the speeds are worked out in single precision */
    if (!sim)
        speed = actual_speed * 60.0;
    a = speed;

    k = spindle_lpf;
    if (k > 0 && was_at)
        spindle_rpm_abs += (fabs(a) - spindle_rpm_abs) * k * fperiod;
    else
        spindle_rpm_abs = fabs(a);

    at = fabs(a - cmd) <= *g_stol[g];
    at_speed = at;
    zero_speed = fabs(a) <= *g_ztol[g];

    /* one step towards the target; with an encoder the steps are RPM
       above/below the measured speed, without one RPM per second */
    up = *g_accel[g];
    dn = *g_decel[g];
    if (sim) {
        up *= fperiod;
        dn *= fperiod;
    }
    if (at || t == a) {
        r = t;
    } else if (t > a) {
        if (a >= 0) {               /* speeding up forward */
            r = up > 0 ? a + up : t;
            if (r > t)
                r = t;
        } else {                    /* slowing down from reverse */
            double stop = t < 0 ? t : 0.0;
            r = dn > 0 ? a + dn : stop;
            if (r > stop)
                r = stop;
        }
    } else {
        if (a <= 0) {               /* speeding up in reverse */
            r = up > 0 ? a - up : t;
            if (r < t)
                r = t;
        } else {                    /* slowing down from forward */
            double stop = t > 0 ? t : 0.0;
            r = dn > 0 ? a - dn : stop;
            if (r < stop)
                r = stop;
        }
    }
    if (sim)
        speed = r;

    /* a zero command never switches a direction on, and drops reverse */
    if (r > 0) {
        if (cmd != 0)
            forward = 1;
        reverse = 0;
    } else if (r < 0) {
        forward = 0;
        reverse = cmd != 0;
    } else {
        forward = 0;
        reverse = 0;
    }
    brake = 0;

    spindle_rpm = sim ? r : actual_speed * 60.0;
    output = (fabs(r) + *g_offset[g]) * *g_scale[g];
}
