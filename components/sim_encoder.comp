component sim_encoder "Simulated quadrature encoder with index pulse";

description """
Generates the A, B and index (Z) signals of a quadrature encoder turning at
a commanded speed, in software. Use it to test an encoder counter, or a
whole configuration, without a real encoder.

Load it with \\fBnum_chan=\\fIN\\fR (1 to 8 channels, default 1) or with
\\fBnames=\\fIname1,name2,...\\fR (at most 8); the two are exclusive. With
\\fBnum_chan\\fR the channels are named \\fBsim-encoder.\\fIN\\fR.

The two functions serve all channels at once:
\\fBsim-encoder.update-speed\\fR (floating point) turns each channel's
speed into a step rate and belongs in the servo thread;
\\fBsim-encoder.make-pulses\\fR (no floating point) makes at most one
quadrature step a call and belongs in a fast base thread. The highest
count rate is therefore one count per make-pulses period; a faster
command is limited to that rate. A new speed takes effect when
update-speed next runs. Until make-pulses has run once, update-speed
does not know its period and assumes 50 us.

Each pulse of the encoder is four counts (every edge of A and B is a
count). The index output is TRUE for one count per revolution, where A is
TRUE and B is FALSE.
""";

notes """
A speed at or beyond the highest count rate (in either direction) makes
the channel count downwards at the highest rate, as the reference
implementation does. Keep the commanded count rate, |speed| / scale * ppr
* 4, below 1e9 / (make-pulses period in ns). A NaN speed or scale stops
the channel where it is (no steps), as in the reference.

A scale between \\-1e\\-20 and 1e\\-20 is replaced by 1.0 when update-speed
notices the change (the scale pin then reads 1). A scale of exactly 0
set before the first update-speed is not noticed and acts as 1.0.
""";

pin out bit phase_A "Quadrature output A";
pin out bit phase_B "Quadrature output B, a quarter cycle behind A when counting up";
pin out bit phase_Z "Index pulse: TRUE for one count each revolution";
pin in float speed "Commanded speed, in user units per second; divided by scale to get revolutions per second";
pin io u32 ppr = 100 "Pulses (full quadrature cycles, four counts each) per revolution";
pin io float scale = 1.0 "User units per revolution: speed / scale is revolutions per second (60 makes speed RPM)";
pin in s32 rawcounts "Count of the generated edges: the component adds one for each step up and subtracts one for each step down (it writes this pin although it is an input, as the reference does)";

function make_pulses nofp "sim-encoder.make-pulses: make the quadrature steps of all channels; run it in a fast thread";
function update_speed "sim-encoder.update-speed: read speed, scale and ppr of all channels and set their step rates";

variable rtapi_s64 addval;
variable rtapi_u64 accum;
variable int state;
variable int cycle;
variable double old_scale;
variable double scale_mult;

modparam int num_chan = 0 "Number of channels, 1 to 8 (0: not given; one channel unless names= is given)";
modparam dummy names "Names of the channels, separated by commas (at most 8), instead of sim-encoder.0, sim-encoder.1, ...";

option rtapi_app no;

see_also "encoder(9), sim_spindle(9)";
author "the halsdk authors";
license "GPL";
;;
#define MAX_CHAN 8

/* rawcounts is an input pin that the component counts in, so it needs a
   writable shorthand */
#undef rawcounts
#define raw_count (*__comp_inst->rawcounts)

static char *names[MAX_CHAN];
RTAPI_MP_ARRAY_STRING(names, MAX_CHAN, "names of the channels");

/* the make-pulses period, known once make-pulses has run; until then
   update-speed assumes 50 us, as the reference does */
static long pulse_period = 50000;
static long rate_period;
static double max_rate;         /* counts per second */
static double rate_to_add;      /* accumulator units per (count/s) */

FUNCTION(make_pulses) {
    pulse_period = period;
    FOR_ALL_INSTS() {
        rtapi_u64 before = accum;

        accum += (rtapi_u64)addval;
        /* a step each time the accumulator passes a multiple of 2^31, as
           bits 31 to 62 tell (the reference keeps 32 bits of accum >> 31):
           the add value of a NaN speed, -2^63, changes only bit 63 and
           makes no step */
        if ((rtapi_u32)(before >> 31) != (rtapi_u32)(accum >> 31)) {
            /* the direction is the low 32 bits of addval >> 31: +2^31
               (the highest rate upwards) counts down, as in the
               reference */
            if ((rtapi_s32)(addval >> 31) != 0) {
                raw_count--;
                if (--state < 0) {
                    state = 3;
                    if (--cycle < 0)
                        cycle += ppr;
                }
            } else {
                raw_count++;
                if (++state > 3) {
                    state = 0;
                    if (++cycle >= (int)ppr)
                        cycle -= ppr;
                }
            }
        }
        /* the quadrature states in counting order: 10 11 01 00 */
        phase_A = (state == 0 || state == 1);
        phase_B = (state == 1 || state == 2);
        phase_Z = (state == 0 && cycle == 0);
    }
}

