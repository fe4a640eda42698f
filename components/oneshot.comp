component oneshot "One-shot pulse generator";

description """
Starts an output pulse of \\fBwidth\\fR seconds when \\fBin\\fR changes in a
direction selected by \\fBrising\\fR and \\fBfalling\\fR.  The pulse is timed
by the thread period, so its length is a whole number of periods (the width
rounded up).  A width of 0 or less gives no pulse.

With \\fBretriggerable\\fR TRUE, a new edge during a pulse starts the full
width again; with it FALSE, edges are ignored until the pulse has ended.
Changing \\fBwidth\\fR does not affect a pulse already running.

While \\fBreset\\fR is TRUE the pulse is cancelled, the outputs show no pulse
and edges are ignored; \\fBtime-left\\fR keeps its last value.  The input is
then seen as FALSE before the reset ended, so a rising-edge one-shot whose
input is still TRUE when \\fBreset\\fR goes FALSE starts a pulse.

The function uses floating point; for a base-thread version with
nanosecond times see \\fBedge\\fR(9).
""";

pin in bit in "Trigger input";
pin in bit reset "While TRUE: no pulse, edges ignored";
pin out bit out "TRUE during the pulse";
pin out bit out_not "FALSE during the pulse";
pin in float width = 0 "Length of the pulse in seconds";
pin out float time_left "Seconds left in the running pulse";

param rw bit retriggerable = TRUE "TRUE: an edge during a pulse restarts it";
param rw bit rising = TRUE "Start a pulse on a rising edge of in";
param rw bit falling = FALSE "Start a pulse on a falling edge of in";

variable double timer;
variable int old_in;

function _ "Watch in for edges and time the pulse";

see_also "edge(9), timedelay(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int now = in;
    int hit;

    if (reset) {
        /* cancel the pulse; the input counts as FALSE meanwhile */
        timer = 0;
        old_in = 0;
        out = 0;
        out_not = 1;
        return;
    }

    hit = (rising && now && !old_in) || (falling && !now && old_in);
    old_in = now;

    if (hit && (retriggerable || !(timer > 0))) {
        timer = width;
    } else if (timer > 0) {
        timer -= fperiod;
        if (timer < 0)
            timer = 0;
    }
    out = timer > 0;
    out_not = !out;
    time_left = timer;
}
