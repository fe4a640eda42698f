component maj3 "Majority vote of three bits";

pin in bit in1;
pin in bit in2;
pin in bit in3;
pin out bit out "TRUE when at least two of in1, in2 and in3 are TRUE (inverted if invert is set)";
param rw bit invert "When TRUE, out is the opposite of the majority";

function _ nofp;

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int m = (in1 + in2 + in3) >= 2;

    out = invert ? !m : m;
}
