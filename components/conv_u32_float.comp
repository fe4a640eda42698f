component conv_u32_float "Convert a value from u32 to float";

pin in u32 in "The value to convert";
pin out float out "The input as float";

function _ fp "Convert in and update out";

see_also "conv_bit_float(9), conv_float_s32(9), conv_s32_u32(9), conv_u32_bit(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) { out = in; }
