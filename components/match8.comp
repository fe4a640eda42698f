component match8 "Compare two 8-bit numbers given as bits";

description """out is TRUE when every bit aN equals the bit bN (N from 0 to 7) and the
in pin is TRUE. Chain several match8 by connecting the out of one to the in of
the next to compare wider numbers.""";

pin in bit in = TRUE "Cascade input: while FALSE, out is FALSE whatever the other inputs";
pin in bit a#[8] "The bits of the first number";
pin in bit b#[8] "The bits of the second number";
pin out bit out "TRUE only if in is TRUE and a0..a7 equal b0..b7 bit for bit";

function _ nofp;

see_also "select8(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int i, same = in;

    for (i = 0; i < 8 && same; i++)
        same = !a(i) == !b(i);
    out = same;
}
