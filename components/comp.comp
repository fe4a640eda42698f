component comp "Comparator of two inputs, with hysteresis";

pin in float in0 "Inverting input: out goes FALSE when it rises above in1";
pin in float in1 "Non-inverting input: out goes TRUE when it rises above in0";
pin out bit out """TRUE when in1 > in0. With hysteresis, out goes TRUE when
in1 - in0 > hyst/2, goes FALSE when in1 - in0 < -hyst/2 and keeps its state
in between (also when the inputs are exactly equal and hyst is 0)""";
pin out bit equal "TRUE when |in1 - in0| <= hyst/2, and when an input or hyst is NaN (as in LinuxCNC)";

param rw float hyst = 0.0 """Width of the band around in1 = in0 where out keeps
its state. Rounding makes exact equality unreliable: set hyst to use
equal""";

function _ "Update out and equal";

notes """A negative hyst gives no memory: out is TRUE only when
in1 - in0 >= -hyst/2, and equal is never TRUE.""";
see_also "wcomp(9), near(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double d = in1 - in0;
    double half = hyst / 2;

    /* both tests run in this order, which matters only for hyst < 0 */
    if (d > half)
        out = 1;
    if (d < -half)
        out = 0;
    /* neither test passed: equal, also when d or hyst is NaN (as in
       LinuxCNC) */
    equal = !(d > half) && !(d < -half);
}
