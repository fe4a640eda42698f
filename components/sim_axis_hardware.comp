component sim_axis_hardware "Simulated home and limit switches for up to eight joints";

description """
Makes home and limit switches out of joint positions, so that a simulated
machine can home and trip its limits like a real one. It serves the
joints named X, X2 (a second X motor), Y, Y2, Z, A, U and V; leave the
pins of joints you do not use alone.

For each joint \\fIj\\fR:
.IP \\(bu 2
the home switch \\fIj\\fBhomesw-out\\fR is TRUE while the position is
no further than half of \\fIj\\fBhomesw-hyst\\fR from
\\fIj\\fBhomesw-pos\\fR;
.IP \\(bu 2
the maximum limit switch \\fIj\\fBmaxsw-out\\fR is TRUE while the position
is above \\fIj\\fBmaxsw-lower\\fR + \\fBlimit-offset\\fR and below
\\fIj\\fBmaxsw-upper\\fR;
.IP \\(bu 2
the minimum limit switch \\fIj\\fBminsw-out\\fR is TRUE while the position
is above \\fIj\\fBminsw-lower\\fR and below \\fIj\\fBminsw-upper\\fR \\-
\\fBlimit-offset\\fR;
.IP \\(bu 2
\\fIj\\fBbothsw-out\\fR is either limit switch, but stays FALSE while
any joint is homing (any \\fIj\\fBhoming\\fR TRUE);
.IP \\(bu 2
\\fIj\\fBmaxsw-homesw-out\\fR, \\fIj\\fBminsw-homesw-out\\fR and
\\fIj\\fBbothsw-homesw-out\\fR are the home switch ORed with
\\fIj\\fBmaxsw-out\\fR, \\fIj\\fBminsw-out\\fR and \\fIj\\fBbothsw-out\\fR,
for machines that wire home and limit switches to one input. (For joint
A these three stay FALSE, as in the reference implementation.)
.PP
Over all joints: \\fBhomesw-all\\fR is TRUE while some joint is homing
and some joint is on its home switch (not necessarily the same one), \\fBlimitsw-all\\fR when any \\fIj\\fBbothsw-out\\fR
is TRUE, and \\fBlimitsw-homesw-all\\fR when either of them is, for
machines with all switches on one input.
.PP
As in the reference implementation, each switch is TRUE unless a
comparison puts the position outside it: a NaN position, switch position,
width, bound or offset turns the switch on, and a position exactly on a
limit switch's bound (after the offset) leaves it off. A negative
\\fIj\\fBhomesw-hyst\\fR never finds home.
""";

pin in float Xcurrent_pos "Position of the joint, for example joint.0.motor-pos-fb";
pin in float X2current_pos;
pin in float Ycurrent_pos;
pin in float Y2current_pos;
pin in float Zcurrent_pos;
pin in float Acurrent_pos;
pin in float Ucurrent_pos;
pin in float Vcurrent_pos;

pin in float Xhomesw_pos = 1 "Where the home switch is";
pin in float X2homesw_pos = 1;
pin in float Yhomesw_pos = 1;
pin in float Y2homesw_pos = 1;
pin in float Zhomesw_pos = 1;
pin in float Ahomesw_pos = 1;
pin in float Uhomesw_pos = 1;
pin in float Vhomesw_pos = 1;

pin in float Xmaxsw_upper "Upper end of the maximum limit switch: above it the switch is released";
pin in float X2maxsw_upper;
pin in float Ymaxsw_upper;
pin in float Y2maxsw_upper;
pin in float Zmaxsw_upper;
pin in float Amaxsw_upper;
pin in float Umaxsw_upper;
pin in float Vmaxsw_upper;

pin in float Xmaxsw_lower "Lower end of the maximum limit switch: the switch trips above this plus limit-offset";
pin in float X2maxsw_lower;
pin in float Ymaxsw_lower;
pin in float Y2maxsw_lower;
pin in float Zmaxsw_lower;
pin in float Amaxsw_lower;
pin in float Umaxsw_lower;
pin in float Vmaxsw_lower;

pin in float Xminsw_upper "Upper end of the minimum limit switch: the switch trips below this minus limit-offset";
pin in float X2minsw_upper;
pin in float Yminsw_upper;
pin in float Y2minsw_upper;
pin in float Zminsw_upper;
pin in float Aminsw_upper;
pin in float Uminsw_upper;
pin in float Vminsw_upper;

pin in float Xminsw_lower "Lower end of the minimum limit switch: below it the switch is released";
pin in float X2minsw_lower;
pin in float Yminsw_lower;
pin in float Y2minsw_lower;
pin in float Zminsw_lower;
pin in float Aminsw_lower;
pin in float Uminsw_lower;
pin in float Vminsw_lower;

pin in float Xhomesw_hyst = .025 "Width of the home switch, centred on homesw-pos";
pin in float X2homesw_hyst = .025;
pin in float Yhomesw_hyst = .025;
pin in float Y2homesw_hyst = .025;
pin in float Zhomesw_hyst = .025;
pin in float Ahomesw_hyst = .025;
pin in float Uhomesw_hyst = .025;
pin in float Vhomesw_hyst = .025;

pin in bit Xhoming "TRUE while the joint homes (joint.N.homing): while any joint homes, the limit switches of all joints are left out of bothsw-out and limitsw-all";
pin in bit X2homing;
pin in bit Yhoming;
pin in bit Y2homing;
pin in bit Zhoming;
pin in bit Ahoming;
pin in bit Uhoming;
pin in bit Vhoming;

