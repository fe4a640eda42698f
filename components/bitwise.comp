component bitwise "Bitwise logic on two 32-bit values";

pin in u32 in0 "The first operand";
pin in u32 in1 "The second operand";
pin out u32 out-and "in0 AND in1, bit by bit";
pin out u32 out-or "in0 OR in1, bit by bit";
pin out u32 out-xor "in0 XOR in1, bit by bit";
pin out u32 out-nand "The complement of out-and";
pin out u32 out-nor "The complement of out-or";
pin out u32 out-xnor "The complement of out-xor";

function _ nofp;

see_also "bitslice(9), logic(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    rtapi_u32 a = in0, b = in1;

    out_and = a & b;
    out_or = a | b;
    out_xor = a ^ b;
    out_nand = ~(a & b);
    out_nor = ~(a | b);
    out_xnor = ~(a ^ b);
}
