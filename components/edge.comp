component edge "Edge detector: a pulse on out for each chosen edge of in";

description """
Watches a bit input and, on the edge selected by \\fBboth\\fR and
\\fBin-edge\\fR, raises \\fBout\\fR (and lowers \\fBout-invert\\fR).  The pulse
lasts \\fBout-width-ns\\fR nanoseconds, rounded up to whole periods of the
thread; with a width of 0 or less it lasts exactly one period.  An edge seen
while a pulse is running starts the full width again.

The value of \\fBin\\fR in the first period is taken as its previous value, so
an input that is already high when the thread starts is not an edge.  The
function uses no floating point, so it may run in a base thread.
""";

pin in bit in "The input signal";
pin out bit out "TRUE while a pulse is running";
pin out bit out_invert "FALSE while a pulse is running: the opposite of out";

param rw bit both = FALSE "TRUE: react to rising and falling edges; FALSE: only to the one chosen by in-edge";
param rw bit in_edge = TRUE "With both FALSE: TRUE reacts to falling edges, FALSE to rising edges";
param rw s32 out_width_ns = 0 "Length of each output pulse in nanoseconds";
param r s32 time_left_ns "Nanoseconds left in the running pulse";
param r bit last_in "The value of in seen in the previous period";

variable int started;

function _ nofp "Look for the chosen edge and time the output pulse";

see_also "oneshot(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int now = in;
    int hit;

    /* the first period only records the input */
    if (!started) {
        started = 1;
        last_in = now;
    }
    if (both)
        hit = now != last_in;
    else if (in_edge)
        hit = last_in && !now;
    else
        hit = !last_in && now;
    last_in = now;

    if (hit) {
        time_left_ns = out_width_ns;
        out = 1;
    } else if (time_left_ns > 0) {
        time_left_ns -= period;
        if (time_left_ns > 0) {
            out = 1;
        } else {
            time_left_ns = 0;
            out = 0;
        }
    } else {
        time_left_ns = 0;
        out = 0;
    }
    out_invert = !out;
}
