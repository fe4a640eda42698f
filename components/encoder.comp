component encoder """Software counting of quadrature encoder signals""";

description """
encoder counts the pulses of a quadrature encoder (or, in counter mode, of
a single pulse train) read through ordinary inputs, such as a parallel
port.  Being done in software, the count rate is limited by the thread
that samples the inputs: every state of the A/B signals must be seen at
least once, so the thread must run at least twice as fast as the fastest
edge rate, typically limiting the input to some 10 to 50 kHz.  Use a
hardware counter for faster encoders.

The work is split between two functions, each covering every channel:
\\fBencoder.update-counters\\fR samples the inputs and counts, and belongs
in the fast (base) thread; \\fBencoder.capture-position\\fR turns the count
into position, velocity and latched values, and belongs in the slower
servo thread, before the motion controller or PID loop that reads them.

\\fBQuadrature\\fR: A and B are two square waves a quarter cycle apart.
A leading B counts up, B leading A counts down.  With \\fBx4-mode\\fR (the
default) every edge of A and B is a count, four a cycle; without it there
is one count a cycle (on the rising edge of A while B is low, and back
down on the matching falling edge, so a jittering edge cannot creep).

\\fBCounter mode\\fR: with \\fBcounter-mode\\fR true each rising edge of A
counts up and B is ignored, for single-channel sensors such as a spindle
with one pulse a revolution or a toothed wheel.

\\fBIndex\\fR: setting \\fBindex-enable\\fR arms the channel; the next rising
edge of phase-Z makes that point count zero and clears
\\fBindex-enable\\fR.  This is what the motion controller uses for
spindle synchronisation and homing to an index.

\\fBVelocity\\fR is measured from the time between counts rather than the
number of counts per period, which gives a much less noisy estimate at low
speed.  When counts stop arriving the estimate falls as 1 / (time since
the last count) and is zeroed after a time set by
\\fBmin-speed-estimate\\fR (see NOTES).
""";

notes """
encoder makes at most 8 channels.  num_chan= and names= cannot be given
together; with neither (or num_chan=0) there are three channels,
encoder.0 to encoder.2.

As in the reference, the velocity falls to 0 after position-scale /
min-speed-estimate seconds without a count (the time of one count at
min-speed-estimate only when position-scale is 1; with a negative
position-scale, at the first period without a count).

\\fBmissing-teeth\\fR (as in the reference): for a toothed wheel with a gap
of missing-teeth teeth, such as a 60-2 crank wheel.  Each count up that
comes at least a limit after the previous count is taken as the tooth
after the gap: it counts missing-teeth + 1 and, with index-enable set,
is the index (counts 0 at that tooth).  The limit is learnt from the
teeth themselves: each count up moves it a tenth of the way towards
missing-teeth + 1/2 times the interval per count (the interval divided
by missing-teeth + 1 after a gap), except the first two counts after
loading, which are not used.  It starts at zero, so at first every tooth
counts missing-teeth + 1; on a wheel turning at a steady speed it takes
two or three turns before only the gap does (with missing-teeth 1 and
teeth that are not evenly spaced it may never happen: keep index-enable
clear and check the count until it has settled).  Once settled,
an interval longer than about missing-teeth + 1/2 teeth is a gap, so a
sudden slowdown by that factor is taken as one too.  A count down (in quadrature mode) moves the limit a tenth of the
way towards zero.  The same rule applies to the counts up in quadrature
mode, where it is rarely useful (there our counts match the reference's
for steady rates and simple reversals, not in every case).  With
missing-teeth 0 nothing is added but the limit is still learnt.

The pins x4-mode, counter-mode, position-scale and index-enable are
I/O pins: they can be linked to a signal with other I/O pins or set
with setp, but not driven by an output pin.
""";

modparam dummy num_chan """Number of channels to make (1 to 8, default 3); channels are
named encoder.0, encoder.1, ...""";
modparam dummy names """Comma-separated names of the channels to make (at most 8),
instead of num_chan""";

pin in bit phase_A "Phase A of the encoder (the count input in counter mode).";
pin in bit phase_B "Phase B of the encoder (ignored in counter mode).";
pin in bit phase_Z "Index pulse of the encoder; see index-enable.";
pin io bit index_enable "Set true to reset counts and position to zero at the next rising edge of phase-Z; cleared when that happens.";
pin in bit reset "While true, counts, position and the latched values read zero (the count continues from zero when it is released).";
pin in bit latch_input "Input whose edges copy the current counts and position to counts-latched and position-latched.";
pin in bit latch_rising = 1 "Latch on rising edges of latch-input.";
pin in bit latch_falling = 1 "Latch on falling edges of latch-input.";

