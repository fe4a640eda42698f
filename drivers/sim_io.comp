component sim_io "Simulated I/O board with the canonical HAL device interfaces";

description """
A board that exists only in memory, for examples and tests.  Each simulated board
offers digital inputs and outputs, analog inputs and outputs, encoder counters and
home/limit switches, named like the pins of a real board
(\\fBsim-io.\\fIN\\fB.\\fIio-type\\fB.\\fIMM\\fB.\\fIname\\fR).  Outputs loop back
to inputs so that a machine configuration can be exercised without hardware:
digital output MM drives digital input MM, analog output MM drives analog input
MM, encoders count a simulated motor position (for example the feedback of a
stepgen) or the step and direction or quadrature pulses wired to their
phase-A and phase-B inputs (for example the outputs of a stepgen), and
switches follow a simulated axis position.

Load with \\fBloadrt sim_io num_boards=\\fIB\\fR and the channel counts
\\fBnum_digin\\fR, \\fBnum_digout\\fR, \\fBnum_adcin\\fR, \\fBnum_dacout\\fR,
\\fBnum_encoder\\fR, \\fBnum_switch\\fR (each board gets the same counts).

Add \\fBsim-io.\\fIN\\fB.write\\fR to a thread after the functions that compute the
outputs and \\fBsim-io.\\fIN\\fB.read\\fR before those that use the inputs.
\\fBwrite\\fR latches the output pins into the simulated hardware; \\fBread\\fR
updates the input pins from it.  An encoder that counts pulses
(\\fBsim-source\\fR 1, 2 or 3) sees its inputs only when \\fBread\\fR runs: put
\\fBread\\fR in the thread of the pulse generator, after it, so that it
samples every change (e.g. after \\fBstepgen.make-pulses\\fR in the base
thread, which then needs floating point, as \\fBread\\fR uses it).

The canonical interface names some params with underscores, which a pin
list here cannot show; each analog channel also has these params (rw):
\\fBsim-io.\\fIN\\fB.dacout.\\fIMM\\fB.high_limit\\fR (float, default 10) and
\\fB.low_limit\\fR (default -10): the range of the simulated converter;
\\fBsim-io.\\fIN\\fB.adcin.\\fIMM\\fB.bit_weight\\fR,
\\fB.hw_offset\\fR and the same two for \\fBdacout\\fR (float, defaults 1
and 0): the size of one converter step and its zero error, as a real board
reports them; the simulation does not apply them.
""";

modparam int num_boards = 1 "Number of simulated boards, 1 to 8";
modparam int num_digin = 8 "Digital inputs per board, 0 to 64";
modparam int num_digout = 8 "Digital outputs per board, 0 to 64";
modparam int num_adcin = 4 "Analog inputs per board, 0 to 64";
modparam int num_dacout = 4 "Analog outputs per board, 0 to 64";
modparam int num_encoder = 3 "Encoder counters per board, 0 to 64";
modparam int num_switch = 3 "Sets of home and limit switches per board, 0 to 64";

// The pins and params below document the interface of one board (N) and one
// channel (MM); rtapi_app_main creates them for every board and channel.
pin in bit loopback = 1 "When true each digin.MM follows digout.MM (after invert); when false it follows its sim-in pin";
pin in bit adc_loopback = 1 "When true each adcin.MM reads the level of dacout.MM; when false it reads its sim-in pin";

pin out bit digin.MM.in "The simulated input level";
pin out bit digin.MM.in_not "The simulated input level, inverted";
pin in bit digin.MM.sim_in "Input level used when loopback is false (or when there is no digout.MM)";

pin in bit digout.MM.out "Value to output; the terminal level is out XOR invert";
param rw bit digout.MM.invert "Invert the output";

pin out float adcin.MM.value "Reading: terminal level * scale - offset";
pin in float adcin.MM.sim_in "Terminal level used when adc-loopback is false (or when there is no dacout.MM)";
param rw float adcin.MM.scale = 1.0 "Multiplier applied to the terminal level";
param rw float adcin.MM.offset "Subtracted after scaling";

