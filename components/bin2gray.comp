component bin2gray "Convert a binary number to its Gray code";

description """Each output value differs from the one of the next input value in
exactly one bit (the reflected binary Gray code), which is what absolute
encoders and rotary switches often use. gray2bin(9) converts back.""";

pin in u32 in "The binary number";
pin out u32 out "Its Gray code: in XOR (in shifted right by one bit)";

function _ nofp;

see_also "gray2bin(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) { out = in ^ (in >> 1); }
