component abs "Absolute value of a float, with sign flags";

pin in float in "The value to take the magnitude of";
pin out float out "The magnitude of in: never negative";
pin out bit sign "TRUE when in is below zero (-0.0 counts as positive)";
pin out bit is_positive """TRUE when in is above 1e-6. Values closer to zero
than that count as zero: neither positive nor negative""";
pin out bit is_negative "TRUE when in is below -1e-6";

function _ "Update out and the flags from in";

see_also "abs_s32(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double v = in;

    out = fabs(v);
    sign = v < 0;
    /* a small band around zero counts as zero for the flags */
    is_positive = v > 1e-6;
    is_negative = v < -1e-6;
}
