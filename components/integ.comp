component integ "Integrator with a gain and windup limits";

pin in float in "The signal to integrate";
pin in float gain = 1.0 "Factor applied to in before integrating";
pin out float out """The running integral of gain * in (per second), kept
between min and max""";
pin in bit reset "While TRUE, out is held at 0 (then limited to min and max)";
pin in float max = 1e20 "Upper limit of out: the integral stops growing there";
pin in float min = -1e20 "Lower limit of out; min wins when min > max";

function _ "Integrate one period";

see_also "ddt(9), limit1(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double v;

    if (reset)
        v = 0;
    else
        v = out + in * gain * fperiod;
    /* the upper limit first, so the lower one wins if they cross */
    if (v > max)
        v = max;
    if (v < min)
        v = min;
    out = v;
}
