component toggle "Push-on, push-off from a momentary pushbutton";

description """
Each press of the button on \\fBin\\fR inverts \\fBout\\fR once.

.nf
     ┐     ┏━━┐        ┏━━┐
in : └─────┛  └────────┛  └──
     ┐     ┌───────────┐
out: └─────┘           └─────
.fi

The input is debounced with an up/down counter: each period with \\fBin\\fR
TRUE counts up (to at most \\fBdebounce\\fR), each period with it FALSE
counts down (to at least 0).  Reaching \\fBdebounce\\fR is a press and
inverts \\fBout\\fR; the next press counts only after the counter has come
back to 0 (the button was released).  A \\fBdebounce\\fR outside 1..10000
is replaced by 2 the next time the function runs.

\\fBout\\fR is an I/O pin: its value may also be set from outside, and the
next press inverts the value it then has.
""";

pin in bit in "Button input";
pin io bit out "The on/off output";

param rw u32 debounce = 2 "Number of periods the button must be pressed (and released) to count";

variable int count;
variable int pressed;

function _ nofp;

see_also "toggle2nist(9), debounce(9), flipflop(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (debounce < 1 || debounce > 10000)
        debounce = 2;

    if (in) {
        if (count < (int)debounce)
            count++;
        if (count >= (int)debounce && !pressed) {
            pressed = 1;
            out = !out;
        }
    } else {
        if (count > 0)
            count--;
        if (count == 0)
            pressed = 0;
    }
}
