component conv_bit_s32 "Convert a value from bit to s32";

pin in bit in "The value to convert";
pin out s32 out "The input as s32";

function _ nofp "Convert in and update out";

see_also "conv_bit_float(9), conv_float_s32(9), conv_s32_u32(9), conv_u32_bit(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) { out = in; }
