component dbounce "Debounce filter for one bit input, with a delay pin per instance";

description """
Filters a noisy bit input.  A counter goes up by one each period that
\\fBin\\fR is TRUE and down by one each period it is FALSE, and stays
between 0 and \\fBdelay\\fR.  When the counter already stands at
\\fBdelay\\fR and \\fBin\\fR is still TRUE, \\fBout\\fR becomes TRUE; when it
already stands at 0 and \\fBin\\fR is still FALSE, \\fBout\\fR becomes FALSE.
So a clean change of \\fBin\\fR shows on \\fBout\\fR \\fBdelay\\fR periods
later, and a delay of 0 copies \\fBin\\fR at once.

This is the \\fBdebounce\\fR(9) filter with the usual \\fBcount=\\fR and
\\fBnames=\\fR load parameters and a \\fBdelay\\fR pin for each instance
instead of groups sharing one delay.  Lowering \\fBdelay\\fR below the
counter does not move the counter: it only stops counting up.
""";

pin in bit in "The noisy input";
pin out bit out "The filtered output";
pin in u32 delay = 5 "Number of periods a change must last to reach out";

variable unsigned count;

function _ nofp;

see_also "debounce(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (in) {
        if (count < delay)
            count++;
        else
            out = 1;
    } else {
        if (count > 0)
            count--;
        else
            out = 0;
    }
}
