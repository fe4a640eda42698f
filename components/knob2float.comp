component knob2float "Turn a count (from a knob or an encoder) into a float value";

pin in s32 counts "The count, usually from an encoder";
pin in bit enable "While TRUE, changes of counts move out; while FALSE, they are ignored and out keeps its value";
pin in float scale "The change of out per count";
pin out float out "The value, between min-out and max-out";

param rw float max_out = 1.0 "The largest value out can have; turning further up does nothing";
param rw float min_out = 0.0 "The smallest value out can have; turning further down does nothing";

variable rtapi_s32 last_counts = 0;

function _ fp "Apply the change of counts since the last call";

description """
Each call adds (change of \\fBcounts\\fR) * \\fBscale\\fR to the output and
limits it to \\fBmin-out\\fR..\\fBmax-out\\fR.  Turning past a limit is lost:
turning back moves the output away from the limit at once.  The change is
computed without overflow, whatever the jump of \\fBcounts\\fR.
""";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    rtapi_s32 c = counts;

    if (enable) {
        double v = out + ((double)c - (double)last_counts) * scale;
        if (v > max_out)
            v = max_out;
        if (v < min_out)
            v = min_out;
        out = v;
    }
    last_counts = c;
}
