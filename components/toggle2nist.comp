component toggle2nist "Toggle button to separate on and off commands";

description """
Lets one momentary button drive a device that has an \\fBon\\fR input, an
\\fBoff\\fR input and an \\fBis-on\\fR feedback (for example a spindle, or
halui's mist and flood pins).

Every change of \\fBin\\fR (pressing or releasing the button) asks for the
state the device is not in: if \\fBis-on\\fR is FALSE, \\fBon\\fR goes TRUE
and stays TRUE until \\fBis-on\\fR is TRUE; if \\fBis-on\\fR is TRUE,
\\fBoff\\fR goes TRUE and stays TRUE until \\fBis-on\\fR is FALSE.  Only one
of \\fBon\\fR and \\fBoff\\fR is TRUE at a time.  The input counts as FALSE
before the first period, so a button already pressed at start asks for a
change.
""";

pin in bit in "Button input";
pin in bit is_on "Feedback: TRUE when the device is on";
pin out bit on "TRUE while the device is asked to turn on";
pin out bit off "TRUE while the device is asked to turn off";

variable int old_in;
variable int want;      /* 0 nothing asked, 1 turn on, 2 turn off */

function _ nofp;

see_also "toggle(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int now = in;

    if (now != old_in)
        want = is_on ? 2 : 1;
    old_in = now;

    /* a request ends when the feedback shows it was carried out */
    if (want == 1 && is_on)
        want = 0;
    if (want == 2 && !is_on)
        want = 0;

    on = want == 1;
    off = want == 2;
}