pin in float dacout.MM.value "Value to output: the terminal level is value * scale + offset, clamped to high_limit and low_limit (see the description)";
param rw float dacout.MM.scale = 1.0 "Multiplier";
param rw float dacout.MM.offset "Added after scaling";
pin in bit dacout.MM.enable "When false the terminal level is 0";

pin out s32 encoder.MM.count "Counts since start, reset or the last index taken";
pin out float encoder.MM.position "count / position-scale";
pin out float encoder.MM.velocity "Change of position per second over the last period";
pin in bit encoder.MM.reset "While true count is held at zero";
pin io bit encoder.MM.index_enable "Set true to zero the count at the next index pulse; cleared by the driver when that happens";
pin in float encoder.MM.sim_position "Simulated motor position (e.g. a stepgen position-fb), used when sim-source is 0; the counter reads sim-position * position-scale rounded to the nearest whole count";
pin in bit encoder.MM.phase_A "Encoder input A.  sim-source 1: step, each rising edge is one count (e.g. a stepgen step output); sim-source 2: quadrature channel A; sim-source 3: up, each rising edge counts up (a stepgen up output)";
pin in bit encoder.MM.phase_B "Encoder input B.  sim-source 1: direction, sampled at the step edge, high counts down (as a stepgen dir output); sim-source 2: quadrature channel B, which A leads when counting up; sim-source 3: down, each rising edge counts down (a stepgen down output)";
param rw float encoder.MM.position_scale = 1.0 "Counts per unit of position";
param rw s32 encoder.MM.sim_counts_per_rev = 1000 "An index pulse occurs at every multiple of this many counts (0: no index)";
param rw s32 encoder.MM.sim_source = 0 "What the counter counts: 0 follows sim-position, 1 counts step and direction on phase-A and phase-B, 2 decodes quadrature on phase-A and phase-B (a change of both in one read is not counted), 3 counts up pulses on phase-A and down pulses on phase-B; changing it keeps the count where it is; other values stop the counter and log an error once";

pin in float switch.MM.position "Simulated axis position";
pin out bit switch.MM.home "True at or above home-pos";
pin out bit switch.MM.pos_limit "True at or above pos-limit-pos";
pin out bit switch.MM.neg_limit "True at or below neg-limit-pos";
param rw float switch.MM.home_pos = 0.0 "Home switch trip position";
param rw float switch.MM.pos_limit_pos = 100.0 "Positive limit trip position";
param rw float switch.MM.neg_limit_pos = -100.0 "Negative limit trip position";
param rw float switch.MM.hysteresis = 0.1 "A tripped switch releases only once the position is back by more than this";


author "the halsdk authors";
license "GPL";
option rtapi_app no;
option no_convenience_defines;
;;

#include "rtapi_math.h"
#include "rtapi_string.h"

#define MAX_BOARDS 8
#define MAX_CHAN 64


typedef struct {
    hal_bit_t *in, *in_not, *sim_in;
} digin_t;

typedef struct {
    hal_bit_t *out;
    hal_bit_t invert;
    int state;                  /* level at the simulated output terminal */
} digout_t;

typedef struct {
    hal_float_t *value, *sim_in;
    hal_float_t scale, offset, bit_weight, hw_offset;
} adcin_t;

typedef struct {
    hal_float_t *value;
    hal_bit_t *enable;
    hal_float_t scale, offset, high_limit, low_limit, bit_weight, hw_offset;
    double volts;               /* level at the simulated output terminal */
} dacout_t;

/* the sim-source values; SRC_NONE is the state before the first read
   and while sim-source is out of range */
#define SRC_NONE -1
#define SRC_POSITION 0
#define SRC_STEP_DIR 1
#define SRC_QUADRATURE 2
#define SRC_UP_DOWN 3

