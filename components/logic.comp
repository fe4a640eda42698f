component logic "Configurable AND, OR, XOR, NAND and NOR gates of up to 16 inputs";

description """The personality of each instance, given on the load line as a hexadecimal
number, chooses its number of inputs and which outputs it has. Add:
.IP \\(bu 4
the number of inputs, 0 to 16 (the in-MM pins);
.IP \\(bu
0x100 for the and output (TRUE when every input is TRUE),
.IP \\(bu
0x200 for or (TRUE when at least one input is TRUE),
.IP \\(bu
0x400 for xor (TRUE when an odd number of inputs is TRUE),
.IP \\(bu
0x800 for nand (the opposite of and),
.IP \\(bu
0x1000 for nor (the opposite of or).
.PP
For example 0x302 makes a two-input gate with both an and and an or output,
and 0x1f04 a four-input gate with all five. With no inputs, and and nor are
TRUE, the others FALSE. Give one personality per instance, in the order of
count= or names=.""";

pin in bit in-##[16 : personality & 0xff] "The inputs";
pin out bit and if personality & 0x100 "TRUE when every input is TRUE";
pin out bit or if personality & 0x200 "TRUE when at least one input is TRUE";
pin out bit xor if personality & 0x400 "TRUE when an odd number of inputs is TRUE";
pin out bit nand if personality & 0x800 "FALSE when every input is TRUE";
pin out bit nor if personality & 0x1000 "FALSE when at least one input is TRUE";

function _ nofp "Compute the outputs from the inputs.";

examples """A three-input or gate:
.IP
.nf
loadrt logic count=1 personality=0x203
addf logic.0 servo-thread
net door-open => logic.0.in-00
net guard-open => logic.0.in-01
net cover-open => logic.0.in-02
net any-open <= logic.0.or
.fi
.PP
A two-input and gate named interlock:
.IP
.nf
loadrt logic names=interlock personality=0x102
addf interlock servo-thread
net spindle-at-speed => interlock.in-00
net coolant-on => interlock.in-01
net ready-to-cut <= interlock.and
.fi""";

see_also "and2(9), lut5(9), not(9), or2(9), xor2(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int i, n = personality & 0xff, ones = 0;

    for (i = 0; i < n; i++)
        if (in(i))
            ones++;
    if (personality & 0x100)
        and = ones == n;
    if (personality & 0x200)
        or = ones != 0;
    if (personality & 0x400)
        xor = ones & 1;
    if (personality & 0x800)
        nand = ones != n;
    if (personality & 0x1000)
        nor = ones == 0;
}
