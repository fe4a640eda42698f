component ton "IEC TON timer: delays the rising edge of a signal";

description """
An on-delay timer as in IEC 61131-3.  While \\fBin\\fR is TRUE, \\fBet\\fR
counts the seconds it has been TRUE, up to the first value reaching
\\fBpt\\fR; in the period after that, \\fBq\\fR becomes TRUE.  When \\fBin\\fR
goes FALSE, \\fBq\\fR and \\fBet\\fR go back to FALSE and 0 at once.  A
\\fBpt\\fR of 0 or less makes \\fBq\\fR follow \\fBin\\fR without delay.
""";

pin in bit in "Input signal";
pin out bit q "Output signal: in, with its rising edges delayed by pt";
pin out float et "Seconds since the rising edge of in (stops at pt)";

param rw float pt "Delay time in seconds";

function _ "Update the timer";

see_also "tof(9), timedelay(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (!in) {
        q = 0;
        et = 0;
    } else if (et >= pt) {
        q = 1;
    } else {
        /* a NaN pt is never reached: et counts on and q stays FALSE */
        et += fperiod;
    }
}