typedef struct {
    hal_s32_t *count;
    hal_float_t *position, *velocity, *sim_position;
    hal_bit_t *reset, *index_enable, *phase_a, *phase_b;
    hal_float_t position_scale;
    hal_s32_t counts_per_rev, source;
    long long raw;              /* simulated counter, never reset */
    long long base;             /* raw value where count is zero */
    double old_pos;
    int mode;                   /* source used by the last read */
    int old_a, old_b;           /* input levels seen by the last read */
    int warned;
    char name[HAL_NAME_LEN + 1];    /* for messages */
} encoder_t;

typedef struct {
    hal_float_t *position;
    hal_bit_t *home, *pos_limit, *neg_limit;
    hal_float_t home_pos, pos_limit_pos, neg_limit_pos, hysteresis;
} switch_t;

typedef struct {
    hal_bit_t *lb;
    hal_bit_t *adc_lb;
    digin_t *digin;
    digout_t *digout;
    adcin_t *adcin;
    dacout_t *dacout;
    encoder_t *enc;
    switch_t *sw;
} board_t;

static board_t *boards;

static void board_write(void *arg, long period)
{
    board_t *b = arg;
    int i;

    for (i = 0; i < num_digout; i++) {
        digout_t *d = &b->digout[i];
        d->state = (*d->out != 0) ^ (d->invert != 0);
    }
    for (i = 0; i < num_dacout; i++) {
        dacout_t *d = &b->dacout[i];
        double v = *d->value * d->scale + d->offset;
        if (v > d->high_limit) v = d->high_limit;
        if (v < d->low_limit) v = d->low_limit;
        d->volts = *d->enable ? v : 0.0;
    }
}

/* hysteresis switch: on at or beyond trip, off once back by more than hyst */
static int trip_high(int old, double pos, double trip, double hyst)
{
    if (pos >= trip) return 1;
    if (old && pos > trip - hyst) return 1;
    return 0;
}

static int trip_low(int old, double pos, double trip, double hyst)
{
    if (pos <= trip) return 1;
    if (old && pos < trip + hyst) return 1;
    return 0;
}

/* counter value of the simulated position: the nearest whole count; a
   stepgen's position-fb carries a fraction of a step, rounding it gives
   back the stepgen's own step count */
static long long position_counts(const encoder_t *e, double scale)
{
    double pos = floor(*e->sim_position * scale + 0.5);

    if (pos != pos)
        return e->raw;                  /* NaN: the counter stands still */
    if (pos > 1e15)
        return 1000000000000000LL;      /* keep the conversion defined */
    if (pos < -1e15)
        return -1000000000000000LL;
    return (long long)pos;
}

/* place of the A/B levels in the quadrature cycle; counting up it runs
   0 1 2 3 0 ..., so A rises a quarter cycle before B */
static int quad_state(int a, int b)
{
    return a ? (b ? 2 : 1) : (b ? 3 : 0);
}

/* an index pulse sits at every multiple of counts-per-rev: when armed,
   take the first one passed between the old counter and raw */
static void take_index(encoder_t *e, long long raw)
{
    long long cpr = e->counts_per_rev;
    long long lo = raw > e->raw ? e->raw : raw;
    long long hi = raw > e->raw ? raw : e->raw;
    long long idx;

    if (cpr <= 0 || !*e->index_enable || raw == e->raw)
        return;
    if (raw > e->raw) {
        /* first multiple in (lo, hi] */
        idx = (lo >= 0 ? lo / cpr + 1 : -((-lo) / cpr)) * cpr;
        if (idx > hi)
            return;
    } else {
        /* first multiple in [lo, hi) going down: the largest <= hi - 1 */
        long long h = hi - 1;
        idx = (h >= 0 ? h / cpr : -((-h + cpr - 1) / cpr)) * cpr;
        if (idx < lo)
            return;
    }
    e->base = idx;
    *e->index_enable = 0;
}

