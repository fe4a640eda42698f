component modmath "Shortest way round a wrapping range, such as a tool changer carousel";

description """
\\fBmod_dir=\\fIN\\fR makes \\fIN\\fR instances named \\fBmod-dir.0\\fR ... \\fBmod-dir.\\fIN-1\\fR
(with \\fBmod_dir\\fR missing, 0 or negative, the module loads and makes
none).  Each one looks at where a rotating device is (\\fBactual\\fR) and
where it should go (\\fBdesired\\fR), both positions in the range
\\fBmin-num\\fR ... \\fBmax-num\\fR, and tells which way to turn: \\fBup\\fR
(towards higher numbers), \\fBdown\\fR, or \\fBon-target\\fR.

Both positions are first reduced to the range, counted from min-num,
M = max-num - min-num + 1, each keeping its sign (C's remainder of
position - min-num by M), and the difference of the two is taken.  When
\\fBwrap\\fR is TRUE, the range is a circle (position max-num is next to
min-num) and a difference of more than half a turn is replaced, once, by
the way the other way round; at exactly half a turn (even M) the
direction of the plain difference is kept.  With \\fBwrap\\fR FALSE the
difference is used as it is.  Positions outside the range thus give
answers that are not always the shortest way (as in LinuxCNC); with
M = 0 nothing is reduced.

A carousel with pockets 1 to 8 uses min-num 1 and max-num 8: from 7 to 2
the shortest way is up (7, 8, 1, 2).

The pins and functions are listed below as \\fBmodmath.\\fIN\\fR...; their real
names start with \\fBmod-dir.\\fIN\\fR (for example \\fBmod-dir.0.on-target\\fR,
function \\fBmod-dir.0\\fR).
""";

modparam dummy mod_dir "Number of instances to make, named mod-dir.0, mod-dir.1, ... (default 0: none)";

pin in s32 actual "Where the device is now";
pin in s32 desired "Where the device should go";
pin out bit up "TRUE when the shortest way is towards higher numbers";
pin out bit down "TRUE when the shortest way is towards lower numbers";
pin out bit on_target = TRUE "TRUE when actual and desired are the same position (modulo the range)";
pin io s32 min_num = 0 "Lowest position of the range";
pin io s32 max_num = 15 "Highest position of the range";
pin io bit wrap = TRUE "TRUE: the range is circular and the shorter way round is chosen";

function _ "Compare actual and desired and set up, down and on-target";

see_also "updown(9)";
author "the halsdk authors";
license "GPL";
option rtapi_app no;
;;

static int mod_dir = 0;
RTAPI_MP_INT(mod_dir, "number of mod-dir instances to make");

/* 32-bit two's complement arithmetic, wrapping as the reference's does */
static rtapi_s32 wsub(rtapi_s32 a, rtapi_s32 b)
{
    return (rtapi_s32)((rtapi_u32)a - (rtapi_u32)b);
}

/* C's remainder, without the traps of x % 0 and INT_MIN % -1 */
static rtapi_s32 rem(rtapi_s32 x, rtapi_s32 m)
{
    if (m == 0 || m == -1)
        return m == 0 ? x : 0;
    return x % m;
}

FUNCTION(_) {
    rtapi_s32 m = wsub(wsub(max_num, min_num), -1);
    /* each position is reduced to the range on its own, counted from
       min-num, and the difference of the two is then turned at most
       once by a whole range (positions outside the range give the
       reference's answers) */
    rtapi_s32 d = wsub(rem(wsub(desired, min_num), m),
                       rem(wsub(actual, min_num), m));

    if (wrap) {
        if (d > m / 2)
            d = wsub(d, m);
        else if (d < -(m / 2))
            d = (rtapi_s32)((rtapi_u32)d + (rtapi_u32)m);
    }
    up = d > 0;
    down = d < 0;
    on_target = d == 0;
}

int rtapi_app_main(void)
{
    int i, r;

    comp_id = hal_init("modmath");
    if (comp_id < 0)
        return comp_id;
    for (i = 0; i < mod_dir; i++) {
        char name[HAL_NAME_LEN + 1];

        rtapi_snprintf(name, sizeof(name), "mod-dir.%d", i);
        r = export(name, i);
        if (r != 0) {
            hal_exit(comp_id);
            return r;
        }
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
