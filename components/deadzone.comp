component deadzone "Hold the output at a center value while the input is close to it";

pin in float in "The input";
pin out float out "center while in is inside the dead band; outside it, in moved toward center by half the threshold";

param rw float center = 0.0 "The middle of the dead band";
param rw float threshold = 1.0 "The width of the dead band: it reaches threshold/2 on each side of center";

function _ fp "Compute out from in, center and threshold";

description """
The output is \\fBcenter\\fR while the input is within \\fBthreshold\\fR/2 of
it (the edges included).  Beyond the band the output follows the input,
offset by \\fBthreshold\\fR/2 toward \\fBcenter\\fR, so it has no jump at the
band edges.
""";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double half = threshold / 2.0;
    double x = in;

    if (x < center - half)
        out = x + half;
    else if (x > center + half)
        out = x - half;
    else
        out = center;
}
