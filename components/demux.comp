component demux "Turn on one of several bits, chosen by a number and/or by selection bits";

description """The personality of an instance is its number of outputs (1 to 32); an
instance loaded without one (no personality= given, or fewer values than
instances) has 32, as in LinuxCNC.
The selection is the binary number on the sel-bit pins plus sel-u32; usually
only one of the two is connected, but a sel-bit can also shift the range that
sel-u32 selects from. A selection past the last output selects the last
output; a sum that wraps to 2147483648 or more (a negative number) selects
none.

With bargraph set, every output below the selected one is TRUE instead (the
selected one itself is not), as for an LED bar graph.""";

pin in bit sel-bit-##[5] "The selection as a binary number, sel-bit-00 the least significant bit";
pin in u32 sel-u32 "The selection as a number, added to the one on the sel-bit pins";
pin out bit out-##[32 : personality] "out-MM is TRUE when the selection is MM (or above MM, with bargraph)";
param rw bit bargraph = 0 "TRUE: turn on every output below the selected one instead of just the selected one";

function _;
option default_personality 32;

see_also "select8(9), mux_generic(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    rtapi_u32 u = sel_u32;
    int i, s;

    for (i = 0; i < 5; i++)
        u += (rtapi_u32)sel_bit(i) << i;
    s = (int)u;
    if (s > personality - 1)
        s = personality - 1;
    for (i = 0; i < personality; i++)
        out(i) = bargraph ? i < s : i == s;
}
