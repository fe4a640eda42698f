component invert "Reciprocal of a signal, with a deadband around zero";

pin in float in "The signal to invert";
pin out float out "1 / in; see deadband for inputs close to zero";

param rw float deadband """While |in| < deadband, out is 1/deadband (in >= 0,
-0.0 included) or -1/deadband (in < 0), so out stays finite. Values below
1e-12 (0, the default, too) are raised to 1e-12 when the function runs""";

function _ "Compute out";

see_also "div2(9), mult2(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double v = in;

    if (deadband < 1e-12)
        deadband = 1e-12;
    if (v >= 0 && v < deadband)
        v = deadband;
    else if (v < 0 && v > -deadband)
        v = -deadband;
    out = 1 / v;
}
