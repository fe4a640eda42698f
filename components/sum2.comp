component sum2 "Weighted sum of two inputs plus an offset";

pin in float in0 "First input";
pin in float in1 "Second input";
pin out float out "in0 * gain0 + in1 * gain1 + offset";

param rw float gain0 = 1.0 "Weight of in0";
param rw float gain1 = 1.0 "Weight of in1";
param rw float offset "Constant added to the weighted sum";

function _ "Compute out";

see_also "scale(9), mult2(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    out = in0 * gain0 + in1 * gain1 + offset;
}
