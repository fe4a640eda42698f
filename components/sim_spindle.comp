component sim_spindle "Simulated spindle: position feedback from a velocity command, with an index";

description """
Integrates a velocity command into a spindle position, in revolutions, as
the feedback of an encoder on a spindle would give it. It lets a
simulated machine do spindle-synchronized motion (threading, rigid
tapping) and orient the spindle on its index.

Setting \\fBindex-enable\\fR (as motion does when it waits for the index)
makes the next whole revolution the new zero: when the position passes an
integer, the component subtracts that integer from it and clears
\\fBindex-enable\\fR. With a positive \\fBvelocity-cmd\\fR the integer below
the new position is subtracted, otherwise the integer above it.
""";

pin in float velocity_cmd "Commanded spindle speed; multiplied by scale it must be revolutions per second";
pin out float position_fb "Spindle position, in revolutions";
pin io bit index_enable "Set to TRUE to wait for the index; the component resets position-fb at the next whole revolution and clears this pin";

param rw float scale = 1.0 "Factor from velocity-cmd to revolutions per second: 1 for revolutions per second, 1/60 (0.016666667) for RPM";

function _ "Advance the position by one thread period";

see_also "sim_encoder(9), sim_home_switch(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double was = position_fb;

    position_fb = was + velocity_cmd * scale * fperiod;
    if (index_enable && floor(was) != floor(position_fb)) {
        /* the position passed a whole revolution: that is the index */
        if (velocity_cmd > 0)
            position_fb -= floor(position_fb);
        else
            position_fb -= ceil(position_fb);
        index_enable = 0;
    }
}
