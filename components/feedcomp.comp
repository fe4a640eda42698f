component feedcomp "Scale a value by the ratio of the current velocity to a reference feed rate";

description """
While \\fBenable\\fR is TRUE, \\fBout\\fR is \\fBin\\fR multiplied by
\\fBvel\\fR / \\fBfeed\\fR: at the reference feed rate the value passes
unchanged, at half that rate it is halved, and so on. A typical use is to
make a laser power or a dispenser flow follow the actual tool velocity,
so that the amount per unit of path stays the same while the machine
accelerates or slows down.

While \\fBenable\\fR is FALSE, \\fBout\\fR equals \\fBin\\fR.
""";

pin out float out "The scaled value";
pin in float in "The value to scale (its size at the reference feed rate)";
pin in bit enable "TRUE: scale by vel/feed; FALSE: out follows in unchanged";
pin in float vel "The current velocity, in the same units as feed";

param rw float feed "The reference feed rate at which out equals in. Set it before enabling: with the default of 0 the output is infinite or not a number";

function _ "Compute out from in, vel and feed";

notes "The ratio keeps its sign: a negative velocity (or feed) gives an output of the opposite sign.";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (enable)
        out = in * vel / feed;
    else
        out = in;
}
