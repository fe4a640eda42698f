component filter_kalman "One-dimensional Kalman filter (linear quadratic estimation) that smooths a noisy signal";

description """
Estimates the true value of a slowly changing quantity from noisy
measurements, for instance a temperature or a voltage read by an ADC.

Each cycle the filter first lets its error estimate grow by
\\fBQk\\fR, then weighs the new measurement \\fBzk\\fR against its previous
estimate with the gain
.RS
K = P / (P + Rk)
.RE
so the estimate becomes \\fIestimate + K * (zk \\- estimate)\\fR and the
error estimate \\fIP\\fR shrinks by the factor \\fI1 \\- K\\fR. After a reset
the estimate is 0 and \\fIP\\fR is 1.

\\fBRk\\fR and \\fBQk\\fR must be found for each sensor; their defaults (the
smallest normal single-precision number) are only placeholders. A
practical way: record raw \\fBzk\\fR values (halscope, or the \\fBdebug\\fR
pin) while the measured quantity is steady, and use their variance for
\\fBRk\\fR. \\fBQk\\fR sets how fast the filter follows real changes: the
smaller it is compared with \\fBRk\\fR, the smoother and the slower the
output. Choosing both a little larger than computed gives some margin.
See also https://en.wikipedia.org/wiki/Kalman_filter.
""";

pin in bit debug = FALSE "While TRUE, print the measurement and the estimate every cycle (to the realtime log, one line a cycle, labelled filter-kalman.0 for every instance)";
pin in bit passthrough = FALSE "While TRUE, xk-out follows zk unfiltered; the filter state is kept as it is";
pin in bit reset = FALSE "While TRUE, the filter returns to its initial state and xk-out is 0 (wins over passthrough)";

pin in float zk "The measurement to filter";
pin out float xk_out "The filtered estimate";

param rw float Rk = 1.17549e-38 "Variance of the measurement noise: larger means less trust in each measurement";
param rw float Qk = 1.17549e-38 "Variance added to the estimate's error each cycle: larger means a faster but noisier response";

variable float xk;
variable float pk = 1.0;
function _ "Filter one measurement: update xk-out from zk";

author "the halsdk authors";
license "GPL-2.0-or-later";
;;
FUNCTION(_) {
    if (reset) {
        /* back to the initial state */
        xk = 0.0;
        pk = 1.0;
        xk_out = 0.0;
    } else if (passthrough) {
        xk_out = zk;
    } else {
        /* the state is kept in single precision, as the reference does;
           one cycle is computed in double */
        double pred = pk + Qk;          /* predict: uncertainty grows */
        double gain = pred / (pred + Rk);

        xk_out = xk + gain * (zk - xk); /* correct towards the measurement */
        xk = xk_out;
        pk = (1.0 - gain) * pred;
    }

    /* the reference labels these lines "filter-kalman.0" whatever the
       instance; keep that so logs read the same */
    if (debug)
        rtapi_print("filter-kalman.0 %f %f\n", zk, xk_out);
}
