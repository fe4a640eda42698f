component tof "IEC TOF timer: delays the falling edge of a signal";

description """
An off-delay timer as in IEC 61131-3.  While \\fBin\\fR is TRUE, \\fBq\\fR is
TRUE and \\fBet\\fR is 0.  While \\fBin\\fR is FALSE, \\fBet\\fR counts the
seconds since it went FALSE, up to the first value reaching \\fBpt\\fR; in
the period after that, \\fBq\\fR becomes FALSE.  A \\fBpt\\fR of 0 or less
makes \\fBq\\fR follow \\fBin\\fR without delay.  Since \\fBin\\fR starts
FALSE, \\fBet\\fR also counts from the first period until \\fBin\\fR goes
TRUE or \\fBpt\\fR is reached.
""";

pin in bit in "Input signal";
pin out bit q "Output signal: in, with its falling edges delayed by pt";
pin out float et "Seconds since the falling edge of in (stops at pt)";

param rw float pt "Delay time in seconds";

function _ "Update the timer";

see_also "ton(9), timedelay(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (in) {
        q = 1;
        et = 0;
    } else if (et < pt) {
        et += fperiod;
    } else {
        q = 0;
    }
}
