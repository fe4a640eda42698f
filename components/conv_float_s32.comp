component conv_float_s32 "Convert a value from float to s32";

pin in float in "The value to convert";
pin out s32 out "The input as s32, wrapped or clamped as the clamp parameter says";
pin out bit out_of_range "TRUE when the last conversion could not represent the input exactly (see the description)";

param rw bit clamp "TRUE: out-of-range inputs give the nearest end of the output range; FALSE: the conversion wraps around as a plain C cast does";

function _ fp "Convert in and update out";

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
#include <rtapi_math.h>

/* The result of a plain (int) cast on x86: truncation toward zero, and the
   most negative value for anything that does not fit (and for NaN).  Written
   out so that it does not depend on the compiler. */
static inline rtapi_s32 to_s32(double v)
{
    if (v > -2147483649.0 && v < 2147483648.0)
        return (rtapi_s32)v;
    return (rtapi_s32)0x80000000u;
}

FUNCTION(_) {
    double v = in;
    if (clamp) {
        if (v > 2147483647.0) {
            out = 2147483647;
            out_of_range = 1;
        } else if (v < -2147483648.0) {
            out = -2147483647 - 1;
            out_of_range = 1;
        } else {
            out = to_s32(v);
            out_of_range = 0;
        }
    } else {
        rtapi_s32 r = to_s32(v);
        out = r;
        if ((double)r != v)
            out_of_range = 1;
    }
}
