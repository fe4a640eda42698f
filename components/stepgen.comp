component stepgen "software step pulse generator for stepper motor drives";

description """
\\fBstepgen\\fR turns a position or velocity command into step pulses for
up to 16 stepper motors (channels).  Load it with

.B loadrt stepgen step_type=\\fIT0\\fB[,\\fIT1\\fB...] [ctrl_type=\\fIC0\\fB[,\\fIC1\\fB...]] [user_step_type=\\fIS0\\fB,\\fIS1\\fB...]

One channel is made for each value of \\fBstep_type\\fR, numbered from 0.
\\fBctrl_type\\fR picks the control mode of each channel: \\fBp\\fR (the
default) follows \\fBposition-cmd\\fR with a trapezoidal profile inside the
\\fBmaxvel\\fR and \\fBmaxaccel\\fR limits, the way a machine axis is driven;
\\fBv\\fR runs at \\fBvelocity-cmd\\fR, ramping with \\fBmaxaccel\\fR.

Step types (the outputs of the channel):
.TP
\\fB0\\fR
step and direction: \\fBstep\\fR, \\fBdir\\fR (high for reverse).
Timing: \\fBsteplen\\fR, \\fBstepspace\\fR, \\fBdirsetup\\fR, \\fBdirhold\\fR.
.TP
\\fB1\\fR
up/down: \\fBup\\fR pulses for forward steps, \\fBdown\\fR for
reverse steps.  Timing: \\fBsteplen\\fR, \\fBstepspace\\fR, \\fBdirdelay\\fR.
.TP
\\fB2\\fR
quadrature: \\fBphase-A\\fR leads \\fBphase-B\\fR when moving forward.
.TP
\\fB3\\fR, \\fB4\\fR
three phases (A-C), full step and half step.
.TP
\\fB5\\fR to \\fB8\\fR
four phases (A-D), full step (5 and 6 for unipolar
windings, 7 and 8 for bipolar windings driven by H-bridges).
.TP
\\fB9\\fR, \\fB10\\fR
four phases, half step (unipolar, bipolar).
.TP
\\fB11\\fR, \\fB12\\fR
five phases (A-E), full step.
.TP
\\fB13\\fR, \\fB14\\fR
five phases, half step.
.TP
\\fB15\\fR
your own pattern: \\fBuser_step_type\\fR lists the output word of
each state (bit 0 is phase-A ... bit 4 is phase-E), for example
\\fBuser_step_type=1,3,2,0\\fR; the highest bit used sets how many phase
pins are made.
.PP
Types 2 and up change state at most once per \\fBsteplen\\fR and have a
\\fBdirdelay\\fR between the last step one way and the first step the other
way.  All timing values are in nanoseconds and are rounded up to whole
periods of the thread that runs \\fBmake-pulses\\fR (the rounded value is
written back).  The step rate is limited to one step per
\\fBsteplen\\fR+\\fBstepspace\\fR (types 0 and 1) or per \\fBsteplen\\fR
(other types); \\fBmaxvel\\fR is lowered to that limit when set higher.

Functions (each handles every channel):
.TP
\\fBstepgen.make-pulses\\fR (no floating point)
makes the pulses; put it in
a fast base thread (e.g. 25-50 \\(mcs).  Its period sets the timing
resolution and the highest step rate.
.TP
\\fBstepgen.update-freq\\fR
reads the commands, applies the limits and
position loop and sets the step rate; a servo thread is fast enough.
.TP
\\fBstepgen.capture-position\\fR
copies the step count to \\fBcounts\\fR and
\\fBposition-fb\\fR; servo thread.

.PP
More pins of channel N (see also PINS below):
.TP
\\fBstepgen.\\fIN\\fB.position-cmd\\fR float in (position mode)
wanted position, in machine units.
.TP
\\fBstepgen.\\fIN\\fB.velocity-cmd\\fR float in (velocity mode)
wanted velocity, in machine units per second.
.TP
\\fBstepgen.\\fIN\\fB.step\\fR, \\fB.dir\\fR / \\fB.up\\fR, \\fB.down\\fR / \\fB.phase-A\\fR ... \\fB.phase-E\\fR bit out
the outputs of the step type.

.PP
Parameters of channel N:
.TP
\\fBposition-scale\\fR float rw (default 1)
steps per machine unit, for commands and feedback.
.TP
\\fBmaxvel\\fR float rw (default 0: only the step rate limit)
velocity limit in units per second.
.TP
\\fBmaxaccel\\fR float rw (default 0: no limit)
acceleration limit in units per second squared.
.TP
\\fBfrequency\\fR float ro
the present step rate, in steps per second (negative in reverse).
.TP
\\fBrawcounts\\fR s32 ro
the step count as kept by make-pulses.
.TP
\\fBsteplen\\fR, \\fBstepspace\\fR, \\fBdirsetup\\fR, \\fBdirhold\\fR, \\fBdirdelay\\fR u32 rw (default 1)
the timing values of the step types, in nanoseconds: pulse length, least
low time between pulses, direction-to-step setup time, step-to-direction
hold time, and least time between steps in opposite directions.
""";

