component not "Inverter";

pin in bit in;
pin out bit out "the opposite of in";

function _ nofp;

see_also "and2(9), or2(9), xor2(9)";
author "the halsdk authors";
license "LGPL-2.1-or-later";
;;
FUNCTION(_) { out = !in; }
