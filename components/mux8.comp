component mux8 "Pass one of eight float values through, chosen by three bits";

pin in bit sel0 "Bit 0 (weight 1) of the number of the input to pass through";
pin in bit sel1 "Bit 1 (weight 2) of the number of the input to pass through";
pin in bit sel2 "Bit 2 (weight 4) of the number of the input to pass through";
pin out float out """A copy of inN, where N is sel2, sel1 and sel0 read as a binary number
(sel2 the most significant bit): all FALSE gives in0, only sel0 TRUE gives in1,
only sel2 TRUE gives in4, all TRUE gives in7""";
pin in float in0;
pin in float in1;
pin in float in2;
pin in float in3;
pin in float in4;
pin in float in5;
pin in float in6;
pin in float in7;

function _;

see_also "mux2(9), mux4(9), mux16(9), mux_generic(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int n = (sel2 ? 4 : 0) + (sel1 ? 2 : 0) + (sel0 ? 1 : 0);

    switch (n) {
    case 0: out = in0; break;
    case 1: out = in1; break;
    case 2: out = in2; break;
    case 3: out = in3; break;
    case 4: out = in4; break;
    case 5: out = in5; break;
    case 6: out = in6; break;
    default: out = in7; break;
    }
}
