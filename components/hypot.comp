component hypot "Length of a three-component vector (Euclidean distance)";

pin in float in0 "First component (e.g. the X distance)";
pin in float in1 "Second component";
pin in float in2 "Third component; leave unconnected for a 2-D distance";
pin out float out """sqrt(in0^2 + in1^2 + in2^2). The squares are summed
directly, so components above about 1e154 give inf""";

function _ "Compute out";

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    out = sqrt(in0 * in0 + in1 * in1 + in2 * in2);
}
