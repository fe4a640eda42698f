component multiclick "Single-, double-, triple- and quadruple-click detector";

description """
Counts clicks on a button.  A click is a press of \\fBin\\fR (a rising edge,
or a falling edge with \\fBinvert-input\\fR TRUE) held for at most
\\fBmax-hold-ns\\fR, then released.  Clicks follow each other in one
multi-click when the button stays released for at most \\fBmax-space-ns\\fR
between them.

As soon as the Nth click of a multi-click is released, the
\\fBN-click\\fR output (\\fBsingle-click\\fR, \\fBdouble-click\\fR, ...)
gives a pulse.  When the button then stays released longer than
\\fBmax-space-ns\\fR, no further click can belong to it, and the
\\fBN-click-only\\fR output gives a pulse; these suit commands that must run
for one kind of multi-click only, such as halui MDI commands.  Each pulse
lasts \\fBoutput-hold-ns\\fR, rounded up to whole periods; a new one on
the same output starts the time again.  With \\fBoutput-hold-ns\\fR 0 an
output that went TRUE stays TRUE.

A press held too long, or a fifth click, ends the multi-click without an
\\fB-only\\fR pulse; the detector then waits for the button to be released.
Times are counted in whole thread periods, by a 32-bit timer as in
LinuxCNC: it wraps after 4294967296 ns, so a \\fBmax-hold-ns\\fR or
\\fBmax-space-ns\\fR above 4294967296 minus the period is never passed
and such a press or release does not end the multi-click.  A noisy
button should go through \\fBdebounce\\fR(9) first.

\\fBstate\\fR shows the internal state: 0 idle, 1 3 5 7 the first to fourth
press held, 2 4 6 8 released after the first to fourth click, 9 waiting for
the button to be released.
""";

pin in bit in "The button";
pin out bit single_click "A pulse when a first click is released";
pin out bit single_click_only "A pulse when a single click was not followed by a second one";
pin out bit double_click "A pulse when a second click is released";
pin out bit double_click_only "A pulse when a double click was not followed by a third click";
pin out bit triple_click "A pulse when a third click is released";
pin out bit triple_click_only "A pulse when a triple click was not followed by a fourth click";
pin out bit quadruple_click "A pulse when a fourth click is released";
pin out bit quadruple_click_only "A pulse when a quadruple click was not followed by a fifth click";
pin out s32 state "The internal state, for debugging (see the description)";

param rw bit invert_input = FALSE "FALSE: a click starts with a rising edge of in; TRUE: with a falling edge";
param rw u32 max_hold_ns = 250000000 "A press held longer than this (in ns) is not a click; default 250 ms";
param rw u32 max_space_ns = 250000000 "A release longer than this (in ns) ends the multi-click; default 250 ms";
param rw u32 output_hold_ns = 100000000 "Length of the output pulses in ns; default 100 ms";

variable rtapi_u32 timer;
variable long left[8];
variable int on[8];

function _ nofp "Look for clicks and time the output pulses";

see_also "debounce(9), toggle(9)";
author "the halsdk authors";
license "GPL";
;;
#define IDLE 0
#define WAIT_RELEASE 9

FUNCTION(_) {
    int now = invert_input ? !in : in;
    int st = state;
    int fire = -1;
    int k;

    /* age the pulses started in earlier periods; a pulse ends when its
       time runs out (so one of 0 ns, which has no time to run out,
       stays on) */
    for (k = 0; k < 8; k++) {
        if (left[k] > 0) {
            left[k] -= period;
            if (left[k] <= 0)
                on[k] = 0;
        }
    }

    if (st == IDLE) {
        if (now) {
            st = 1;
            timer = 0;
        }
    } else if (st == WAIT_RELEASE) {
        if (!now)
            st = IDLE;
    } else if (st % 2) {
        /* a press is held: click number (st + 1) / 2 */
        if (!now) {
            fire = st - 1;          /* its N-click output */
            st++;
            timer = 0;
        } else {
            timer += (rtapi_u32)period;     /* wraps as the reference's */
            if (timer > max_hold_ns)
                st = WAIT_RELEASE;
        }
    } else {
        /* released after click number st / 2 */
        if (now) {
            /* a fifth click ends the sequence */
            st = st == 8 ? WAIT_RELEASE : st + 1;
            timer = 0;
        } else {
            timer += (rtapi_u32)period;
            if (timer > max_space_ns) {
                fire = st - 1;      /* its N-click-only output */
                st = IDLE;
            }
        }
    }
    if (fire >= 0) {
        left[fire] = output_hold_ns;
        on[fire] = 1;
    }
    state = st;

    single_click = on[0];
    single_click_only = on[1];
    double_click = on[2];
    double_click_only = on[3];
    triple_click = on[4];
    triple_click_only = on[5];
    quadruple_click = on[6];
    quadruple_click_only = on[7];
}