pin out s32 counts "Position in counts, from the last index or reset.";
pin out s32 counts_latched "counts at the last selected edge of latch-input.";
pin out s32 rawcounts "The count of update-counters itself, not affected by index or reset (updated in the fast thread).";
pin out float position "Position in machine units: counts / position-scale.";
pin out float position_latched "position at the last selected edge of latch-input.";
pin out float position_interpolated "position plus velocity times the time since the last count: smoother than position at steady speed, but not for position control.";
pin out float velocity "Velocity in machine units per second, estimated from the time between counts; 0 below min-speed-estimate.";
pin out float velocity_rpm "velocity times 60 (units per minute; revolutions per minute when a unit is a revolution).";

pin io float position_scale = 1.0 "Counts per machine unit (may be negative to reverse the direction).  Values too close to 0 are replaced by 1.";
pin io bit x4_mode = 1 "True: count every edge of A and B (4 counts per cycle); false: one count per cycle.  Ignored in counter mode.";
pin io bit counter_mode "True: count the rising edges of phase-A only, up, ignoring phase-B.";
pin in float min_speed_estimate = 1.0 "Lowest speed (in units per second) that gives a non-zero velocity; a lower value makes the velocity take longer to fall to 0 after the counts stop.";
pin in s32 missing_teeth "For a toothed wheel with a gap used as the index: the number of teeth missing from the gap (e.g. 2 for a 60-2 wheel, with position-scale 60).  A long enough interval then counts this many teeth plus one.  0: off.  See NOTES.";

variable int ab;
variable int zold;
variable int lold;
variable int raw;
variable int idx_raw;
variable int idx_seen;
variable int armed;
variable int latch_raw;
variable int latch_seen;
variable long long stamp;
variable long long tooth_t;
variable long long tooth_lim;
variable int teeth_seen;

variable int old_raw;
variable int offset;
variable int since_timeout;
variable long long old_stamp;
variable double old_scale;
variable double inv_scale;
variable double vel;

option rtapi_app no;
option extra_setup yes;

see_also "sim_encoder(9), pid(9), encoder_ratio(9)";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

#define MAX_CHAN 8

static int num_chan;
RTAPI_MP_INT(num_chan, "number of channels");
static char *names[MAX_CHAN];
RTAPI_MP_ARRAY_STRING(names, MAX_CHAN, "names of the channels");

/* time of update-counters, in ns, advanced once a call */
static long long timebase;

/* count change for a move from quadrature state o to n (state = A | B<<1),
   x4: every edge; x1: only 00 -> A (up) and A -> 00 (down) */
static const signed char step4[16] = {
/* n:  00  A   B   AB        o: */
        0, +1, -1,  0,      /* 00 */
       -1,  0,  0, +1,      /* A  */
       +1,  0,  0, -1,      /* B  */
        0, -1, +1,  0,      /* AB */
};
static const signed char step1[16] = {
        0, +1,  0,  0,
       -1,  0,  0,  0,
        0,  0,  0,  0,
        0,  0,  0,  0,
};

EXTRA_SETUP() {
    old_scale = 1.0;
    inv_scale = 1.0;
    return 0;
}

