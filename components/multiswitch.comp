component multiswitch "Steps through a number of output bits, one TRUE at a time";

description """
A rotary switch made from up and down buttons.  Exactly one of the
\\fBbit-\\fIMM\\fR outputs, the one numbered \\fBposition\\fR, is TRUE.  A
rising edge on \\fBup\\fR moves to the next position, one on \\fBdown\\fR to
the previous one; from \\fBtop-position\\fR up goes round to 0, and from 0
down goes round to \\fBtop-position\\fR.  Rising edges on both in the same
period cancel.

\\fBcfg=\\fR lists the number of positions of each instance, for example
\\fBcfg=2,4,6\\fR makes three instances with 2, 4 and 6 output bits (at most
32 each, and at most 32 instances; a 0 ends the list).  Without \\fBcfg=\\fR
one instance with 4 bits is made.  The \\fBpersonality=\\fR parameter is set
from \\fBcfg=\\fR and should not be given.

\\fBtop-position\\fR starts at the number of bits minus one; it may be set
lower to use fewer positions.  \\fBposition\\fR may be set in HAL too: a
value above \\fBtop-position\\fR becomes 0 and a negative one becomes
\\fBtop-position\\fR the next time the function runs.
""";

pin in bit up = false "A rising edge moves to the next position";
pin in bit down = false "A rising edge moves to the previous position";
pin out bit bit-##[32 : personality] = false "The outputs: only bit-MM with MM equal to position is TRUE";

param rw u32 top_position "Highest position before wrapping round to 0";
param rw s32 position "The current position (may be set in HAL)";

modparam dummy cfg "Number of output bits of each instance, for example cfg=2,4,6 makes 3 instances with 2, 4 and 6 bits";

variable int old_up;
variable int old_down;

function _;

option count_function;
option extra_setup;

author "the halsdk authors";
license "GPL";
;;
#define MAX_INSTANCES 32

static int cfg[MAX_INSTANCES];
RTAPI_MP_ARRAY_INT(cfg, MAX_INSTANCES, "number of bits of each instance");

/* the generated loader reads each instance's size from personality[] */
#undef personality
static int get_count(void)
{
    int n;

    for (n = 0; n < MAX_INSTANCES && cfg[n] != 0; n++)
        personality[n] = cfg[n];
    if (n == 0) {
        personality[0] = 4;
        n = 1;
    }
    return n;
}
#define personality (__comp_inst->_personality)

EXTRA_SETUP() {
    top_position = personality - 1;
    return 0;
}

FUNCTION(_) {
    int i;
    int u = up, d = down;

    if (u && !old_up)
        position++;
    if (d && !old_down)
        position--;
    old_up = u;
    old_down = d;

    if (position < 0)
        position = top_position;
    else if (position > (int)top_position)
        position = 0;

    for (i = 0; i < personality; i++)
        bit(i) = i == position;
}
