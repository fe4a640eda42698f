component mux2 "Pass one of two float values through, chosen by a bit";

pin in bit sel "FALSE selects in0, TRUE selects in1";
pin out float out "A copy of in0 while sel is FALSE, of in1 while sel is TRUE";
pin in float in1 "The value passed through while sel is TRUE";
pin in float in0 "The value passed through while sel is FALSE";

function _;

see_also "mux4(9), mux8(9), mux16(9), mux_generic(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) { out = sel ? in1 : in0; }
