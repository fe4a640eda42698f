component and2 "Two-input AND gate";

pin in bit in0;
pin in bit in1;
pin out bit out "TRUE when both in0 and in1 are TRUE, otherwise FALSE";

function _ nofp;

see_also "not(9), or2(9), xor2(9)";
author "the halsdk authors";
license "LGPL-2.1-or-later";
;;
FUNCTION(_) { out = in0 && in1; }