notes """
Rough step rate limits: types 0 and 1 need two make-pulses runs per step
(one to raise the pulse, one to drop it); types 2 and up can step on every
run.  A reversal waits until \\fBdirhold\\fR (or \\fBdirdelay\\fR) has passed
after the last pulse and, for type 0, the new direction is on its pin for
\\fBdirsetup\\fR before the next pulse.
""";

pin in bit enable "no steps are made while false.  When it comes back in position mode the motor moves to the present command, starting from standstill (every channel has this pin)";
pin out s32 counts "position in whole steps (rounded), updated by capture-position";
pin out float position_fb "position in machine units, with a resolution finer than a step; updated by capture-position";

see_also "pwmgen(9), encoder(9)";
author "the halsdk authors";
license "GPL";
option rtapi_app no;
;;

#include "rtapi_math.h"
#include "rtapi_string.h"

#define MAX_CHAN 16
#define MAX_USER 32
/* the accumulator counts steps with FRAC fractional bits */
#define FRAC 28
#define HALF_STEP (1LL << (FRAC - 1))

static int step_type[MAX_CHAN] = {
    -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1 };
RTAPI_MP_ARRAY_INT(step_type, MAX_CHAN, "step type of each channel, 0-15");
static char *ctrl_type[MAX_CHAN];
RTAPI_MP_ARRAY_STRING(ctrl_type, MAX_CHAN, "control mode of each channel, p or v");
static int user_step_type[MAX_USER] = {
    -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1,
    -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1 };
RTAPI_MP_ARRAY_INT(user_step_type, MAX_USER, "output words of step type 15");

/* output words of the state based step types (bit 0 is phase-A) */
static const unsigned char pat2[] = { 1, 3, 2, 0 };
static const unsigned char pat3[] = { 1, 2, 4 };
static const unsigned char pat4[] = { 1, 3, 2, 6, 4, 5 };
static const unsigned char pat5[] = { 1, 2, 4, 8 };
static const unsigned char pat6[] = { 3, 6, 12, 9 };
static const unsigned char pat7[] = { 1, 7, 14, 8 };
static const unsigned char pat8[] = { 5, 6, 10, 9 };
static const unsigned char pat9[] = { 1, 3, 2, 6, 4, 12, 8, 9 };
static const unsigned char pat10[] = { 1, 5, 7, 6, 14, 10, 8, 9 };
static const unsigned char pat11[] = { 1, 2, 4, 8, 16 };
static const unsigned char pat12[] = { 3, 6, 12, 24, 17 };
static const unsigned char pat13[] = { 1, 3, 2, 6, 4, 12, 8, 24, 16, 17 };
static const unsigned char pat14[] = { 3, 7, 6, 14, 12, 28, 24, 25, 17, 19 };
static unsigned char pat15[MAX_USER];

static const unsigned char *const pats[16] = {
    0, 0, pat2, pat3, pat4, pat5, pat6, pat7, pat8, pat9, pat10,
    pat11, pat12, pat13, pat14, pat15 };
static int pat_len[16] = { 0, 0, 4, 3, 6, 4, 4, 4, 4, 8, 8, 5, 5, 10, 10, 0 };
static int pat_pins[16] = { 2, 2, 2, 3, 3, 4, 4, 4, 4, 4, 4, 5, 5, 5, 5, 0 };

