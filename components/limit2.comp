component limit2 "Limit a signal to a range and its rate of change";

pin in float in "The signal to follow";
pin out float out """in clamped to [min, max], moving at most maxv per second
(when the signal is a position: position and velocity limits)""";
pin in bit load """While TRUE, out jumps to in (still clamped to [min, max])
without the maxv limit""";
pin in float min = -1e20 "Lowest target; it wins when min > max";
pin in float max = 1e20 "Highest target";
pin in float maxv = 1e20 "Largest change of out per second";

variable double last;

function _ "Move out one period towards in";

see_also "limit1(9), limit3(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double v = in;
    double step = maxv * fperiod;

    if (v < min)
        v = min;
    else if (v > max)
        v = max;
    if (!load) {
        if (v - last < -step)
            v = last - step;
        else if (v - last > step)
            v = last + step;
    }
    last = v;
    out = v;
}
