component sample_hold "Pass an integer through, or hold its last value";

pin in s32 in "The value to sample";
pin in bit hold "While TRUE, out keeps its value; while FALSE, out follows in";
pin out s32 out "The sampled value";

function _ nofp "Copy in to out unless hold is TRUE";

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (!hold)
        out = in;
}
