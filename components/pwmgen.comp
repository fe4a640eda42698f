component pwmgen "software PWM and PDM generator";

description """
\\fBpwmgen\\fR makes pulse width modulated (PWM) or pulse density modulated
(PDM) outputs in software, for up to 8 channels, e.g. to drive a spindle
speed input, a heater or an H-bridge.  Load it with

.B loadrt pwmgen output_type=\\fIT0\\fB[,\\fIT1\\fB...]

One channel is made for each value, numbered from 0.  Output types:
.TP
\\fB0\\fR
one output, \\fBpwm\\fR; negative commands give no output (or
\\fBmin-dc\\fR).
.TP
\\fB1\\fR
\\fBpwm\\fR and \\fBdir\\fR; the duty cycle follows the size of the
command and \\fBdir\\fR is high when it is negative.
.TP
\\fB2\\fR
\\fBup\\fR and \\fBdown\\fR; the waveform is on \\fBup\\fR for
positive commands and on \\fBdown\\fR for negative ones, the other output
stays low (for the two halves of an H-bridge).
.PP
The duty cycle is \\fBvalue\\fR/\\fBscale\\fR + \\fBoffset\\fR (1.0 is 100%),
kept between \\fBmin-dc\\fR and \\fBmax-dc\\fR (in size).  With
\\fBpwm-freq\\fR 0 the output is PDM: on and off times are whole periods of
\\fBmake-pulses\\fR, mixed so that their average is the duty cycle.  Otherwise
it is PWM at \\fBpwm-freq\\fR Hz, at most half the \\fBmake-pulses\\fR rate.
Without \\fBdither-pwm\\fR the PWM period is a whole number of \\fBmake-pulses\\fR
periods (\\fBpwm-freq\\fR is changed to the frequency really made) and the duty
cycle is rounded to whole periods too; with \\fBdither-pwm\\fR the high time
varies from one PWM period to the next so that the average is right.

Functions (each handles every channel):
.TP
\\fBpwmgen.make-pulses\\fR (no floating point)
makes the waveforms; put it in
a fast base thread.  Its period sets the resolution.
.TP
\\fBpwmgen.update\\fR
applies scale, offset and limits to \\fBvalue\\fR; a servo
thread is fast enough.  Run \\fBmake-pulses\\fR before it: until
\\fBmake-pulses\\fR has run once its period is unknown, and a PWM channel
configured then ends up in PDM mode with \\fBpwm-freq\\fR 0.

.PP
More pins of channel N (see also PINS below; the I/O pins are settings that pwmgen may correct):
.TP
\\fBpwmgen.\\fIN\\fB.pwm\\fR, \\fB.dir\\fR / \\fB.up\\fR, \\fB.down\\fR bit out
the outputs of the output type.
.TP
\\fBpwmgen.\\fIN\\fB.scale\\fR float io (default 1), \\fB.offset\\fR float io (default 0)
duty cycle = value/scale + offset.
.TP
\\fBpwmgen.\\fIN\\fB.min-dc\\fR float io (default 0), \\fB.max-dc\\fR float io (default 1)
the smallest and largest duty cycle while enabled (0.0 to 1.0).
.TP
\\fBpwmgen.\\fIN\\fB.pwm-freq\\fR float io (default 0)
PWM frequency in Hz; 0 for PDM.
.TP
\\fBpwmgen.\\fIN\\fB.dither-pwm\\fR bit io (default false)
dither the PWM high time for a finer average duty cycle.
""";

see_also "stepgen(9)";
author "the halsdk authors";
license "GPL";
option rtapi_app no;

pin in bit enable "the outputs are low while false (every channel has this pin)";
pin in float value "the command (every channel has this pin)";
pin out float curr_dc "the duty cycle being made, -1.0 to 1.0, after scaling, limits and rounding (every channel has this pin)";
;;

#include "rtapi_string.h"

#define MAX_CHAN 8

static int output_type[MAX_CHAN] = { -1, -1, -1, -1, -1, -1, -1, -1 };
RTAPI_MP_ARRAY_INT(output_type, MAX_CHAN, "output type of each channel, 0-2");

enum { OFF, PWM, DITHER, PDM };

