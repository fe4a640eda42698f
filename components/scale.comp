component scale "Multiply a signal by a gain and add an offset";

pin in float in "The signal to scale";
pin in float gain "Factor applied to in (a pin: it may change while running)";
pin in float offset "Added after scaling";
pin out float out "in * gain + offset";

function _ "Compute out";

see_also "sum2(9), mult2(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    out = in * gain + offset;
}
