component limit1 "Keep a signal between a minimum and a maximum";

pin in float in "The signal to limit";
pin out float out "in, clamped to [min, max]";
pin in float min = -1e20 "Lowest value out may take";
pin in float max = 1e20 "Highest value out may take; it wins when max < min";

function _ "Compute out";

see_also "limit2(9), limit3(9), wcomp(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double v = in;

    /* the lower limit first, so max wins if the two cross */
    if (v < min)
        v = min;
    if (v > max)
        v = max;
    out = v;
}
