component near "Tell whether two values are nearly equal";

pin in float in1 "First value";
pin in float in2 "Second value";
pin out bit out """TRUE when in2 lies within a factor scale of in1 (in1 > 0:
in1/scale <= in2 <= in1*scale; for in1 < 0 the bounds swap), or when
|in1 - in2| <= difference""";

param rw float scale = 1 "Ratio allowed between the values; 1 or below: none";
param rw float difference = 0 "Absolute difference allowed between the values";

function _ "Compare in1 and in2";

notes """The ratio test only matches values of the same sign; use
difference for values near zero. A scale below 1 never matches by ratio.""";
see_also "comp(9), wcomp(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double a = in1, b = in2;
    int r;

    if (a > 0)
        r = a / scale <= b && b <= a * scale;
    else
        r = a * scale <= b && b <= a / scale;
    out = r || fabs(a - b) <= difference;
}
