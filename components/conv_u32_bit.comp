component conv_u32_bit "Convert a value from u32 to bit";

pin in u32 in "The value to convert";
pin out bit out "The input as bit, wrapped or clamped as the clamp parameter says";
pin out bit out_of_range "TRUE when the last conversion could not represent the input exactly (see the description)";

param rw bit clamp "TRUE: out-of-range inputs give the nearest end of the output range; FALSE: the conversion wraps around as a plain C cast does";

function _ nofp "Convert in and update out";

description """
With \\fBclamp\\fR TRUE, an input beyond the output range gives the nearest end
of the range and sets \\fBout-of-range\\fR; an input inside the range clears it.
With \\fBclamp\\fR FALSE, the value wraps around and \\fBout-of-range\\fR is set
whenever the result, compared with the input, differs; it then stays set
until a clamped conversion clears it.
""";
see_also "conv_bit_float(9), conv_float_s32(9), conv_s32_u32(9), conv_u32_bit(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    rtapi_u32 v = in;
    if (clamp) {
        out = v > 0;
        out_of_range = v > 1;
    } else {
        out = v != 0;
        if (v > 1)
            out_of_range = 1;
    }
}
