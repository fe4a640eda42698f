component mult2 "Product of two signals";

pin in float in0 "First factor";
pin in float in1 "Second factor";
pin out float out "in0 * in1";

function _ "Compute out";

see_also "div2(9), invert(9), scale(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    out = in0 * in1;
}
