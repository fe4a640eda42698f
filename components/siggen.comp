component siggen """Signal generator: sine, cosine, triangle, sawtooth and square waves
and a clock bit""";

description """
siggen makes test waveforms, for example to drive a position loop while
tuning it, or to exercise another component.  Each channel keeps a phase
that advances by \\fBfrequency\\fR times the thread period each time its
update function runs; one cycle of every waveform takes the phase from 0 to
1, after which it starts again from 0.

All outputs of a channel come from the same phase, so they keep a fixed
relation to each other:
.nf

    phase      0      0.25    0.5     0.75    1
    sine       0      +A      0       -A      0
    cosine     +A     0       -A      0       +A
    triangle   +A     0       -A      0       +A
    sawtooth   -A     -A/2    0       +A/2    +A  (then drops to -A)
    square     -A     -A      -A      +A      +A
    clock      false  false   false   true    true
.fi

(A is \\fBamplitude\\fR; \\fBoffset\\fR is added to every float output.)
square and clock are high during the second half of each cycle.

The frequency is limited to half the sample rate (1 / (2 * period)); a
larger value is written back to the \\fBfrequency\\fR pin as that limit.
A negative frequency runs the phase backwards; it is then not brought
back into 0..1, so triangle and sawtooth keep growing beyond the amplitude
and sine and cosine lose precision over time: use a negative amplitude to
invert the waveforms instead.

Call the update function many times faster than the frequency wanted, or
the waveforms are coarse and the sine and cosine alias.
""";

notes """
siggen makes at most 16 channels.  num_chan= and names= cannot be given
together; with neither there is one channel, siggen.0.
""";

modparam dummy num_chan """Number of channels to make (1 to 16, default 1); channels are
named siggen.0, siggen.1, ...""";
modparam dummy names """Comma-separated names of the channels to make (at most 16),
instead of num_chan""";

pin in float frequency = 1.0 "Frequency of the waveforms, in Hz (cycles per second).  Limited to 1 / (2 * thread period); a larger value is replaced by that limit.";
pin in float amplitude = 1.0 "Peak value of the waveforms: with offset 0 they swing from -amplitude to +amplitude.";
pin in float offset "Added to every float output (the centre line of the waveforms).";
pin in bit reset "While true the phase is held at half a cycle: sine and sawtooth are at offset, cosine, triangle and square at offset - amplitude, clock is false.";

pin out float square "Square wave: -amplitude in the first half of each cycle, +amplitude in the second (plus offset).";
pin out float sine "Sine wave; it lags cosine by a quarter cycle.";
pin out float cosine "Cosine wave; it leads sine by a quarter cycle.";
pin out float triangle "Triangle wave: falls from +amplitude to -amplitude in the first half of each cycle and rises back in the second; its peaks coincide with those of cosine.";
pin out float sawtooth "Sawtooth wave: rises from -amplitude to +amplitude over each cycle, then drops back at once.";
pin out bit clock "Clock bit: false in the first half of each cycle, true in the second (in step with square).";

variable double phase;

function update "Advance the phase of the channel by one period and compute its outputs.";

option rtapi_app no;

see_also "sim_encoder(9), pid(9)";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

#define MAX_CHAN 16

/* the clamped frequency is written back to its input pin (as the
   reference does), so make that pin assignable here */
#undef frequency
#define frequency (*__comp_inst->frequency)
/* and read amplitude and offset as they are: the input pin names add 0,
   which turns a -0 into +0 (the reference keeps the sign of a -0 offset) */
#undef amplitude
#define amplitude (*__comp_inst->amplitude)
#undef offset
#define offset (*__comp_inst->offset)

/* 2*pi rounded to eight digits: the reference's sine and cosine carry
   this rounding, which shows in their sixth decimal and in the sign of
   their zeros */
#define TURN 6.2831854

static int num_chan;
RTAPI_MP_INT(num_chan, "number of channels");
static char *names[MAX_CHAN];
RTAPI_MP_ARRAY_STRING(names, MAX_CHAN, "names of the channels");

FUNCTION(update) {
    double f = frequency;
    double fmax = 0.5 / fperiod;
    double a = amplitude;
    double o = offset;
    double p, w, s;

    /* above half the sample rate the phase would alias; clamp and let
       the user see it on the pin */
    if (f > fmax) {
        f = fmax;
        frequency = f;
    }

    if (reset) {
        p = 0.5;
    } else {
        p = phase + f * fperiod;
        if (p >= 1.0)
            p -= 1.0;
    }
    phase = p;

    w = TURN * p;
    sine = a * sin(w) + o;
    cosine = a * cos(w) + o;
    /* the triangle is folded from the normalised sawtooth (2|2p-1| - 1),
       which rounds as the reference does for large amplitudes */
    s = 2.0 * p - 1.0;
    sawtooth = a * s + o;
    triangle = a * (2.0 * fabs(s) - 1.0) + o;
    if (p > 0.5) {
        clock = 1;
        square = a + o;
    } else {
        clock = 0;
        square = o - a;
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
            num_chan = 1;
        if (num_chan < 1 || num_chan > MAX_CHAN) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "SIGGEN: ERROR: invalid number of channels: %d\n",
                            num_chan);
            return -EPERM;
        }
    }

    comp_id = hal_init("siggen");
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
            rtapi_snprintf(buf, sizeof(buf), "siggen.%d", n);
            r = export(buf, n);
            if (r != 0)
                goto fail;
        }
    }
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
