component orient "Command value for a spindle orientation (M19) position loop";

description """
Works with the spindle orient pins of motion and a \\fBpid\\fR component to
stop the spindle at a given angle (M19).

When \\fBenable\\fR goes TRUE, the current \\fBposition\\fR (in revolutions,
from the spindle encoder) is sampled once and \\fBcommand\\fR is set to the
target angle, angle/360, plus the whole number of revolutions that
puts it where the \\fBmode\\fR asks for, as seen from the position
(for an angle so large that whole revolutions are lost in the
rounding of the sum, the command is what that rounding gives, as in
LinuxCNC 2.9):
.TP
\\fB0\\fR
the nearer of the two ways round: the target is at most half a
revolution from the position (exactly half a revolution: ahead);
.TP
\\fB1\\fR
always forward (increasing position, clockwise): the target is at the
position or less than a revolution ahead of it;
.TP
\\fB2\\fR
always backward: the target is at the position or less than a
revolution behind it.
.PP
With any other mode the command keeps its previous value. The command
then holds until the next rising edge of enable.

While enable is TRUE, \\fBposerr\\fR is (position \\- command) in degrees,
useful when tuning the PID loop; while it is FALSE poserr keeps its last
value.

A typical connection (spindle 0):
.nf
  loadrt orient names=orient
  loadrt pid names=orient-pid
  net orient-angle  spindle.0.orient-angle orient.angle
  net orient-mode   spindle.0.orient-mode orient.mode
  net orient-enable spindle.0.orient orient.enable orient-pid.enable
  net spindle-pos   encoder.0.position orient.position orient-pid.feedback
  net orient-cmd    orient.command orient-pid.command
.fi
""";

pin in bit enable "Rising edge: sample position and compute a new command; TRUE: update poserr";
pin in s32 mode "How to reach the angle: 0 nearer way, 1 always forward (clockwise), 2 always backward (counterclockwise)";
pin in float position "Spindle position in revolutions (from the encoder)";
pin in float angle "Target angle in degrees, 0 <= angle < 360";
pin out float command "Target position in revolutions, for the PID command";
pin out float poserr "position - command in degrees, while enabled";
pin out bit is_oriented "Always FALSE, as in LinuxCNC 2.9 (see the notes)";
pin in float tolerance = 0.5 "Angle tolerance in degrees, meant for is-oriented (which ignores it, see the notes)";

variable int last_enable = 0;

function _ "Sample on enable's rising edge, update command and poserr";

notes """\\fBis-oriented\\fR never goes TRUE in LinuxCNC 2.9's orient, whatever
\\fBposerr\\fR and \\fBtolerance\\fR are; this component behaves the same so
that configurations work alike. To know when the spindle is oriented,
compare poserr with the tolerance outside, for instance with \\fBwcomp\\fR
or \\fBnear\\fR, and drive spindle.N.is-oriented from that.""";
see_also "pid(9), motion(9)";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

FUNCTION(_) {
    if (enable && !last_enable) {
        /* the target angle in revolutions plus a whole number of
           revolutions, chosen from the revolutions between the target and
           the position: for a huge angle the whole revolutions are lost
           in the rounding of the sum, as in the reference */
        double target = angle / 360.0;
        double behind = position - target;

        switch (mode) {
        case 0:
            command = target + floor(behind + 0.5);
            break;
        case 1:
            command = target + ceil(behind);
            break;
        case 2:
            command = target + floor(behind);
            break;
        default:
            break;  /* unknown mode: keep the command */
        }
    }
    last_enable = enable;

    if (enable)
        poserr = (position - command) * 360.0;
    is_oriented = 0;
}
