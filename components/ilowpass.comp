component ilowpass "Low-pass filter of an integer signal, with integer output";

pin in s32 in "The integer signal to filter (e.g. MPG encoder counts)";
pin out s32 out """in * scale through a low-pass filter, rounded to the nearest
integer (halves round up). Beyond the s32 range it wraps around""";

param rw float scale = 1024 "Factor applied to in before filtering";
param rw float gain = .5 """Fraction of the remaining distance to in * scale
covered each period: 0 < gain <= 1; larger values follow in more quickly
(0.9 goes 90% of the way per period)""";

variable double value;

function _ "Filter one sample and update out";

description """Smooths a stepwise integer signal. Its main use is jogging
with a manual pulse generator on a machine with high acceleration: placed
between the MPG's encoder counts and the jog-counts input of an axis, it
turns each detent's step into a short ramp.

The filter keeps a floating-point state, so small steps are not lost to
rounding. Because out is in * scale, divide the jog scale by scale; choose
scale small enough that in * scale stays within about 2e9 for a session.""";
see_also "lowpass(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double r;

    value += (in * scale - value) * gain;
    r = floor(value + 0.5);
    /* out of range: keep the low 32 bits, as the integer would wrap */
    out = (hal_s32_t)(hal_u32_t)(unsigned long long)(long long)r;
}
