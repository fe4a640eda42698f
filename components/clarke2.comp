component clarke2 "Clarke transform of a three-phase quantity given by two phases";

pin in float a "Phase A";
pin in float b "Phase B (phase C is taken as -a-b)";
pin out float x "The cartesian x component (equal to a)";
pin out float y "The cartesian y component: (a + 2b)/sqrt(3)";

function _ fp "Compute x and y";

description """
Turns a three-phase quantity (three components 120 degrees apart) into
cartesian x and y.  In a three-wire system the three phase currents (or
voltages) add up to zero, so phases A and B are enough; the homopolar
component is then zero and is not computed.  With phase C available, or
when the sum may not be zero, use \\fBclarke3\\fR.
""";
see_also "clarke3(9), clarkeinv(9)";
author "the halsdk authors";
license "GPL";
;;
/* 1/sqrt(3) and 2/sqrt(3), to 15 digits (the numbers of the reference) */
#define K1 0.577350269189626
#define K2 1.15470053837925

FUNCTION(_) {
    x = a;
    y = K1 * a + K2 * b;
}
