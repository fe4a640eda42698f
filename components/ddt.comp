component ddt "Rate of change of a signal";

pin in float in "The signal to differentiate";
pin out float out """Change of in since the previous run, divided by the thread
period in seconds""";

variable double prev;

function _ "Compute out and remember in";

notes """The derivative is a plain two-point difference, so it is only
meaningful when in changes every period; a signal updated more slowly gives
spikes separated by zeros. The first run compares in with 0.""";
see_also "integ(9), lowpass(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double v = in;

    out = (v - prev) / fperiod;
    prev = v;
}
