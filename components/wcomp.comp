component wcomp "Window comparator";

pin in float in "The value to test";
pin in float min "Lower edge of the window";
pin in float max "Upper edge of the window";
pin out bit out "TRUE when neither over nor under: min < in < max, or a NaN in in, min or max";
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

    under = v <= lo;
    over = v >= hi;
    /* neither over nor under: a NaN (in, min or max) counts as inside */
    out = !(over || under);
}