typedef struct {
    /* used by make-pulses */
    long per_ns;            /* PWM period */
    long on_ns;             /* high time wanted per PWM period */
    long per_t;             /* time into the present PWM period */
    long on_t;              /* high time counter */
    int mode;
    int out;                /* present state of the waveform */
    int neg;                /* command is negative */
    int type;
    hal_bit_t *o[2];        /* pwm/dir or up/down */
    /* used by update */
    int steps;              /* base periods per PWM period (PWM mode) */
    double steps_inv;
    double old_scale, inv_scale, old_freq;
    hal_bit_t *en, *dither;
    hal_float_t *val, *scale, *offset, *freq, *min_dc, *max_dc, *cur_dc;
} chan_t;

static chan_t *chans;
static int nchan;
/* period of make-pulses; -1 until it has run (the reference's start value:
   a channel set up before then gets a negative pwm-freq, which the next
   update turns into 0, i.e. PDM) */
static long base_ns = -1;

static void make_pulses(void *arg, long period)
{
    chan_t *c = arg;
    int n;

    base_ns = period;
    for (n = 0; n < nchan; n++, c++) {
        switch (c->mode) {
        case PWM:
            /* high for on_ns from the start of each period */
            if (c->out) {
                c->on_t += period;
                if (c->on_t >= c->on_ns)
                    c->out = 0;
            }
            c->per_t += period;
            if (c->per_t >= c->per_ns) {
                c->per_t = 0;
                c->on_t = 0;
                if (c->on_ns > 0)
                    c->out = 1;
            }
            break;
        case DITHER:
            /* like PWM, but the rounding error is carried over */
            if (c->out) {
                c->on_t -= period;
                if (c->on_t <= 0)
                    c->out = 0;
            }
            c->per_t += period;
            if (c->per_t >= c->per_ns) {
                c->per_t -= c->per_ns;
                c->on_t += c->on_ns;
                if (c->on_t > 0)
                    c->out = 1;
            }
            break;
        case PDM:
            /* on whenever the wanted on time is ahead of the real one */
            c->on_t += c->on_ns;
            if (c->out)
                c->on_t -= period;
            c->out = c->on_t > 0;
            break;
        default:
            c->out = 0;
            c->on_t = 0;
            c->per_t = 0;
            break;
        }
        if (c->type < 2) {
            *c->o[0] = c->out;
        } else {
            *c->o[0] = c->out && !c->neg;
            *c->o[1] = c->out && c->neg;
        }
    }
}

static void update(void *arg, long period)
{
    chan_t *c = arg;
    int n;

    for (n = 0; n < nchan; n++, c++) {
        int mode;
        double dc, mag;

        /* keep 0 <= min-dc <= max-dc <= 1 */
        if (*c->max_dc > 1.0)
            *c->max_dc = 1.0;
        if (*c->min_dc > *c->max_dc)
            *c->min_dc = *c->max_dc;
        if (*c->min_dc < 0.0)
            *c->min_dc = 0.0;
        if (*c->max_dc < *c->min_dc)
            *c->max_dc = *c->min_dc;
        if (*c->scale != c->old_scale) {
            c->old_scale = *c->scale;
            /* a zero scale would divide by zero */
            if (*c->scale < 1e-20 && *c->scale > -1e-20)
                *c->scale = 1.0;
            c->inv_scale = 1.0 / *c->scale;
        }
        if (!*c->en)
            mode = OFF;
        else if (*c->freq == 0)
            mode = PDM;
        else if (*c->dither)
            mode = DITHER;
        else
            mode = PWM;
        /* a negative frequency means PDM, from the next run on */
        if (*c->freq < 0.0)
            *c->freq = 0;
        /* a new frequency restarts the waveform */
        if (*c->freq != c->old_freq)
            c->mode = OFF;
        if (c->mode != mode) {
            c->mode = OFF;
            if (*c->freq != 0) {
                if (*c->freq < 0.5) {
                    *c->freq = 0.5;
                } else if (*c->freq > 0.5e9 / base_ns) {
                    *c->freq = 0.5e9 / base_ns;
                }
            }
            if (*c->freq != 0) {
                c->per_ns = 1.0e9 / *c->freq;
                if (mode == PWM) {
                    /* a whole number of base periods */
                    c->steps = (c->per_ns * 1.0) / base_ns + 0.5;
                    c->steps_inv = 1.0 / c->steps;
                    c->per_ns = c->steps * base_ns;
                    *c->freq = 1.0e9 / c->per_ns;
                }
            }
            c->old_freq = *c->freq;
        }
        dc = *c->val * c->inv_scale + *c->offset;
        if (c->type == 0 && dc < 0.0)
            dc = 0.0;
        if (dc >= 0.0) {
            if (dc > *c->max_dc)
                dc = *c->max_dc;
            else if (dc < *c->min_dc)
                dc = *c->min_dc;
            c->neg = 0;
            mag = dc;
        } else {
            if (dc < -*c->max_dc)
                dc = -*c->max_dc;
            else if (dc > -*c->min_dc)
                dc = -*c->min_dc;
            c->neg = 1;
            mag = -dc;
        }
        if (mode == PWM) {
            /* whole base periods of high time */
            int k = c->steps * mag + 0.5;
            c->on_ns = k * base_ns;
            *c->cur_dc = (dc >= 0 ? k : -k) * c->steps_inv;
        } else {
            c->on_ns = c->per_ns * mag + 0.5;
            *c->cur_dc = dc;
        }
        if (mode == PDM)
            c->on_ns = base_ns * mag + 0.5;
        if (c->type == 1)
            *c->o[1] = c->neg;
        c->mode = mode;
    }
}

