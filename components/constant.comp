component constant "Drive a pin with the value of a parameter";

pin out float out "Equal to value";

param rw float value "The value to put on out";

function _ fp "Copy value to out";

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) { out = value; }
