component lut5 "Any logic function of up to five bits, given as a truth table";

description """The five inputs form a number from 0 to 31 (in-0 is bit 0, in-4 bit 4);
out is bit number N of the function parameter, where N is that number. So
function is the sum of the weights 2^N (as a hexadecimal number) of every
input pattern for which out should be TRUE, and every one of the
4294967296 functions of five bits can be made:
.IP
.nf
in-4 in-3 in-2 in-1 in-0   weight
  0    0    0    0    0    0x1
  0    0    0    0    1    0x2
  0    0    0    1    0    0x4
  0    0    0    1    1    0x8
  0    0    1    0    0    0x10
  ...
  1    1    1    1    0    0x40000000
  1    1    1    1    1    0x80000000
.fi
.PP
Examples: 0x80000000 is TRUE only when all five inputs are TRUE (AND);
0xe is a two-input OR of in-0 and in-1 (weights 0x2, 0x4 and 0x8);
0x6 a two-input XOR of in-0 and in-1; 0xfffffffe a five-input OR. Inputs the
function does not mention must be left FALSE (unconnected), since a TRUE
there selects another row of the table.""";

pin in bit in-#[5] "The inputs; in-0 is the least significant bit of the row number";
pin out bit out "The bit of function chosen by the inputs";
param rw u32 function "The truth table: bit N is the output for input pattern N";

function _ nofp;

see_also "and2(9), logic(9), not(9), or2(9), xor2(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int i, row = 0;

    for (i = 0; i < 5; i++)
        if (in(i))
            row |= 1 << i;
    out = (function >> row) & 1;
}
