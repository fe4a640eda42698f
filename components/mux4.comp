component mux4 "Pass one of four float values through, chosen by two bits";

pin in bit sel0 "The low bit of the number of the input to pass through";
pin in bit sel1 "The high bit of the number of the input to pass through";
pin out float out """A copy of the input whose number is given by sel1 and sel0 read as a
binary number: in0 when both are FALSE, in1 when only sel0 is TRUE, in2 when
only sel1 is TRUE, in3 when both are TRUE""";
pin in float in0 "Selected by sel1=FALSE, sel0=FALSE";
pin in float in1 "Selected by sel1=FALSE, sel0=TRUE";
pin in float in2 "Selected by sel1=TRUE, sel0=FALSE";
pin in float in3 "Selected by sel1=TRUE, sel0=TRUE";

function _;

see_also "mux2(9), mux8(9), mux16(9), mux_generic(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int n = (sel1 ? 2 : 0) + (sel0 ? 1 : 0);

    switch (n) {
    case 0: out = in0; break;
    case 1: out = in1; break;
    case 2: out = in2; break;
    default: out = in3; break;
    }
}
