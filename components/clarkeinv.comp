component clarkeinv "Inverse Clarke transform, with a rotation";

pin in float x "The cartesian x component";
pin in float y "The cartesian y component";
pin in float h "The homopolar component (usually 0); h/sqrt(2) is added to each phase";
pin in float theta "The rotation applied to (x, y) first, in turns: 0.0 to 1.0 is 0 to 360 degrees";
pin out float a "Phase A";
pin out float b "Phase B";
pin out float c "Phase C";

function _ fp "Rotate (x, y) by theta, then compute the three phases";

description """
Rotates the vector (\\fBx\\fR, \\fBy\\fR) by \\fBtheta\\fR turns (counterclockwise)
and turns the result into three phases 120 degrees apart, adding
\\fBh\\fR/sqrt(2) to each.  With \\fBtheta\\fR fed from a motor's electrical angle, this turns
field-oriented (d, q) values into phase values.
""";
see_also "clarke2(9), clarke3(9)";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

/* one turn in radians, sqrt(3)/2 and 1/sqrt(2), with the reference's precision (its
   outputs differ from exact ones in the 10th digit; 1/sqrt(2) is the
   15-digit 0.707106781186547, seen in the last digits of huge outputs) */
#define TURN 6.283185308
#define KS3  0.866025403784439
#define KH   0.707106781186547

FUNCTION(_) {
    double ang = theta * TURN;
    double s = sin(ang);
    double co = cos(ang);
    double xr = x * co - y * s;
    double yr = x * s + y * co;

    double hh = KH * h;

    a = xr + hh;
    b = -0.5 * xr + KS3 * yr + hh;
    c = -0.5 * xr - KS3 * yr + hh;
}