static void encoder_read(encoder_t *e, long period)
{
    double scale = e->position_scale;
    int src = e->source;
    int a = *e->phase_a != 0, b = *e->phase_b != 0;
    long long raw = e->raw;

    if (scale == 0.0) scale = 1.0;      /* avoid dividing by zero */
    if (src < SRC_POSITION || src > SRC_UP_DOWN) {
        if (!e->warned)
            rtapi_print_msg(RTAPI_MSG_ERR,
                "sim_io: %s.sim-source=%d is not 0, 1, 2 or 3; "
                "the counter stands still\n", e->name, src);
        e->warned = 1;
        src = SRC_NONE;
    } else {
        e->warned = 0;
    }
    if (src != e->mode) {
        /* first read or a new source: start from the input as it is now,
           without counting, so that count carries on where it was */
        if (src == SRC_POSITION) {
            raw = position_counts(e, scale);
            e->base += raw - e->raw;
            e->raw = raw;
        }
        e->mode = src;
    } else if (src == SRC_POSITION) {
        raw = position_counts(e, scale);
    } else if (src == SRC_STEP_DIR) {
        if (a && !e->old_a)
            raw += b ? -1 : 1;
    } else if (src == SRC_QUADRATURE) {
        /* one step along the cycle is one count; a jump of two (both
           inputs changed since the last read) has no direction */
        int d = (quad_state(a, b) - quad_state(e->old_a, e->old_b)) & 3;
        if (d == 1)
            raw++;
        else if (d == 3)
            raw--;
    } else if (src == SRC_UP_DOWN) {
        if (a && !e->old_a)
            raw++;
        if (b && !e->old_b)
            raw--;
    }
    e->old_a = a;
    e->old_b = b;
    take_index(e, raw);
    e->raw = raw;
    if (*e->reset) e->base = raw;
    *e->count = (hal_s32_t)(raw - e->base);
    *e->position = *e->count / scale;
    *e->velocity = (*e->position - e->old_pos) / (period * 1e-9);
    e->old_pos = *e->position;
}

static void board_read(void *arg, long period)
{
    board_t *b = arg;
    int i;

    for (i = 0; i < num_digin; i++) {
        digin_t *d = &b->digin[i];
        int v;
        if (*b->lb && i < num_digout)
            v = b->digout[i].state;
        else
            v = *d->sim_in != 0;
        *d->in = v;
        *d->in_not = !v;
    }
    for (i = 0; i < num_adcin; i++) {
        adcin_t *a = &b->adcin[i];
        double raw;
        if (*b->adc_lb && i < num_dacout)
            raw = b->dacout[i].volts;
        else
            raw = *a->sim_in;
        *a->value = raw * a->scale - a->offset;
    }
    for (i = 0; i < num_encoder; i++)
        encoder_read(&b->enc[i], period);
    for (i = 0; i < num_switch; i++) {
        switch_t *s = &b->sw[i];
        double p = *s->position, h = s->hysteresis;
        if (h < 0) h = 0;
        *s->home = trip_high(*s->home, p, s->home_pos, h);
        *s->pos_limit = trip_high(*s->pos_limit, p, s->pos_limit_pos, h);
        *s->neg_limit = trip_low(*s->neg_limit, p, s->neg_limit_pos, h);
    }
}

static int check_count(const char *name, int v, int lo, int hi)
{
    if (v < lo || v > hi) {
        rtapi_print_msg(RTAPI_MSG_ERR,
            "sim_io: %s=%d is out of range (must be %d to %d)\n",
            name, v, lo, hi);
        return -EINVAL;
    }
    return 0;
}

