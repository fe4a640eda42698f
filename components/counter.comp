component counter "Count the pulses of a single-channel sensor, such as a spindle pulse pickup (deprecated)";

description """
\\fBnum_chan=\\fIN\\fR makes \\fIN\\fR counters, 1 to 8 (default 1), \\fBcounter.0\\fR ...
\\fBcounter.\\fIN-1\\fR.  This component is deprecated: the encoder
component does the same with its counter-mode set to TRUE.

Each counter adds one for every rising edge of \\fBphase-A\\fR, for a
machine that has a single pulse train from its spindle (and maybe an index
pulse once a revolution) instead of a quadrature encoder.  It cannot tell
the direction of rotation, so it only suits a spindle that turns one way.
The outputs follow the usual encoder interface: \\fBcounts\\fR,
\\fBposition\\fR (counts divided by \\fBposition-scale\\fR), \\fBvelocity\\fR
and \\fBindex-enable\\fR for spindle-synchronized motion.

Two functions serve every counter:
.TP
\\fBcounter.update-counters\\fR (no floating point)
looks at phase-A and phase-Z and counts the edges; it sets \\fBrawcounts\\fR.
Run it often enough to see every pulse (each high and each low level must
last at least one period of its thread).
.TP
\\fBcounter.capture-position\\fR
handles \\fBreset\\fR and computes counts, position and velocity from the
edges counted so far; a servo thread is usual.  The velocity is the change
of the count since the previous run of this function, per second of its
thread's period, divided by \\fBposition-scale\\fR.

Pins of counter N (\\fBcounter.\\fIN\\fB.\\fR...):
.TP
\\fBphase-A\\fR bit in
the pulse input; every rising edge counts one.
.TP
\\fBphase-Z\\fR bit in
the index input.  A rising edge while \\fBindex-enable\\fR is TRUE makes the
present position the new zero of \\fBcounts\\fR (rawcounts carries on) and
sets \\fBindex-enable\\fR FALSE.
.TP
\\fBindex-enable\\fR bit io
set TRUE to zero the counts at the next index pulse; goes FALSE when that
has happened.
.TP
\\fBreset\\fR bit in
while TRUE, rawcounts, counts, position and velocity are held at zero.
.TP
\\fBcounts\\fR s32 out
the number of pulses since the last index (or reset).
.TP
\\fBrawcounts\\fR s32 out
the number of pulses since loading or the last reset; an index pulse does
not change it.
.TP
\\fBposition\\fR float out
counts / position-scale, for example revolutions.
.TP
\\fBvelocity\\fR float out
in position units per second.
.TP
\\fBposition-scale\\fR float io (default 1)
pulses per position unit (e.g. per revolution); a value closer to zero than
1e-20 is replaced by 1.
""";

modparam dummy num_chan "Number of counters to make, 1 to 8 (default 1)";

pin in bit phase_A "(counter.N.phase-A) pulse input, see the description for all pins";
pin out s32 counts "(counter.N.counts) pulses since the last index or reset";

see_also "encoder(9)";
author "the halsdk authors";
license "GPL";
option rtapi_app no;
;;

#include "rtapi_string.h"

#define MAX_CHAN 8

typedef struct {
    hal_bit_t *a;              /* phase-A */
    hal_bit_t *z;              /* phase-Z */
    hal_bit_t *idx_en;         /* index-enable */
    hal_bit_t *rst;            /* reset */
    hal_s32_t *cnt;            /* counts */
    hal_s32_t *raw_pin;        /* rawcounts */
    hal_float_t *pos;          /* position */
    hal_float_t *vel;          /* velocity */
    hal_float_t *scale;        /* position-scale */
    int old_a, old_z;          /* inputs seen by the previous update */
    rtapi_s32 raw;             /* pulses counted by update-counters */
    rtapi_s32 zero;            /* raw count at the last index pulse */
    rtapi_s32 last_raw;        /* raw count at the previous capture */
    double old_scale, inv_scale;
} chan_t;

