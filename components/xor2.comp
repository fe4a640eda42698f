component xor2 "Two-input XOR (exclusive OR) gate";

pin in bit in0;
pin in bit in1;
pin out bit out "TRUE when exactly one of in0 and in1 is TRUE, otherwise FALSE";

function _ nofp;

see_also "and2(9), not(9), or2(9)";
author "the halsdk authors";
license "LGPL-2.1-or-later";
;;
FUNCTION(_) { out = (!in0) != (!in1); }
