component clarke3 "Clarke transform: three phases to cartesian x, y and homopolar h";

pin in float a "Phase A";
pin in float b "Phase B";
pin in float c "Phase C";
pin out float x "The cartesian x component: (2a - b - c)/3";
pin out float y "The cartesian y component: (b - c)/sqrt(3)";
pin out float h "The homopolar component: (a + b + c) * sqrt(2)/3 (zero when the phases add up to zero)";

function _ fp "Compute x, y and h";

description """
Turns a three-phase quantity (three components 120 degrees apart) into
cartesian x and y, plus the homopolar part h of phases that do not add up to
zero.  When they always do, \\fBclarke2\\fR needs only two of them.
""";
see_also "clarke2(9), clarkeinv(9)";
author "the halsdk authors";
license "GPL";
;;
/* 2/3, 1/3, 1/sqrt(3) and sqrt(2)/3, to 15 digits (the reference's numbers) */
#define K23 0.666666666666667
#define K13 0.333333333333333
#define KY  0.577350269189626
#define KH  0.471404520791032

FUNCTION(_) {
    x = K23 * a - K13 * (b + c);
    y = KY * (b - c);
    h = KH * (a + b + c);
}