static void update_counters(void *arg, long period)
{
    struct __comp_state *__comp_inst;

    FOR_ALL_INSTS() {
        int n = (phase_A ? 1 : 0) | (phase_B ? 2 : 0);
        int o = ab;
        int d, gap;

        if (counter_mode)
            d = (n & 1) && !(o & 1);
        else if (x4_mode)
            d = step4[(o << 2) | n];
        else
            d = step1[(o << 2) | n];

        /* missing-teeth: a count up that comes at least tooth_lim after
           the previous count is taken as the gap and adds missing-teeth */
        gap = 0;
        if (d) {
            long long dt = timebase - tooth_t;

            tooth_t = timebase;
            if (d > 0 && dt >= tooth_lim) {
                gap = 1;
                d += missing_teeth;
            }
            /* the limit follows missing-teeth + 1/2 times the time per
               count, smoothed with a weight of 1/10; the first two counts
               are not used, a net count down pulls it towards zero and
               a gap that leaves no count does not change it */
            if (teeth_seen < 2) {
                teeth_seen++;
            } else if (d > 0) {
                long long lim = dt * (2LL * missing_teeth + 1) / (2LL * d);

                tooth_lim += (lim - tooth_lim) / 10;
            } else if (d < 0) {
                tooth_lim -= tooth_lim / 10;
            }
        }
        ab = n;
        if (d) {
            raw += d;
            stamp = timebase;
        }

        if (((phase_Z && !zold) || (gap && missing_teeth)) && armed) {
            idx_raw = raw;
            idx_seen = 1;
            armed = 0;
        }
        zold = phase_Z;

        if (latch_input != lold &&
            ((latch_input && latch_rising) || (!latch_input && latch_falling))) {
            latch_raw = raw;
            latch_seen = 1;
        }
        lold = latch_input;

        rawcounts = raw;
    }
    timebase += period;
}

static void capture_position(void *arg, long period)
{
    struct __comp_state *__comp_inst;

    FOR_ALL_INSTS() {
        int r = raw;
        int dc = r - old_raw;
        double s;

        if (position_scale != old_scale) {
            if (fabs(position_scale) < 1e-20)
                position_scale = 1.0;
            old_scale = position_scale;
            inv_scale = 1.0 / position_scale;
        }
        s = inv_scale;
        old_raw = r;

        if (idx_seen) {
            idx_seen = 0;
            offset = idx_raw;
            index_enable = 0;
        }
        /* update-counters looks for the index only once this function
           has seen index-enable set */
        armed = index_enable;
        if (latch_seen) {
            latch_seen = 0;
            counts_latched = latch_raw - offset;
        }
        if (reset) {
            offset = r;
            counts_latched = 0;
        }
        counts = r - offset;
        position = (r - offset) * s;
        position_latched = counts_latched * s;

        if (dc != 0) {
            long long dt = stamp - old_stamp;

            old_stamp = stamp;
            if (since_timeout < 2)
                since_timeout++;
            else
                vel = dc * s / (dt * 1e-9);
        } else if (since_timeout) {
            long long dt = timebase - old_stamp;
            /* the reference's limit: min-speed-estimate times the length
               of a count, not divided by it (so it depends on the scale
               squared, and is never met with a negative scale) */
            double limit = 1e9 / (min_speed_estimate * s);

            if (dt < limit) {
                double est = s / (dt * 1e-9);

                if (fabs(est) < fabs(vel))
                    vel = vel > 0.0 ? fabs(est) : -fabs(est);
            } else {
                vel = 0.0;
                since_timeout = 0;
            }
        } else {
            vel = 0.0;
        }
        velocity = vel;
        velocity_rpm = vel * 60.0;
        position_interpolated = position + vel * ((timebase - stamp) * 1e-9);
    }
}

int rtapi_app_main(void)
{
    char buf[HAL_NAME_LEN + 1];
    int n, r;

    if (num_chan && names[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "num_chan= and names= are mutually exclusive\n");
        return -EINVAL;
    }
    if (!names[0]) {
        if (!num_chan)
            num_chan = 3;
        if (num_chan < 1 || num_chan > MAX_CHAN) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "ENCODER: ERROR: invalid number of channels: %d\n",
                            num_chan);
            return -EPERM;
        }
    }

    comp_id = hal_init("encoder");
    if (comp_id < 0)
        return comp_id;

    if (names[0]) {
        for (n = 0; n < MAX_CHAN && names[n] && names[n][0]; n++) {
            r = export(names[n], n);
            if (r != 0)
                goto fail;
        }
    } else {
        for (n = 0; n < num_chan; n++) {
            rtapi_snprintf(buf, sizeof(buf), "encoder.%d", n);
            r = export(buf, n);
            if (r != 0)
                goto fail;
        }
    }

    r = hal_export_funct("encoder.update-counters", update_counters,
                         NULL, 0, 0, comp_id);
    if (r != 0)
        goto fail;
    r = hal_export_funct("encoder.capture-position", capture_position,
                         NULL, 1, 0, comp_id);
    if (r != 0)
        goto fail;

    hal_ready(comp_id);
    return 0;

fail:
    hal_exit(comp_id);
    return r;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
