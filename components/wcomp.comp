component wcomp "Window comparator";

pin in float in "The value to test";
pin in float min "Lower edge of the window";
pin in float max "Upper edge of the window";
pin out bit out "TRUE when min < in < max";
pin out bit under "TRUE when in <= min";
pin out bit over "TRUE when in >= max";

function _ "Compare in with the window";

notes """The edges belong to under and over, not to the window. With
max <= min the window is empty: out is always FALSE and under and over may
both be TRUE.""";
see_also "comp(9), near(9), limit1(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double v = in, lo = min, hi = max;

    out = v > lo && v < hi;
    under = v <= lo;
    over = v >= hi;
}
