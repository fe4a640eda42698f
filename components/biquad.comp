component biquad "Second-order IIR filter: low-pass, notch or own coefficients";

pin in float in "Filter input";
pin out float out "Filter output (in itself while disabled or invalid)";
pin in bit enable = 0 """TRUE: filter. FALSE: out follows in unfiltered. On
each change from FALSE to TRUE with type 1 or 2 the coefficients are
designed again from f0 and Q and the filter state is cleared (type 0 keeps
the state)""";
pin out bit valid = 0 """FALSE when the last enable could not make usable
coefficients: type 1 or 2 with Q outside [0.5, 2] or f0 above half the
sample rate, or an unknown type. Then out follows in""";
pin in u32 type = 0 """What the enable edge does: 0 uses the n0, n1, n2, d1, d2
params as they are; 1 designs a low-pass filter from f0 and Q; 2 designs a
notch filter at f0 with quality Q""";
pin in float f0 = 250.0 "Corner (type 1) or centre (type 2) frequency, Hz";
pin in float Q = 0.7071 "Quality factor (0.7071: flattest low-pass)";
pin out float s1 = 0.0 "First internal state (for debugging)";
pin out float s2 = 0.0 "Second internal state (for debugging)";

param rw float d1 = 0.0 "Denominator coefficient of z^-1";
param rw float d2 = 0.0 "Denominator coefficient of z^-2";
param rw float n0 = 1.0 "Numerator coefficient of z^0";
param rw float n1 = 0.0 "Numerator coefficient of z^-1";
param rw float n2 = 0.0 "Numerator coefficient of z^-2";

variable int was_enabled;

function _ "Filter one sample (and design the filter on enable's rising edge)";

description """A biquad IIR filter with the transfer function

H(z) = (n0 + n1 z^-1 + n2 z^-2) / (1 + d1 z^-1 + d2 z^-2)

computed in transposed direct form II. The coefficients are the params; on
a rising edge of enable with type 1 or 2 they are designed for the thread's
period (bilinear transform, as in the well-known audio EQ cookbook) and
written to the params. The params are used as they are every period, so
with type 0 they can be tuned while the filter runs.""";
see_also "lowpass(9)";
author "the halsdk authors";
license "GPL";
;;
/* the value of pi the filter designs use (12 decimals: matches the
   coefficients of LinuxCNC's biquad exactly) */
#define BQ_PI 3.141592653589

/* Design the coefficients of a low-pass (type 1) or notch (type 2)
   filter; 0 on success, -1 when the settings are unusable. */
static int design(struct __comp_state *__comp_inst, double t)
{
    double w, c, alpha, a0;

    if (Q < 0.5 || Q > 2.0 || f0 > 0.5 / t)
        return -1;
    w = 2 * BQ_PI * f0 * t;
    c = cos(w);
    alpha = sin(w) / (2 * Q);
    a0 = 1 + alpha;
    if (type == 1) {
        n0 = (1 - c) / 2 / a0;
        n1 = (1 - c) / a0;
        n2 = n0;
    } else {
        n0 = 1 / a0;
        n1 = -2 * c / a0;
        n2 = n0;
    }
    d1 = -2 * c / a0;
    d2 = (1 - alpha) / a0;
    /* a new filter starts from rest */
    s1 = 0;
    s2 = 0;
    return 0;
}

FUNCTION(_) {
    double x = in, y;

    if (enable && !was_enabled) {
        if (type == 0)
            valid = 1;
        else if (type == 1 || type == 2)
            valid = design(__comp_inst, fperiod) == 0;
        else
            valid = 0;
    }
    was_enabled = enable;
    if (!enable || !valid) {
        out = x;
        return;
    }
    y = n0 * x + s1;
    s1 = n1 * x - d1 * y + s2;
    s2 = n2 * x - d2 * y;
    out = y;
}
