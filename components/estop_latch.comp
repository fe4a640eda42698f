component estop_latch "Software ESTOP latch";

description """
A building block of a software ESTOP chain.  It is either \\fIOK\\fR
(\\fBok-out\\fR TRUE, \\fBfault-out\\fR FALSE, \\fBwatchdog\\fR inverting
every period) or \\fIfaulted\\fR (\\fBok-out\\fR FALSE, \\fBfault-out\\fR
TRUE, \\fBwatchdog\\fR holding its value).  It starts faulted.

It faults as soon as \\fBfault-in\\fR is TRUE or \\fBok-in\\fR is FALSE.  It
becomes OK only on a rising edge of \\fBreset\\fR while \\fBfault-in\\fR is
FALSE and \\fBok-in\\fR is TRUE; holding \\fBreset\\fR TRUE does not clear a
later fault.

Unconnected, \\fBok-in\\fR is TRUE and \\fBfault-in\\fR is FALSE, so either
one alone can carry the fault signal; at least one must be connected for
the latch ever to fault.  A usual hookup: the external estop chain to
\\fBfault-in\\fR (or \\fBok-in\\fR), \\fBiocontrol.0.user-request-enable\\fR
to \\fBreset\\fR and \\fBok-out\\fR to \\fBiocontrol.0.emc-enable-in\\fR.
Several latches may be chained, \\fBok-out\\fR of one to \\fBok-in\\fR of the
next.
""";

pin in bit ok_in = TRUE "FALSE faults the latch";
pin in bit fault_in = FALSE "TRUE faults the latch";
pin in bit reset "A rising edge clears the fault when the inputs allow it";
pin out bit ok_out = FALSE "TRUE when OK";
pin out bit fault_out = TRUE "TRUE when faulted";
pin out bit watchdog "Inverts every period while OK, for a charge pump";

variable int old_reset;
variable int ok;

function _ nofp;

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int r = reset;

    if (fault_in || !ok_in)
        ok = 0;
    else if (r && !old_reset)
        ok = 1;
    old_reset = r;

    if (ok)
        watchdog = !watchdog;
    ok_out = ok;
    fault_out = !ok;
}