static int num_chan = 1;
RTAPI_MP_INT(num_chan, "number of counters, 1 to 8");

static chan_t *chans;

static void update_counters(void *arg, long period)
{
    chan_t *c = arg;
    int n;

    (void)period;
    for (n = 0; n < num_chan; n++, c++) {
        int a = *c->a != 0, z = *c->z != 0;

        if (a && !c->old_a)
            c->raw++;
        /* the index counts after a pulse on the same edge */
        if (z && !c->old_z && *c->idx_en) {
            c->zero = c->raw;
            *c->idx_en = 0;
        }
        c->old_a = a;
        c->old_z = z;
        *c->raw_pin = c->raw;
    }
}

static void capture_position(void *arg, long period)
{
    chan_t *c = arg;
    int n;

    for (n = 0; n < num_chan; n++, c++) {
        rtapi_s32 delta, cn;

        if (*c->rst) {
            c->raw = 0;
            c->zero = 0;
            c->last_raw = 0;
        }
        /* a scale of (almost) zero would make the outputs infinite */
        if (*c->scale != c->old_scale) {
            if (*c->scale > -1e-20 && *c->scale < 1e-20)
                *c->scale = 1.0;
            c->old_scale = *c->scale;
            c->inv_scale = 1.0 / *c->scale;
        }
        cn = c->raw - c->zero;
        delta = c->raw - c->last_raw;
        c->last_raw = c->raw;
        *c->raw_pin = c->raw;
        *c->cnt = cn;
        *c->pos = cn * c->inv_scale;
        *c->vel = delta * c->inv_scale * 1e9 / period;
    }
}

static int make_channel(int n, chan_t *c)
{
    int r;

    r = hal_pin_bit_newf(HAL_IN, &c->a, comp_id, "counter.%d.phase-A", n);
    if (r) return r;
    r = hal_pin_bit_newf(HAL_IN, &c->z, comp_id, "counter.%d.phase-Z", n);
    if (r) return r;
    r = hal_pin_bit_newf(HAL_IO, &c->idx_en, comp_id, "counter.%d.index-enable", n);
    if (r) return r;
    r = hal_pin_bit_newf(HAL_IN, &c->rst, comp_id, "counter.%d.reset", n);
    if (r) return r;
    r = hal_pin_s32_newf(HAL_OUT, &c->cnt, comp_id, "counter.%d.counts", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_OUT, &c->pos, comp_id, "counter.%d.position", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_OUT, &c->vel, comp_id, "counter.%d.velocity", n);
    if (r) return r;
    r = hal_pin_s32_newf(HAL_OUT, &c->raw_pin, comp_id, "counter.%d.rawcounts", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_IO, &c->scale, comp_id, "counter.%d.position-scale", n);
    if (r) return r;

    *c->a = *c->z = *c->idx_en = *c->rst = 0;
    *c->cnt = *c->raw_pin = 0;
    *c->pos = *c->vel = 0.0;
    *c->scale = 1.0;
    c->old_scale = 1.0;
    c->inv_scale = 1.0;
    return 0;
}

int rtapi_app_main(void)
{
    int n, r;

    if (num_chan < 1 || num_chan > MAX_CHAN) {
        rtapi_print_msg(RTAPI_MSG_ERR, "COUNTER: ERROR: invalid num_chan: %d\n", num_chan);
        return -EINVAL;
    }
    comp_id = hal_init("counter");
    if (comp_id < 0)
        return comp_id;
    chans = hal_malloc(num_chan * sizeof(chan_t));
    if (!chans) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    memset(chans, 0, num_chan * sizeof(chan_t));
    for (n = 0; n < num_chan; n++) {
        r = make_channel(n, &chans[n]);
        if (r) {
            hal_exit(comp_id);
            return r;
        }
    }
    r = hal_export_funct("counter.update-counters", update_counters, chans, 0, 0, comp_id);
    if (!r)
        r = hal_export_funct("counter.capture-position", capture_position, chans, 1, 0, comp_id);
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
