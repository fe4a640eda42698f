component charge_pump """Square wave for the charge pump (watchdog) input of a breakout
board, plus the same at a half and a quarter of its frequency""";

description """
Many breakout boards only enable their outputs while a \\fIcharge pump\\fR
input sees a steady square wave: if the computer stops (crash, stopped
thread, e-stop logic clearing \\fBenable\\fR) the wave stops and the board
drops its outputs.

Add the function to the fastest thread (normally the base thread that
also runs stepgen).  Each time it runs while \\fBenable\\fR is true a
three-bit counter goes up by one; \\fBout\\fR, \\fBout-2\\fR and \\fBout-4\\fR
are its bits.  \\fBout\\fR thus toggles every period, a frequency of
1 / (2 * period): with a base period of 100000 ns, 5 kHz.  \\fBout-2\\fR and
\\fBout-4\\fR run at a half and a quarter of that, for boards that want a
slower wave.

While \\fBenable\\fR is false all three outputs are false and the counter
holds its value.
""";

notes """
This component has a single instance, charge-pump; it takes no count= or
names= on its load line.
""";

pin out bit out "Square wave at 1 / (2 * thread period) while enabled, false otherwise.";
pin out bit out_2 "Square wave at half the frequency of out while enabled, false otherwise.";
pin out bit out_4 "Square wave at a quarter of the frequency of out while enabled, false otherwise.";
pin in bit enable = 1 "When false, all outputs are forced false; leave unconnected (true) to run always.";

variable unsigned cnt;

function _ nofp "Advance the counter (if enabled) and set the outputs.";

option singleton yes;

see_also "stepgen(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    unsigned c;

    if (!enable) {
        out = 0;
        out_2 = 0;
        out_4 = 0;
        return;
    }
    c = (cnt + 1) & 7;
    cnt = c;
    out = c & 1;
    out_2 = (c >> 1) & 1;
    out_4 = (c >> 2) & 1;
}