typedef struct {
    /* used by make-pulses (fast thread); what every run reads and writes
       comes first, in the channel's first two cache lines */
    long long acc;          /* position in steps << FRAC, plus half a step */
    long add;               /* added to acc each base period */
    long add_goal;          /* add value asked for by update-freq */
    long add_slew;          /* largest change of add per base period */
    unsigned long t_pulse;  /* ns until the step pulse may end */
    unsigned long t_dir;    /* ns until the direction output may change */
    unsigned long t_rev;    /* ns until motion may restart the other way */
    hal_bit_t *en;
    int dir;                /* +1 forward, -1 reverse */
    int held;               /* waiting for t_rev before reversing */
    int step_on, dir_on;    /* step type 0: what step and dir show */
    int type;
    hal_s32_t rawcount;
    hal_bit_t *out[5];      /* step/dir, up/down or the phases */
    int state;              /* index in the pattern (types 2 and up) */
    int nstates;
    int npins;              /* phase pins (types 2 and up) */
    const unsigned char *pat;
    hal_u32_t steplen, stepspace, dirsetup, dirhold;  /* dirhold is dirdelay */
    unsigned long hold_ns;  /* dirhold as used, never 0 for types 1 and up */
    /* used by update-freq and capture-position (slow thread) */
    int posmode;
    double last_cmd;        /* position command of the last run, in steps */
    double old_scale;
    double fb_scale;        /* acc units to machine units */
    hal_u32_t old_len, old_space, old_setup, old_hold;
    hal_float_t *pos_cmd, *vel_cmd, *pos_fb;
    hal_s32_t *cnt;
    hal_float_t scale, maxvel, maxaccel, freq;
    int warned;
} chan_t;

static chan_t *chans;
static int nchan;

/* period of make-pulses, seen by update-freq; until make-pulses has run
   it is taken to be 50 us (the timing values are rounded to that first) */
static long base_ns = 50000, old_base_ns, old_servo_ns;
static double add_per_hz, slew_per_hz_s, servo_dt, servo_rate;

static void tick(unsigned long *t, unsigned long ns)
{
    *t = *t > ns ? *t - ns : 0;
}

/* the phases show the pattern word of the present state (every run: a
   pin linked to a new signal shows the state at once) */
static void show_state(chan_t *c)
{
    unsigned w = c->pat[c->state];

    switch (c->npins) {
    case 5:
        *c->out[4] = (w >> 4) & 1;
        /* fall through */
    case 4:
        *c->out[3] = (w >> 3) & 1;
        /* fall through */
    case 3:
        *c->out[2] = (w >> 2) & 1;
        /* fall through */
    case 2:
        *c->out[1] = (w >> 1) & 1;
        /* fall through */
    case 1:
        *c->out[0] = w & 1;
        break;
    default:
        break;
    }
}

static void make_pulses(void *arg, long period)
{
    chan_t *c = arg;
    /* the outputs are bool stores, which may alias anything: a count
       read in the loop would be read again on every channel */
    chan_t *const end = c + nchan;

    base_ns = period;
    for (; c < end; c++) {
        long add;
        long long acc;
        int stepped;

        /* t_rev >= t_dir >= t_pulse always: all three are 0 at once */
        if (c->t_rev) {
            tick(&c->t_pulse, period);
            tick(&c->t_dir, period);
            tick(&c->t_rev, period);
        }
        if (!*c->en) {
            /* let a pulse in progress finish */
            if (c->t_pulse == 0) {
                if (c->type == 0)
                    *c->out[0] = c->step_on = 0;
                else if (c->type == 1)
                    *c->out[0] = *c->out[1] = 0;
            }
            if (c->type >= 2 && c->nstates > 0)
                show_state(c);
            continue;
        }
        /* a reversal held for t_rev goes on once it has run out */
        if (c->held && c->t_rev == 0)
            c->held = 0;
        /* ramp the add value; it stays put while a reversal waits */
        if (!c->held) {
            add = c->add_goal;
            if (c->add_slew != 0) {
                /* the bounds wrap around, as two's complement sums do in
                   the reference (only a NaN maxaccel or command gets near:
                   then add alternates between the goal and 0 as there) */
                long hi = (long)((unsigned long)c->add
                                 + (unsigned long)c->add_slew);
                long lo = (long)((unsigned long)c->add
                                 - (unsigned long)c->add_slew);
                if (add > hi)
                    add = hi;
                else if (add < lo)
                    add = lo;
            }
            c->add = add;
        }
        add = c->add;
        /* zero counts as forward: the signs of add and dir (+1 or -1)
           differ when the xor of the two is negative */
        if ((add ^ (long)c->dir) < 0) {
            if (c->t_rev != 0)
                c->held = 1;
            else
                c->dir = -c->dir;
        }
        if (c->type == 0) {
            /* the outputs are written when they change: fewer stores to
               shared memory in the common case of nothing to do */
            /* the likely false test first: the direction shown is right
               and no pulse is up */
            if ((add < 0) != c->dir_on && add != 0 && c->t_dir == 0)
                *c->out[1] = c->dir_on = add < 0;
            if (c->step_on && c->t_pulse == 0)
                *c->out[0] = c->step_on = 0;
        } else if (c->type == 1) {
            if (c->t_pulse == 0)
                *c->out[0] = *c->out[1] = 0;
        }
        stepped = 0;
        if (!c->held) {
            acc = c->acc + add;
            /* a step is a toggle of the step bit (at most one step a
               period): a jump of the accumulator by a multiple of two
               steps (a NaN command) makes none, as in the reference */
            stepped = (int)(((acc ^ c->acc) >> FRAC) & 1);
            c->acc = acc;
            c->rawcount = acc >> FRAC;
        }
        if (stepped) {
            c->t_pulse = c->steplen;
            c->t_dir = c->steplen + c->hold_ns;
            c->t_rev = c->t_dir + c->dirsetup;
            if (c->type == 0) {
                *c->out[0] = c->step_on = 1;
            } else if (c->type == 1) {
                *c->out[c->dir > 0 ? 0 : 1] = 1;
            } else if (c->nstates > 0) {
                int s = c->state + c->dir;
                if (s < 0)
                    s = c->nstates - 1;
                else if (s >= c->nstates)
                    s = 0;
                c->state = s;
            }
        }
        if (c->type >= 2 && c->nstates > 0)
            show_state(c);
    }
}