pin out bit Xhomesw_out "Home switch";
pin out bit X2homesw_out;
pin out bit Yhomesw_out;
pin out bit Y2homesw_out;
pin out bit Zhomesw_out;
pin out bit Ahomesw_out;
pin out bit Uhomesw_out;
pin out bit Vhomesw_out;

pin out bit homesw_all "TRUE when a joint is homing and a joint is on its home switch";

pin out bit Xmaxsw_out "Maximum limit switch";
pin out bit Xminsw_out "Minimum limit switch";
pin out bit Xbothsw_out "Either limit switch; FALSE while homing";
pin out bit X2maxsw_out;
pin out bit X2minsw_out;
pin out bit X2bothsw_out;
pin out bit Ymaxsw_out;
pin out bit Yminsw_out;
pin out bit Ybothsw_out;
pin out bit Y2maxsw_out;
pin out bit Y2minsw_out;
pin out bit Y2bothsw_out;
pin out bit Zmaxsw_out;
pin out bit Zminsw_out;
pin out bit Zbothsw_out;
pin out bit Amaxsw_out;
pin out bit Aminsw_out;
pin out bit Abothsw_out;
pin out bit Umaxsw_out;
pin out bit Uminsw_out;
pin out bit Ubothsw_out;
pin out bit Vmaxsw_out;
pin out bit Vminsw_out;
pin out bit Vbothsw_out;

pin out bit limitsw_all "TRUE when any joint's bothsw-out is TRUE";

pin out bit limitsw_homesw_all "TRUE when limitsw-all or homesw-all is TRUE";

pin out bit Xmaxsw_homesw_out "Maximum limit switch or home switch";
pin out bit Xminsw_homesw_out "Minimum limit switch or home switch";
pin out bit Xbothsw_homesw_out "Either limit switch (FALSE while homing) or home switch";
pin out bit X2maxsw_homesw_out;
pin out bit X2minsw_homesw_out;
pin out bit X2bothsw_homesw_out;
pin out bit Ymaxsw_homesw_out;
pin out bit Yminsw_homesw_out;
pin out bit Ybothsw_homesw_out;
pin out bit Y2maxsw_homesw_out;
pin out bit Y2minsw_homesw_out;
pin out bit Y2bothsw_homesw_out;
pin out bit Zmaxsw_homesw_out;
pin out bit Zminsw_homesw_out;
pin out bit Zbothsw_homesw_out;
pin out bit Amaxsw_homesw_out;
pin out bit Aminsw_homesw_out;
pin out bit Abothsw_homesw_out;
pin out bit Umaxsw_homesw_out;
pin out bit Uminsw_homesw_out;
pin out bit Ubothsw_homesw_out;
pin out bit Vmaxsw_homesw_out;
pin out bit Vminsw_homesw_out;
pin out bit Vbothsw_homesw_out;

pin in float limit_offset = .01 "How far inside their lower (maximum switch) or upper (minimum switch) end the limit switches trip";

function update "Update all switches from the joint positions";

see_also "sim_home_switch(9)";
author "the halsdk authors";
license "GPL";
;;
/* the switches of one joint; while any joint homes, no joint reports a
   limit on bothsw-out */
struct joint_sw {
    int home, max, min, both;
};

static struct joint_sw joint_switches(double pos, double home_pos,
                                      double hyst, double max_up,
                                      double max_low, double min_up,
                                      double min_low, double offset,
                                      int homing)
{
    struct joint_sw s;

    /* written as the reference tests them, so that a NaN anywhere makes
       a switch TRUE (no comparison with a NaN holds) and a position on a
       bound leaves the limit switch FALSE */
    s.home = !((pos - home_pos) < -hyst * 0.5) &&
             !((pos - home_pos) > hyst * 0.5);
    s.max = !(pos <= max_low + offset) && !(pos >= max_up);
    s.min = !(pos <= min_low) && !(pos >= min_up - offset);
    s.both = (s.max || s.min) && !homing;
    return s;
}

#define JOINT(j)                                                        \
    do {                                                                \
        struct joint_sw s = joint_switches(j##current_pos, j##homesw_pos, \
            j##homesw_hyst, j##maxsw_upper, j##maxsw_lower,             \
            j##minsw_upper, j##minsw_lower, limit_offset, homing);      \
        j##homesw_out = s.home;                                         \
        j##maxsw_out = s.max;                                           \
        j##minsw_out = s.min;                                           \
        j##bothsw_out = s.both;                                         \
        j##maxsw_homesw_out = s.max || s.home;                          \
        j##minsw_homesw_out = s.min || s.home;                          \
        j##bothsw_homesw_out = s.both || s.home;                        \
        home_any = home_any || s.home;                                  \
        limit_any = limit_any || s.both;                                \
    } while (0)

FUNCTION(update) {
    int homing = Xhoming || X2homing || Yhoming || Y2homing || Zhoming ||
                 Ahoming || Uhoming || Vhoming;
    int home_any = 0, limit_any = 0;

    JOINT(X);
    JOINT(X2);
    JOINT(Y);
    JOINT(Y2);
    JOINT(Z);
    JOINT(A);
    /* the reference never sets the combined outputs of A */
    Amaxsw_homesw_out = 0;
    Aminsw_homesw_out = 0;
    Abothsw_homesw_out = 0;
    JOINT(U);
    JOINT(V);
    homesw_all = home_any && homing;
    limitsw_all = limit_any;
    limitsw_homesw_all = homesw_all || limitsw_all;
}