static int make_channel(int n, chan_t *c)
{
    int r;

    r = hal_pin_bit_newf(HAL_IN, &c->en, comp_id, "pwmgen.%d.enable", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_IN, &c->val, comp_id, "pwmgen.%d.value", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_OUT, &c->cur_dc, comp_id, "pwmgen.%d.curr-dc", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_IO, &c->scale, comp_id, "pwmgen.%d.scale", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_IO, &c->offset, comp_id, "pwmgen.%d.offset", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_IO, &c->min_dc, comp_id, "pwmgen.%d.min-dc", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_IO, &c->max_dc, comp_id, "pwmgen.%d.max-dc", n);
    if (r) return r;
    r = hal_pin_float_newf(HAL_IO, &c->freq, comp_id, "pwmgen.%d.pwm-freq", n);
    if (r) return r;
    r = hal_pin_bit_newf(HAL_IO, &c->dither, comp_id, "pwmgen.%d.dither-pwm", n);
    if (r) return r;
    if (c->type == 2) {
        r = hal_pin_bit_newf(HAL_OUT, &c->o[0], comp_id, "pwmgen.%d.up", n);
        if (r) return r;
        r = hal_pin_bit_newf(HAL_OUT, &c->o[1], comp_id, "pwmgen.%d.down", n);
    } else {
        r = hal_pin_bit_newf(HAL_OUT, &c->o[0], comp_id, "pwmgen.%d.pwm", n);
        if (r) return r;
        if (c->type == 1)
            r = hal_pin_bit_newf(HAL_OUT, &c->o[1], comp_id, "pwmgen.%d.dir", n);
    }
    if (r) return r;
    *c->scale = 1.0;
    *c->max_dc = 1.0;
    c->old_scale = *c->scale + 1.0;
    c->mode = OFF;
    return 0;
}

int rtapi_app_main(void)
{
    int n, r;

    for (nchan = 0; nchan < MAX_CHAN && output_type[nchan] != -1; nchan++) {
        if (output_type[nchan] < 0 || output_type[nchan] > 2) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                "PWMGEN: ERROR: bad output type '%i', channel %i\n",
                output_type[nchan], nchan);
            return -EPERM;
        }
    }
    if (nchan == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "PWMGEN: ERROR: no channels configured\n");
        return -EPERM;
    }
    comp_id = hal_init("pwmgen");
    if (comp_id < 0)
        return comp_id;
    chans = hal_malloc(nchan * sizeof(chan_t));
    if (!chans) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    memset(chans, 0, nchan * sizeof(chan_t));
    for (n = 0; n < nchan; n++) {
        chans[n].type = output_type[n];
        r = make_channel(n, &chans[n]);
        if (r) {
            hal_exit(comp_id);
            return r;
        }
    }
    r = hal_export_funct("pwmgen.make-pulses", make_pulses, chans, 0, 0, comp_id);
    if (!r)
        r = hal_export_funct("pwmgen.update", update, chans, 1, 0, comp_id);
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