/* round a time up to a whole number of base periods */
static hal_u32_t round_up(hal_u32_t ns, long per)
{
    unsigned long p = per;
    return (hal_u32_t)(((ns + p - 1) / p) * p);
}

static void check_scale(chan_t *c)
{
    if (c->scale == c->old_scale)
        return;
    c->old_scale = c->scale;
    /* a zero scale would divide by zero */
    if (c->scale < 1e-20 && c->scale > -1e-20)
        c->scale = 1.0;
    c->fb_scale = (1.0 / (1L << FRAC)) / c->scale;
}

static void update_freq(void *arg, long period)
{
    chan_t *c = arg;
    int n, new_base = 0;

    if (base_ns != old_base_ns) {
        double bp = base_ns * 0.000000001;
        old_base_ns = base_ns;
        add_per_hz = (1L << FRAC) * bp;
        slew_per_hz_s = add_per_hz * bp;
        new_base = 1;
    }
    if (period != old_servo_ns) {
        old_servo_ns = period;
        servo_dt = period * 0.000000001;
        servo_rate = 1.0 / servo_dt;
    }
    for (n = 0; n < nchan; n++, c++) {
        double top, acc_lim, goal, v;
        long min_ns;

        check_scale(c);
        if (new_base)
            c->old_len = c->old_space = c->old_setup = c->old_hold = ~0u;
        if (c->steplen != c->old_len) {
            if (c->steplen == 0)
                c->steplen = 1;
            c->steplen = c->old_len = round_up(c->steplen, base_ns);
        }
        if (c->stepspace != c->old_space)
            c->stepspace = c->old_space = round_up(c->stepspace, base_ns);
        if (c->dirsetup != c->old_setup)
            c->dirsetup = c->old_setup = round_up(c->dirsetup, base_ns);
        if (c->dirhold != c->old_hold) {
            if (c->dirhold + c->dirsetup == 0 && c->type == 0)
                c->dirhold = 1;
            c->dirhold = c->old_hold = round_up(c->dirhold, base_ns);
            /* types 1 and up keep at least one period between reversals */
            c->hold_ns = c->dirhold;
            if (c->dirhold + c->dirsetup == 0 && c->type > 0)
                c->hold_ns = round_up(1, base_ns);
        }
        if (!*c->en) {
            /* track the command so that enabling sees no jump in velocity */
            if (c->posmode)
                c->last_cmd = *c->pos_cmd * c->scale;
            c->freq = 0;
            c->add = 0;
            c->add_goal = 0;
            continue;
        }
        /* fastest step rate the timing allows */
        min_ns = c->steplen + c->stepspace;
        top = 1.0 / (min_ns * 0.000000001);
        if (c->maxvel <= 0.0) {
            c->maxvel = 0.0;
        } else {
            double want = c->maxvel * fabs(c->scale);
            if (want > top) {
                if (!c->warned) {
                    rtapi_print_msg(RTAPI_MSG_ERR,
                        "STEPGEN: Channel %d: The requested maximum velocity of %d steps/sec is too high.\n",
                        n, (int)want);
                    rtapi_print_msg(RTAPI_MSG_ERR,
                        "STEPGEN: The maximum possible frequency is %d steps/second\n",
                        (int)top);
                    c->warned = 1;
                }
                c->maxvel = top / fabs(c->scale);
            } else {
                top = want;
            }
        }
        /* without a limit: full speed in one servo period */
        acc_lim = top * servo_rate;
        if (c->maxaccel <= 0.0) {
            c->maxaccel = 0.0;
        } else if (c->maxaccel * fabs(c->scale) > acc_lim) {
            c->maxaccel = acc_lim / fabs(c->scale);
        } else {
            acc_lim = c->maxaccel * fabs(c->scale);
        }
        if (c->posmode) {
            /* all in steps, steps/s and steps/s^2 */
            double cmd = *c->pos_cmd * c->scale;
            double cmd_v = (cmd - c->last_cmd) * servo_rate;
            double here = (c->acc - HALF_STEP) * (1.0 / (1L << FRAC));
            double vel = c->freq;
            double a, t, end_pos, end_cmd, err;

            c->last_cmd = cmd;
            /* time to reach the command velocity at full accel */
            a = cmd_v > vel ? acc_lim : -acc_lim;
            t = (cmd_v - vel) / a;
            /* where we and the command would be by then */
            end_pos = here + (cmd_v + vel) * 0.5 * t;
            end_cmd = cmd + cmd_v * (t - 1.5 * servo_dt);
            err = end_pos - end_cmd;
            if (t < servo_dt) {
                /* velocity matches within this period */
                if (fabs(err) < 0.0001) {
                    v = cmd_v;
                } else {
                    /* and steer out half of the position error */
                    v = cmd_v - 0.5 * err * servo_rate;
                    if (v > vel + acc_lim * servo_dt)
                        v = vel + acc_lim * servo_dt;
                    else if (v < vel - acc_lim * servo_dt)
                        v = vel - acc_lim * servo_dt;
                }
            } else {
                /* accelerate the other way if that ends closer */
                double dp = -2.0 * a * servo_dt * t;
                if (fabs(err + dp * 2.0) < fabs(err))
                    a = -a;
                v = vel + a * servo_dt;
            }
            if (v > top)
                v = top;
            else if (v < -top)
                v = -top;
        } else {
            double dv = acc_lim * servo_dt;
            goal = *c->vel_cmd * c->scale;
            if (goal > top)
                goal = top;
            else if (goal < -top)
                goal = -top;
            if (goal > c->freq + dv)
                v = c->freq + dv;
            else if (goal < c->freq - dv)
                v = c->freq - dv;
            else
                v = goal;
        }
        c->freq = v;
        c->add_goal = c->freq * add_per_hz;
        c->add_slew = acc_lim * slew_per_hz_s;
    }
}

