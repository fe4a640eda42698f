component conv_u32_s32 "Convert a value from u32 to s32";

pin in u32 in "The value to convert";
pin out s32 out "The input as s32, wrapped or clamped as the clamp parameter says";
pin out bit out_of_range "TRUE when the last conversion could not represent the input exactly (see the description)";

param rw bit clamp "TRUE: out-of-range inputs give the nearest end of the output range; FALSE: the conversion wraps around as a plain C cast does";

function _ nofp "Convert in and update out";

description """
With \\fBclamp\\fR TRUE, an input beyond the output range gives the nearest end
of the range and sets \\fBout-of-range\\fR; an input inside the range clears it.
With \\fBclamp\\fR FALSE, the bits are kept as they are (so the value wraps
around) and \\fBout-of-range\\fR is left unchanged.
""";
see_also "conv_bit_float(9), conv_float_s32(9), conv_s32_u32(9), conv_u32_bit(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    rtapi_u32 v = in;
    if (clamp) {
        out = v > 2147483647u ? 2147483647 : (rtapi_s32)v;
        out_of_range = v > 2147483647u;
    } else {
        /* the bits are kept; the flag is left as it was (see above) */
        out = (rtapi_s32)v;
    }
}
