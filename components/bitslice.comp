component bitslice "Split a 32-bit value into bit pins";

description """The personality of an instance is the number of bit pins it has (1 to
32): out-00 is bit 0 (the least significant) of in, out-01 bit 1, and so on.
Without a personality an instance has no output pins. weighted_sum(9) does the
opposite.""";

pin in u32 in "The value to split";
pin out bit out-##[32 : personality] "Bit MM of in";

function _ nofp;

see_also "bitwise(9), weighted_sum(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int i;

    for (i = 0; i < personality; i++)
        out(i) = (in >> i) & 1;
}
