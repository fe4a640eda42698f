component flipflop "D type flip-flop with set and reset";

description """
On each rising edge of \\fBclk\\fR, \\fBout\\fR takes the value of
\\fBdata\\fR.  \\fBset\\fR forces \\fBout\\fR TRUE and \\fBreset\\fR forces it
FALSE; when both are TRUE, \\fBreset\\fR wins.  While either is TRUE the clock
is ignored.  \\fBout\\fR is an I/O pin, so its starting state may be set with
setp or by a signal; \\fBout-not\\fR always follows it inverted.
""";

pin in bit data "Value stored on a rising edge of clk";
pin in bit clk "Clock: its rising edge copies data to out";
pin in bit set "While TRUE, out is forced TRUE";
pin in bit reset "While TRUE, out is forced FALSE (stronger than set)";
pin io bit out "The stored value";
pin io bit out_not "The stored value inverted";

variable int old_clk;

function _ nofp;

see_also "toggle(9), edge(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (reset)
        out = 0;
    else if (set)
        out = 1;
    else if (clk && !old_clk)
        out = data;
    old_clk = clk;
    out_not = !out;
}
