component gearchange "Scale and limit a spindle speed command for a two-speed gearbox";

description """
Turns a spindle speed command into the command for the motor drive of a
spindle with two gear ranges.

In gear 1 (\\fBsel\\fR FALSE) the output is the command itself, in gear 2
(\\fBsel\\fR TRUE) it is the command divided by \\fBscale2\\fR, since
the motor turns that many times slower for the same spindle speed. Before
that, the size of the command is limited to the range of the selected
gear (\\fBmin1\\fR..\\fBmax1\\fR or \\fBmin2\\fR..\\fBmax2\\fR, in spindle
speed units); its sign is kept, and a command of 0 counts as positive.
Choose the scale of the drive for gear 1.

The direction passes from \\fBdir-in\\fR to \\fBdir-out\\fR, inverted in gear
2 when \\fBreverse\\fR is set (for a gearbox whose second range turns the
other way).
""";

pin in bit sel "Selected gear: FALSE for gear 1, TRUE for gear 2";
pin in float speed_in "Spindle speed command";
pin out float speed_out "Command for the drive (DAC, PWM, VFD speed)";
pin in bit dir_in "Spindle direction command";
pin out bit dir_out "Direction for the drive: dir-in, inverted in gear 2 when reverse is set";

param rw float min1 = 0 "Smallest speed allowed in gear 1 (a smaller command, 0 included, is raised to it)";
param rw float max1 = 100000 "Largest speed allowed in gear 1";
param rw float min2 = 0 "Smallest speed allowed in gear 2";
param rw float max2 = 100000 "Largest speed allowed in gear 2";
param rw float scale2 = 1.0 "Spindle speed of gear 2 relative to gear 1 at the same motor speed, e.g. 2.5 when gear 2 is 2.5 times faster. Gear 2 is the fast range: a value below 1 is set back to 1";
param rw bit reverse = 0 "TRUE: the spindle turns the other way in gear 2, so dir-out is inverted there";

function _ "Compute speed-out and dir-out for the selected gear";

see_also "spindle(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double lo = sel ? min2 : min1;
    double hi = sel ? max2 : max1;
    double mag = fabs(speed_in);

    if (scale2 < 1.0)
        scale2 = 1.0;

    /* limit the size of the command: one bound or the other, as in
       LinuxCNC (with min > max, a command below min gets min, one above
       it gets max) */
    if (mag < lo)
        mag = lo;
    else if (mag > hi)
        mag = hi;
    if (speed_in < 0)
        mag = -mag;

    if (sel) {
        speed_out = mag / scale2;
        dir_out = reverse ? !dir_in : dir_in;
    } else {
        speed_out = mag;
        dir_out = dir_in;
    }
}
