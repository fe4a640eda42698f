component lincurve "Map an input through a table of points joined by straight lines";

pin in float in "The input (the x value)";
pin out float out "The output (the y value on the curve at in)";
pin io float out_io "The same output on an io pin, so it can drive a PID gain or another io pin";

param rw float x_val_##[16 : (personality < 2 ? 2 : personality > 16 ? 16 : personality)] "The x values of the points, in increasing order";
param rw float y_val_##[16 : (personality < 2 ? 2 : personality > 16 ? 16 : personality)] "The y values of the points";

function _ fp "Look up in on the curve";

description """
The points (\\fBx-val-NN\\fR, \\fBy-val-NN\\fR) make a curve of straight
segments; the output is the curve's value at the input.  Below the first
point the output is \\fBy-val-00\\fR, at or beyond the last one it is the last
y value: the curve is not extended.  The x values should increase; the
search walks the segments from the first point.

The personality is the number of points of an instance: 2 to 16
(smaller values give 2, larger ones 16), for example
\\fBloadrt lincurve count=2 personality=4,9\\fR.  Set the points with
\\fBsetp\\fR.
""";
examples """
A curve that limits a feed to 100 up to a load of 2 and falls to 20 at 5:
.nf
loadrt lincurve personality=3
setp lincurve.0.x-val-00 0
setp lincurve.0.y-val-00 100
setp lincurve.0.x-val-01 2
setp lincurve.0.y-val-01 100
setp lincurve.0.x-val-02 5
setp lincurve.0.y-val-02 20
.fi
""";
author "the halsdk authors";
license "GPL";
;;
/* the number of points of an instance: its personality, limited to 2..16 */
#define NPOINTS (personality < 2 ? 2 : personality > 16 ? 16 : personality)

FUNCTION(_) {
    int n = NPOINTS;
    double x = in;
    double y;
    int i;

    if (x >= x_val(n - 1)) {
        y = y_val(n - 1);
    } else if (x < x_val(0)) {
        y = y_val(0);
    } else {
        /* the segment i .. i+1 that holds x */
        i = 0;
        while (i < n - 2 && x >= x_val(i + 1))
            i++;
        y = y_val(i) + (x - x_val(i)) * (y_val(i + 1) - y_val(i))
            / (x_val(i + 1) - x_val(i));
    }
    out = y;
    out_io = y;
}
