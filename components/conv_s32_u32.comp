component conv_s32_u32 "Convert a value from s32 to u32";

pin in s32 in "The value to convert";
pin out u32 out "The input as u32, wrapped or clamped as the clamp parameter says";
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
    rtapi_s32 v = in;
    if (clamp) {
        out = v < 0 ? 0 : (rtapi_u32)v;
        out_of_range = v < 0;
    } else {
        /* the bits are kept; compared as unsigned the two are always equal,
           so the flag is left as it was */
        out = (rtapi_u32)v;
    }
}