static void capture_position(void *arg, long period)
{
    chan_t *c = arg;
    int n;

    for (n = 0; n < nchan; n++, c++) {
        long long acc = c->acc;
        *c->cnt = acc >> FRAC;
        check_scale(c);
        *c->pos_fb = (double)(acc - HALF_STEP) * c->fb_scale;
    }
}

static int make_channel(int n, chan_t *c)
{
    static const char *const names[2][2] = { { "step", "dir" }, { "up", "down" } };
    int r, k, t = c->type;

    r = hal_pin_bit_newf(HAL_IN, &c->en, comp_id, "stepgen.%d.enable", n);
    if (r) return r;
    r = hal_pin_s32_newf(HAL_OUT, &c->cnt, comp_id, "stepgen.%d.counts", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_OUT, &c->pos_fb, comp_id, "stepgen.%d.position-fb", n);
    if (r) return r;
    if (c->posmode)
        r = hal_pin_float_newf(HAL_IN, &c->pos_cmd, comp_id, "stepgen.%d.position-cmd", n);
    else
        r = hal_pin_float_newf(HAL_IN, &c->vel_cmd, comp_id, "stepgen.%d.velocity-cmd", n);
    if (r) return r;
    for (k = 0; k < pat_pins[t]; k++) {
        if (t < 2)
            r = hal_pin_bit_newf(HAL_OUT, &c->out[k], comp_id, "stepgen.%d.%s", n, names[t][k]);
        else
            r = hal_pin_bit_newf(HAL_OUT, &c->out[k], comp_id, "stepgen.%d.phase-%c", n, 'A' + k);
        if (r) return r;
    }
    r = hal_param_float_newf(HAL_RW, &c->scale, comp_id, "stepgen.%d.position-scale", n);
    if (r) return r;
    r = hal_param_float_newf(HAL_RW, &c->maxvel, comp_id, "stepgen.%d.maxvel", n);
    if (r) return r;
    r = hal_param_float_newf(HAL_RW, &c->maxaccel, comp_id, "stepgen.%d.maxaccel", n);
    if (r) return r;
    r = hal_param_float_newf(HAL_RO, &c->freq, comp_id, "stepgen.%d.frequency", n);
    if (r) return r;
    r = hal_param_s32_newf(HAL_RO, &c->rawcount, comp_id, "stepgen.%d.rawcounts", n);
    if (r) return r;
    r = hal_param_u32_newf(HAL_RW, &c->steplen, comp_id, "stepgen.%d.steplen", n);
    if (r) return r;
    if (t < 2) {
        r = hal_param_u32_newf(HAL_RW, &c->stepspace, comp_id, "stepgen.%d.stepspace", n);
        if (r) return r;
    }
    if (t == 0) {
        r = hal_param_u32_newf(HAL_RW, &c->dirsetup, comp_id, "stepgen.%d.dirsetup", n);
        if (r) return r;
        r = hal_param_u32_newf(HAL_RW, &c->dirhold, comp_id, "stepgen.%d.dirhold", n);
    } else {
        r = hal_param_u32_newf(HAL_RW, &c->dirhold, comp_id, "stepgen.%d.dirdelay", n);
    }
    if (r) return r;

    c->scale = 1.0;
    c->old_scale = c->scale + 1.0;
    c->steplen = 1;
    c->stepspace = t < 2 ? 1 : 0;
    c->dirsetup = t == 0 ? 1 : 0;
    c->dirhold = 1;
    c->old_len = c->old_space = c->old_setup = c->old_hold = ~0u;
    c->acc = HALF_STEP;
    c->dir = 1;
    c->pat = pats[t];
    c->nstates = pat_len[t];
    c->npins = pat_pins[t];
    return 0;
}

