component gray2bin "Convert a Gray code to the binary number it stands for";

description """The inverse of bin2gray(9): reads a reflected binary Gray code, as
given by many absolute encoders and rotary switches, and outputs its plain
binary value.""";

pin in u32 in "The Gray-coded value";
pin out u32 out "The binary number it encodes";

function _ nofp;

see_also "bin2gray(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    rtapi_u32 v = in;

    /* each binary bit is the XOR of the Gray bits at and above it */
    v ^= v >> 16;
    v ^= v >> 8;
    v ^= v >> 4;
    v ^= v >> 2;
    v ^= v >> 1;
    out = v;
}