static int setup_board(int n)
{
    board_t *b = &boards[n];
    int i, r = 0;
    char pre[HAL_NAME_LEN + 1];

    rtapi_snprintf(pre, sizeof(pre), "sim-io.%d", n);
    b->digin = hal_malloc(sizeof(digin_t) * (num_digin + 1));
    b->digout = hal_malloc(sizeof(digout_t) * (num_digout + 1));
    b->adcin = hal_malloc(sizeof(adcin_t) * (num_adcin + 1));
    b->dacout = hal_malloc(sizeof(dacout_t) * (num_dacout + 1));
    b->enc = hal_malloc(sizeof(encoder_t) * (num_encoder + 1));
    b->sw = hal_malloc(sizeof(switch_t) * (num_switch + 1));
    if (!b->digin || !b->digout || !b->adcin || !b->dacout || !b->enc
            || !b->sw)
        return -ENOMEM;

    r = hal_pin_bit_newf(HAL_IN, &b->lb, comp_id, "%s.loopback", pre);
    if (r) return r;
    *b->lb = 1;
    r = hal_pin_bit_newf(HAL_IN, &b->adc_lb, comp_id,
                         "%s.adc-loopback", pre);
    if (r) return r;
    *b->adc_lb = 1;

    for (i = 0; i < num_digin; i++) {
        digin_t *d = &b->digin[i];
        if ((r = hal_pin_bit_newf(HAL_OUT, &d->in, comp_id,
                "%s.digin.%02d.in", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_OUT, &d->in_not, comp_id,
                "%s.digin.%02d.in-not", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_IN, &d->sim_in, comp_id,
                "%s.digin.%02d.sim-in", pre, i))) return r;
        *d->in_not = 1;
    }
    for (i = 0; i < num_digout; i++) {
        digout_t *d = &b->digout[i];
        if ((r = hal_pin_bit_newf(HAL_IN, &d->out, comp_id,
                "%s.digout.%02d.out", pre, i))) return r;
        if ((r = hal_param_bit_newf(HAL_RW, &d->invert, comp_id,
                "%s.digout.%02d.invert", pre, i))) return r;
    }
    for (i = 0; i < num_adcin; i++) {
        adcin_t *a = &b->adcin[i];
        if ((r = hal_pin_float_newf(HAL_OUT, &a->value, comp_id,
                "%s.adcin.%02d.value", pre, i))) return r;
        if ((r = hal_pin_float_newf(HAL_IN, &a->sim_in, comp_id,
                "%s.adcin.%02d.sim-in", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &a->scale, comp_id,
                "%s.adcin.%02d.scale", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &a->offset, comp_id,
                "%s.adcin.%02d.offset", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &a->bit_weight, comp_id,
                "%s.adcin.%02d.bit_weight", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &a->hw_offset, comp_id,
                "%s.adcin.%02d.hw_offset", pre, i))) return r;
        a->scale = 1.0;
        a->bit_weight = 1.0;
    }
    for (i = 0; i < num_dacout; i++) {
        dacout_t *d = &b->dacout[i];
        if ((r = hal_pin_float_newf(HAL_IN, &d->value, comp_id,
                "%s.dacout.%02d.value", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_IN, &d->enable, comp_id,
                "%s.dacout.%02d.enable", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &d->scale, comp_id,
                "%s.dacout.%02d.scale", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &d->offset, comp_id,
                "%s.dacout.%02d.offset", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &d->high_limit, comp_id,
                "%s.dacout.%02d.high_limit", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &d->low_limit, comp_id,
                "%s.dacout.%02d.low_limit", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &d->bit_weight, comp_id,
                "%s.dacout.%02d.bit_weight", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &d->hw_offset, comp_id,
                "%s.dacout.%02d.hw_offset", pre, i))) return r;
        d->scale = 1.0;
        d->bit_weight = 1.0;
        d->high_limit = 10.0;
        d->low_limit = -10.0;
    }
    for (i = 0; i < num_encoder; i++) {
        encoder_t *e = &b->enc[i];
        if ((r = hal_pin_s32_newf(HAL_OUT, &e->count, comp_id,
                "%s.encoder.%02d.count", pre, i))) return r;
        if ((r = hal_pin_float_newf(HAL_OUT, &e->position, comp_id,
                "%s.encoder.%02d.position", pre, i))) return r;
        if ((r = hal_pin_float_newf(HAL_OUT, &e->velocity, comp_id,
                "%s.encoder.%02d.velocity", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_IN, &e->reset, comp_id,
                "%s.encoder.%02d.reset", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_IO, &e->index_enable, comp_id,
                "%s.encoder.%02d.index-enable", pre, i))) return r;
        if ((r = hal_pin_float_newf(HAL_IN, &e->sim_position, comp_id,
                "%s.encoder.%02d.sim-position", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &e->position_scale, comp_id,
                "%s.encoder.%02d.position-scale", pre, i))) return r;
        if ((r = hal_param_s32_newf(HAL_RW, &e->counts_per_rev, comp_id,
                "%s.encoder.%02d.sim-counts-per-rev", pre, i))) return r;
        if ((r = hal_param_s32_newf(HAL_RW, &e->source, comp_id,
                "%s.encoder.%02d.sim-source", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_IN, &e->phase_a, comp_id,
                "%s.encoder.%02d.phase-A", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_IN, &e->phase_b, comp_id,
                "%s.encoder.%02d.phase-B", pre, i))) return r;
        e->position_scale = 1.0;
        e->counts_per_rev = 1000;
        e->mode = SRC_NONE;
        rtapi_snprintf(e->name, sizeof(e->name), "%s.encoder.%02d", pre, i);
    }
    for (i = 0; i < num_switch; i++) {
        switch_t *s = &b->sw[i];
        if ((r = hal_pin_float_newf(HAL_IN, &s->position, comp_id,
                "%s.switch.%02d.position", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_OUT, &s->home, comp_id,
                "%s.switch.%02d.home", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_OUT, &s->pos_limit, comp_id,
                "%s.switch.%02d.pos-limit", pre, i))) return r;
        if ((r = hal_pin_bit_newf(HAL_OUT, &s->neg_limit, comp_id,
                "%s.switch.%02d.neg-limit", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &s->home_pos, comp_id,
                "%s.switch.%02d.home-pos", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &s->pos_limit_pos, comp_id,
                "%s.switch.%02d.pos-limit-pos", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &s->neg_limit_pos, comp_id,
                "%s.switch.%02d.neg-limit-pos", pre, i))) return r;
        if ((r = hal_param_float_newf(HAL_RW, &s->hysteresis, comp_id,
                "%s.switch.%02d.hysteresis", pre, i))) return r;
        s->home_pos = 0.0;
        s->pos_limit_pos = 100.0;
        s->neg_limit_pos = -100.0;
        s->hysteresis = 0.1;
    }

    if ((r = hal_export_functf(board_read, b, 1, 0, comp_id,
            "%s.read", pre))) return r;
    return hal_export_functf(board_write, b, 1, 0, comp_id, "%s.write", pre);
}

int rtapi_app_main(void)
{
    int n, r;

    if ((r = check_count("num_boards", num_boards, 1, MAX_BOARDS))
        || (r = check_count("num_digin", num_digin, 0, MAX_CHAN))
        || (r = check_count("num_digout", num_digout, 0, MAX_CHAN))
        || (r = check_count("num_adcin", num_adcin, 0, MAX_CHAN))
        || (r = check_count("num_dacout", num_dacout, 0, MAX_CHAN))
        || (r = check_count("num_encoder", num_encoder, 0, MAX_CHAN))
        || (r = check_count("num_switch", num_switch, 0, MAX_CHAN)))
        return r;

    comp_id = hal_init("sim_io");
    if (comp_id < 0)
        return comp_id;
    boards = hal_malloc(sizeof(board_t) * num_boards);
    if (!boards) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    for (n = 0; n < num_boards; n++) {
        r = setup_board(n);
        if (r) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                "sim_io: cannot create board %d (error %d)\n", n, r);
            hal_exit(comp_id);
            return r;
        }
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