FUNCTION(update_speed) {
    if (pulse_period != rate_period) {
        rate_period = pulse_period;
        max_rate = 1.0e9 / rate_period;
        rate_to_add = 2147483648.0 / max_rate;
    }
    FOR_ALL_INSTS() {
        double rate;

        if (scale != old_scale) {
            old_scale = scale;
            if (scale > -1e-20 && scale < 1e-20)
                scale = 1.0;
            scale_mult = 1.0 / scale;
        }
        rate = speed * scale_mult * ppr * 4.0;
        if (rate > max_rate)
            rate = max_rate;
        else if (rate < -max_rate)
            rate = -max_rate;
        /* +-max_rate is +-2^31; a NaN speed (no comparison above holds)
           gives the x86 conversion of a NaN, -2^63, as in the reference */
        rate *= rate_to_add;
        if (rate != rate)
            addval = INT64_MIN;
        else
            addval = (rtapi_s64)rate;
    }
}

/* setup code below names the fields itself, not through the per-instance
   shorthands of the functions above */
#undef phase_A
#undef phase_B
#undef phase_Z
#undef speed
#undef ppr
#undef scale
#undef old_scale
#undef scale_mult

static int make_channel(const char *prefix)
{
    struct __comp_state *inst = hal_malloc(sizeof(*inst));
    int r;

    if (!inst)
        return -ENOMEM;
    memset(inst, 0, sizeof(*inst));
    if ((r = hal_pin_bit_newf(HAL_OUT, &inst->phase_A, comp_id,
                              "%s.phase-A", prefix)) ||
        (r = hal_pin_bit_newf(HAL_OUT, &inst->phase_B, comp_id,
                              "%s.phase-B", prefix)) ||
        (r = hal_pin_bit_newf(HAL_OUT, &inst->phase_Z, comp_id,
                              "%s.phase-Z", prefix)) ||
        (r = hal_pin_float_newf(HAL_IN, &inst->speed, comp_id,
                                "%s.speed", prefix)) ||
        (r = hal_pin_u32_newf(HAL_IO, &inst->ppr, comp_id,
                              "%s.ppr", prefix)) ||
        (r = hal_pin_float_newf(HAL_IO, &inst->scale, comp_id,
                                "%s.scale", prefix)) ||
        (r = hal_pin_s32_newf(HAL_IN, &inst->rawcounts, comp_id,
                              "%s.rawcounts", prefix)))
        return r;
    *inst->ppr = 100;
    *inst->scale = 1.0;
    inst->old_scale = 0.0;
    inst->scale_mult = 1.0;
    if (__comp_last_inst)
        __comp_last_inst->_next = inst;
    __comp_last_inst = inst;
    if (!__comp_first_inst)
        __comp_first_inst = inst;
    return 0;
}

int rtapi_app_main(void)
{
    int n, r;

    if (num_chan && names[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "num_chan= and names= are mutually exclusive\n");
        return -EINVAL;
    }
    if (!num_chan && !names[0])
        num_chan = 1;
    if (names[0]) {
        for (num_chan = 0; num_chan < MAX_CHAN; num_chan++)
            if (!names[num_chan] || !names[num_chan][0])
                break;
    }
    if (num_chan <= 0 || num_chan > MAX_CHAN) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "SIM_ENCODER: ERROR: invalid number of channels %d\n",
                        num_chan);
        return -1;
    }
    comp_id = hal_init("sim_encoder");
    if (comp_id < 0)
        return comp_id;
    for (n = 0; n < num_chan; n++) {
        char prefix[HAL_NAME_LEN + 1];

        if (names[0])
            rtapi_snprintf(prefix, sizeof(prefix), "%s", names[n]);
        else
            rtapi_snprintf(prefix, sizeof(prefix), "sim-encoder.%d", n);
        r = make_channel(prefix);
        if (r) {
            hal_exit(comp_id);
            return r;
        }
    }
    r = hal_export_funct("sim-encoder.make-pulses",
                         (void (*)(void *, long))make_pulses, NULL, 0, 0,
                         comp_id);
    if (!r)
        r = hal_export_funct("sim-encoder.update-speed",
                             (void (*)(void *, long))update_speed, NULL, 1,
                             0, comp_id);
    if (r) {
        hal_exit(comp_id);
        return r;
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
