component joyhandle "Shape a joystick axis: deadband, non-linear response, scale and offset";

description """
Maps a joystick axis (\\fBin\\fR, normally \\-1..1) to a jog or speed
command with a deadband around the centre and a curve that gives fine
control for small deflections and full speed at the end of the travel.

For a deflection \\fIx\\fR between \\fBdeadband\\fR and 1 the output is
.RS
out = scale * (a * x^power + b * x) + offset
.RE
where \\fIa\\fR and \\fIb\\fR are chosen so that the curve starts at
(deadband, offset) and reaches (1, scale + offset):
\\fIa\\fR = 1 / (1 \\- deadband^(power\\-1)) and \\fIb\\fR = 1 \\- \\fIa\\fR.
A larger \\fBpower\\fR makes the start flatter; with a large deadband (over
about 0.5) a power of 3 to 5 avoids a jump at the edge of the deadband.

Negative deflections give the same curve mirrored through the origin
(offset included). Inside the deadband (|x| <= deadband) the output is 0,
and from |x| = 1 on it is \\(+-(scale + offset).

With \\fBinverse\\fR set the curve is turned into a progressive one that
rises fast at first and flattens towards the end: for a positive
deflection, out = scale * (1 \\- c(1 \\- x + deadband)) + offset, where
c is the curve above without scale and offset.

With a \\fBpower\\fR of 1 the response is a straight line from the edge of
the deadband to full scale and \\fBinverse\\fR has no effect.

Out-of-range parameters are corrected in place each cycle: a power below 1
becomes 1, a deadband below 0 becomes 0 and one above 0.99 becomes 0.99.
""";

pin in float in "Joystick deflection, -1 to 1";
pin out float out "Shaped command";

param rw float power = 2.0 "Exponent of the curve, at least 1: 1 is linear, larger values give finer control near the centre (typically 1.5 to 5)";
param rw float deadband = 0. "Deflections up to this size give 0 (0 to 0.99, typically about 0.1)";
param rw float scale = 1. "Output at full deflection, less offset";
param rw float offset = 0. "Output at the edge of the deadband (mirrored for negative deflections)";
param rw bit inverse = 0 "TRUE: progressive curve, steep near the deadband and flat near full deflection";

function _ "Compute out from in";

notes """With \\fBinverse\\fR set, negative deflections are not the mirror
image of positive ones: the output there is
\\-scale * (1 + c(1 \\- |x| + deadband)) \\- 3 * offset, which runs from
about \\-(2 * scale + 3 * offset) just outside the deadband to
\\-(scale + 3 * offset) near full deflection, and jumps to
\\-(scale + offset) at |x| = 1. LinuxCNC's joyhandle does the same; use
inverse only for positive-only axes or with care.""";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

/* the curve from (d, 0) to (1, 1) */
static double curve(double x, double p, double d)
{
    double a = 1.0 / (1.0 - pow(d, p - 1.0));
    double b = 1.0 - a;

    return a * pow(x, p) + b * x;
}

FUNCTION(_) {
    double x = in, mag = fabs(x);
    double sgn = x < 0 ? -1.0 : 1.0;
    double g;

    /* keep the parameters in their valid ranges */
    if (power < 1.0)
        power = 1.0;
    if (deadband < 0.0)
        deadband = 0.0;
    if (deadband > 0.99)
        deadband = 0.99;

    if (mag <= deadband) {
        out = 0.0;
    } else if (mag >= 1.0) {
        out = sgn * (scale + offset);
    } else if (power == 1.0) {
        /* straight line from the edge of the deadband */
        out = sgn * (scale * (mag - deadband) / (1.0 - deadband) + offset);
    } else if (!inverse) {
        out = sgn * (scale * curve(mag, power, deadband) + offset);
    } else {
        /* the curve run backwards from full deflection */
        g = scale * curve(1.0 - mag + deadband, power, deadband) + offset;
        out = sgn * (scale + 2.0 * offset) - g;
    }
}
