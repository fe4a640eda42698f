component mux16 "Pass one of sixteen float values through, chosen by four bits";

description """The four sel bits form a number (sel3 the most significant bit, or a
Gray code when use-graycode is TRUE) that chooses which of in00 to in15 is
copied to out-f and, truncated towards zero, to out-s.

A non-zero debounce-time makes a new selection wait until the sel bits have
differed from the current one for that long, so that a rotary switch
passing through other positions does not make the output jump. The time
counts the cycles in which they differed since the last switch, also when
they went back to the current selection in between (as LinuxCNC 2.9). suppress-no-input keeps the
output unchanged while all four sel bits are FALSE, for switches that open
every contact between two positions (in00 can then not be chosen).""";

pin in bit use-graycode "TRUE: the sel bits are a Gray code (one bit changes per step, as with many rotary switches); FALSE: plain binary";
pin in bit suppress-no-input "TRUE: while every sel bit is FALSE, keep the output as it is (in00 cannot be selected)";
pin in float debounce-time "How long, in seconds, a new selection must differ from the current one before the output follows it (e.g. 0.1); 0 follows at once";
pin in bit sel#[4] "The selection bits, sel0 the least significant";
pin out float out-f "The selected input";
pin out s32 out-s """The selected input truncated towards zero; a value outside the s32 range
(or not a number) gives -2147483648""";
pin in float in##[16] "The values to choose from";
param r float elapsed "How long the pending selection has been waiting (seconds), for debugging";
param r s32 selected "The number of the selected input after Gray-code conversion, for debugging";

variable int pending;

function _;

see_also "mux2(9), mux4(9), mux8(9), mux_generic(9), gray2bin(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int n = (sel(3) << 3) | (sel(2) << 2) | (sel(1) << 1) | sel(0);
    double v;

    /* all contacts open between two switch positions: hold the output */
    if (suppress_no_input && n == 0)
        return;

    if (use_graycode) {
        n ^= n >> 2;
        n ^= n >> 1;
    }

    if (n != selected) {
        /* a new selection: time it from its first cycle after the last
           switch, even if it keeps changing (or goes back to the selected
           input for a while) while the time runs, as the reference */
        if (!pending) {
            pending = 1;
            elapsed = 0;
        }
        if (elapsed < debounce_time) {
            elapsed += fperiod;
            return;
        }
        pending = 0;
        selected = n;
    }

    v = in(selected);
    out_f = v;
    if (v > -2147483649.0 && v < 2147483648.0)
        out_s = (rtapi_s32)v;
    else
        out_s = -2147483647 - 1;
}
