component lowpass "First-order low-pass filter";

pin in float in "The signal to filter";
pin out float out "out += (in - out) * gain, once per period";
pin in bit load "While TRUE, out is set to in (no filtering)";

param rw float gain """Fraction of the remaining distance to in covered each
period (0: out never moves, 1: no filtering)""";

function _ "Filter one sample";

notes """This is a single-pole filter H(s) = a / (s + a) sampled with a
zero-order hold at the thread period T. For a pole at a radians per second,
use gain = 1 - exp(-a * T). For T = 1 ms: a 100 Hz corner (a = 2*pi*100)
gives gain 0.466, 10 Hz gives 0.0609 and 1 Hz gives 0.0063.

gain is a parameter; the default 0 holds out where it is.""";
see_also "ilowpass(9), biquad(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (load)
        out = in;
    else
        out += (in - out) * gain;
}
