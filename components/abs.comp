component abs "Absolute value of a float, with sign flags";

pin in float in "The value to take the magnitude of";
pin out float out """The magnitude of in: never negative (a NaN in gives a
NaN with the opposite sign bit, as in LinuxCNC)""";
pin out bit sign "TRUE when in is below zero or NaN (-0.0 counts as positive)";
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

    if (v != v) {
        /* NaN: as LinuxCNC, out is the NaN with its sign bit flipped,
           and sign is TRUE */
        out = -v;
        sign = 1;
    } else {
        out = fabs(v);
        sign = v < 0;
    }
    /* a small band around zero counts as zero for the flags */
    is_positive = v > 1e-6;
    is_negative = v < -1e-6;
}
