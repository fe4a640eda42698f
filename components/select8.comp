component select8 "Decode a number 0 to 7 into one of eight bits";

pin in bit enable = TRUE "While FALSE, every output is FALSE";
pin in s32 sel "The number of the output to turn on; the others are FALSE";
pin out bit out#[8] """outN is TRUE while enable is TRUE and sel equals N; a sel outside 0..7
turns all outputs off""";

function _ nofp;

see_also "demux(9), match8(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int i;

    for (i = 0; i < 8; i++)
        out(i) = enable && sel == i;
}
