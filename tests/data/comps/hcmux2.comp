component hcmux2 "Select one of two input values";
pin in bit sel "TRUE selects in1, FALSE selects in0";
pin out float out "Follows in0 or in1";
pin in float in1;
pin in float in0;
function _;
license "GPL";
description """A two-input multiplexer,
written as a test of halcompile.""";
see_also "mux4(9)";
;;
FUNCTION(_) {
    if (sel) out = in1;
    else out = in0;
}
