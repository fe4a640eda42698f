component abs_s32 "Absolute value of a signed 32-bit integer, with sign flags";

pin in s32 in "The value to take the magnitude of";
pin out s32 out """The magnitude of in. The most negative s32, -2147483648,
has no positive counterpart and comes out unchanged (the value wraps)""";
pin out bit sign "TRUE when in is below zero";
pin out bit is_positive "TRUE when in is above zero; FALSE for zero";
pin out bit is_negative "TRUE when in is below zero; FALSE for zero";

function _ nofp "Update out and the flags from in";

see_also "abs(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    hal_s32_t v = in;

    /* negate in unsigned arithmetic: wraps for INT32_MIN, no overflow */
    out = v < 0 ? (hal_s32_t)(0u - (hal_u32_t)v) : v;
    sign = v < 0;
    is_positive = v > 0;
    is_negative = v < 0;
}
