component tristate_float "Drive a float signal only while enabled, like a tristate buffer";

description """Several tristate_float instances (or other I/O pins) may share one signal
through their io pins; the one whose enable is TRUE writes it, and while
enable is FALSE this instance leaves the signal as it is.""";

pin in float in "The value to drive onto the signal";
pin io float out "Connect to the shared signal; written only while enable is TRUE";
pin in bit enable "TRUE to copy in to out each time the function runs";

function _ "Copy in to out if enable is TRUE, otherwise do nothing.";

see_also "tristate_bit(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (enable)
        out = in;
}
