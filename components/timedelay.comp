component timedelay "The equivalent of a time-delay relay";

description """
\\fBout\\fR follows \\fBin\\fR, but a change is passed on only after it has
lasted: \\fBon-delay\\fR seconds for a change to TRUE, \\fBoff-delay\\fR
seconds for a change to FALSE.  A change that goes away sooner is never
seen on \\fBout\\fR, and the timing starts again at the next change.

\\fBelapsed\\fR shows the timer: the time \\fBin\\fR has differed from
\\fBout\\fR, counted in whole periods (the first period counts).  It keeps
its last value while \\fBin\\fR and \\fBout\\fR agree.  The delays are pins,
so they may be changed while running; a delay of 0 or less passes a change
on in the period it arrives.
""";

pin in bit in "Input";
pin out bit out "Follows the value of in after applying the delays on-delay and off-delay";
pin in float on_delay = 0.5 "Seconds in must be TRUE before out becomes TRUE";
pin in float off_delay = 0.5 "Seconds in must be FALSE before out becomes FALSE";
pin out float elapsed "Seconds in has differed from out (the internal timer)";

variable double timer;

function _;

see_also "ton(9), tof(9), oneshot(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int now = in;

    if (now == out) {
        timer = 0;
        return;
    }
    timer += fperiod;
    elapsed = timer;
    if (timer >= (now ? on_delay : off_delay)) {
        out = now;
        timer = 0;      /* the next change is timed from zero */
    }
}