int rtapi_app_main(void)
{
    int n, r, users = 0, user_pins = 0;
    int posmode[MAX_CHAN];

    for (nchan = 0; nchan < MAX_CHAN && step_type[nchan] != -1; nchan++) {
        if (step_type[nchan] < 0 || step_type[nchan] > 15) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                "STEPGEN: ERROR: bad stepping type '%i', axis %i\n",
                step_type[nchan], nchan);
            return -EPERM;
        }
        posmode[nchan] = 1;
        if (ctrl_type[nchan] && ctrl_type[nchan][0]) {
            char m = ctrl_type[nchan][0];
            if (m == 'v' || m == 'V') {
                posmode[nchan] = 0;
            } else if (m != 'p' && m != 'P') {
                rtapi_print_msg(RTAPI_MSG_ERR,
                    "STEPGEN: ERROR: bad control type '%c' for axis %i (must be 'p' or 'v')\n",
                    m, nchan);
                return -EPERM;
            }
        }
    }
    if (nchan == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "STEPGEN: ERROR: no channels configured\n");
        return -EPERM;
    }
    /* step type 15: one state for each value given */
    for (users = 0; users < MAX_USER && user_step_type[users] != -1; users++) {
        user_pins |= user_step_type[users];
        pat15[users] = user_step_type[users];
    }
    if (user_pins > 31) {
        rtapi_print_msg(RTAPI_MSG_ERR,
            "STEPGEN: ERROR: bad user step type uses more than 5 phases");
        return -EINVAL;
    }
    pat_len[15] = users;
    for (n = 0; user_pins >> n; n++)
        ;
    pat_pins[15] = n;

    comp_id = hal_init("stepgen");
    if (comp_id < 0)
        return comp_id;
    chans = hal_malloc(nchan * sizeof(chan_t));
    if (!chans) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    memset(chans, 0, nchan * sizeof(chan_t));
    for (n = 0; n < nchan; n++) {
        chans[n].type = step_type[n];
        chans[n].posmode = posmode[n];
        r = make_channel(n, &chans[n]);
        if (r) {
            hal_exit(comp_id);
            return r;
        }
    }
    r = hal_export_funct("stepgen.make-pulses", make_pulses, chans, 0, 0, comp_id);
    if (!r)
        r = hal_export_funct("stepgen.update-freq", update_freq, chans, 1, 0, comp_id);
    if (!r)
        r = hal_export_funct("stepgen.capture-position", capture_position, chans, 1, 0, comp_id);
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
