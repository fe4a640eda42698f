component or2 "Two-input OR gate";

pin in bit in0;
pin in bit in1;
pin out bit out "TRUE when in0 or in1 (or both) is TRUE, otherwise FALSE";

function _ nofp;

see_also "and2(9), not(9), xor2(9)";
author "the halsdk authors";
license "LGPL-2.1-or-later";
;;
FUNCTION(_) { out = in0 || in1; }
