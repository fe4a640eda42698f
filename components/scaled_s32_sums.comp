component scaled_s32_sums "Scaled sum of four integer inputs";

pin in s32 in#[4] "The inputs";
pin in float scale#[4] = 1.0 "The factor for each input";
pin out s32 out_s "The sum as an integer: truncated toward zero; the most negative s32 when it does not fit";
pin out float out_f "in0*scale0 + in1*scale1 + in2*scale2 + in3*scale3";

function _ fp "Compute the sums";

see_also "sum2(9), weighted_sum(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double s = 0.0;
    int i;

    for (i = 0; i < 4; i++)
        s += in(i) * scale(i);
    out_f = s;
    /* like a C cast on x86: out-of-range sums give INT_MIN */
    if (s > -2147483649.0 && s < 2147483648.0)
        out_s = (rtapi_s32)s;
    else
        out_s = (rtapi_s32)0x80000000u;
}
