component updown "Up/down counter with optional limits or wrap-around";

pin in bit countup "Each rising edge adds one to count";
pin in bit countdown "Each rising edge takes one from count";
pin in bit reset "While TRUE, count is held at 0 (edges of countup and countdown are still seen and lost)";
pin out s32 count "The count";

param rw bit clamp "When TRUE, count is held between min and max";
param rw bit wrap "When TRUE, going above max gives min and going below min gives max (wrap implies clamp and takes precedence)";
param rw s32 max = 0x7FFFFFFF "The upper limit used by clamp and wrap";
param rw s32 min = 0 "The lower limit used by clamp and wrap";

variable hal_bit_t last_up;
variable hal_bit_t last_down;
variable hal_bit_t last_reset;
variable int started = 0;

function _ nofp "Count the edges seen since the last call and apply the limits";

description """
Edges are found by comparing each input with its value in the previous
call; inputs already TRUE at the first call do not count.  Edges on
\\fBcountup\\fR and \\fBcountdown\\fR in the same call cancel out.  The
limits are applied on every call, so changing \\fBmin\\fR, \\fBmax\\fR,
\\fBclamp\\fR or \\fBwrap\\fR takes effect at once.
""";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    /* in unsigned arithmetic, so that counting past the s32 range wraps */
    rtapi_u32 c = (rtapi_u32)count;

    if (!started) {
        last_up = countup;
        last_down = countdown;
        last_reset = reset;
        started = 1;
    }
    if (countup && !last_up)
        c++;
    if (countdown && !last_down)
        c--;
    if (reset)
        c = 0;          /* held at 0 while reset is TRUE, as the reference */
    last_up = countup;
    last_down = countdown;
    last_reset = reset;

    if (wrap) {
        if ((rtapi_s32)c > max)
            c = (rtapi_u32)min;
        else if ((rtapi_s32)c < min)
            c = (rtapi_u32)max;
    } else if (clamp) {
        if ((rtapi_s32)c > max)
            c = (rtapi_u32)max;
        else if ((rtapi_s32)c < min)
            c = (rtapi_u32)min;
    }
    count = (rtapi_s32)c;
}
