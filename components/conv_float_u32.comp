component conv_float_u32 "Convert a value from float to u32";

pin in float in "The value to convert";
pin out u32 out "The input as u32, wrapped or clamped as the clamp parameter says";
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

/* A plain (unsigned) cast as x86-64 does it: through a 64-bit signed
   integer, keeping the low 32 bits; 0 when even that does not fit (or NaN). */
static inline rtapi_u32 to_u32(double v)
{
    if (v >= -9223372036854775808.0 && v < 9223372036854775808.0)
        return (rtapi_u32)(rtapi_s64)v;
    return 0;
}

FUNCTION(_) {
    double v = in;
    if (clamp) {
        /* the clamped range ends at 2147483647, as the reference's does */
        if (v > 2147483647.0) {
            out = 2147483647;
            out_of_range = 1;
        } else if (v < 0.0) {
            out = 0;
            out_of_range = 1;
        } else {
            out = to_u32(v);
            out_of_range = 0;
        }
    } else {
        rtapi_u32 r = to_u32(v);
        out = r;
        if ((double)r != v)
            out_of_range = 1;
    }
}
