component sim_home_switch "Simulated home switch, with hysteresis and an index-enable reset";

description """
Makes a home switch out of a joint position, for simulated machines.

With \\fBhome-pos\\fR zero or positive the switch is at the positive end:
\\fBhome-sw\\fR goes TRUE when \\fBcur-pos\\fR reaches \\fBhome-pos\\fR and
goes FALSE again only when the position is back down to
\\fBhome-pos\\fR \\- \\fBhysteresis\\fR. With a negative \\fBhome-pos\\fR it is
the mirror image: TRUE at or below \\fBhome-pos\\fR, FALSE again at or above
\\fBhome-pos\\fR + \\fBhysteresis\\fR. In between, the switch keeps its state,
so homing has to back off by the hysteresis, as on a real switch.

For homing to an index (\\fB[JOINT_\\fIn\\fB]HOME_USE_INDEX\\fR), connect
\\fBindex-enable\\fR to \\fBjoint.\\fIN\\fB.index-enable\\fR. When it goes
TRUE, the component clears it again \\fBindex-delay-ms\\fR milliseconds
later, as an encoder would on seeing its index. A delay of zero or less
never clears it.
""";

pin in float cur_pos "Joint position, usually joint.N.motor-pos-fb";
pin in float home_pos = 1 "Where the switch trips; its sign chooses the end of travel";
pin in float hysteresis = 0.1 "How far the joint must move back before the switch releases";
pin out bit home_sw "The simulated home switch";
pin io bit index_enable "Connect to joint.N.index-enable: cleared index-delay-ms after it goes TRUE";
pin in float index_delay_ms = 10 "Time from index-enable going TRUE to its reset, in milliseconds";

function _ "Update the switch and the index-enable timer";

variable int was_enabled;
variable double left_ms;

see_also "sim_axis_hardware(9), sim_spindle(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    if (home_pos >= 0) {
        if (cur_pos >= home_pos)
            home_sw = 1;
        else if (cur_pos <= home_pos - hysteresis)
            home_sw = 0;
    } else {
        if (cur_pos <= home_pos)
            home_sw = 1;
        else if (cur_pos >= home_pos + hysteresis)
            home_sw = 0;
    }

    if (!index_enable) {
        left_ms = 0;
    } else if (!was_enabled) {
        /* just set: the index comes index_delay_ms from now */
        left_ms = index_delay_ms;
    } else if (left_ms > 0) {
        left_ms -= fperiod * 1000.0;
        if (left_ms <= 0)
            index_enable = 0;
    }
    was_enabled = index_enable;
}
