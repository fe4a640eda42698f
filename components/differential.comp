component differential "Kinematics of a differential (bevel gear) wrist: two motors drive roll and pitch";

description """
In a differential wrist two motors turn one pair of bevel gears. Turning
both motors the same way rolls the output, turning them in opposite
directions pitches it. This component converts roll and pitch commands
into the two motor commands and the two motor feedbacks back into roll
and pitch feedback:

.RS
motor0-cmd = roll-cmd + pitch-cmd
.br
motor1-cmd = roll-cmd \\- pitch-cmd
.br
roll-fb = (motor0-fb + motor1-fb) / 2
.br
pitch-fb = (motor0-fb \\- motor1-fb) / 2
.RE

All positions are in the same unit (usually degrees). Scale each motor
(gear ratio, steps per degree) in its own driver.
""";

pin in float roll_cmd "Wanted roll position";
pin in float pitch_cmd "Wanted pitch position";

pin out float roll_fb "Roll position computed from the two motor feedbacks";
pin out float pitch_fb "Pitch position computed from the two motor feedbacks";

pin out float motor0_cmd "Position command for motor 0: roll plus pitch";
pin out float motor1_cmd "Position command for motor 1: roll minus pitch";

pin in float motor0_fb "Position feedback of motor 0";
pin in float motor1_fb "Position feedback of motor 1";

function _ "Compute the motor commands and the roll and pitch feedback";

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    motor0_cmd = roll_cmd + pitch_cmd;
    motor1_cmd = roll_cmd - pitch_cmd;

    roll_fb = (motor0_fb + motor1_fb) / 2.0;
    pitch_fb = (motor0_fb - motor1_fb) / 2.0;
}
