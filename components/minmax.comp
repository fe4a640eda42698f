component minmax "Remember the smallest and largest values of the input";

pin in float in "The input to watch";
pin in bit reset "While TRUE, max and min both follow in (the history starts again)";
pin out float max "The largest input seen (0 at load time)";
pin out float min "The smallest input seen (0 at load time)";

function _ fp "Update max and min from in";

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double x = in;

    if (reset) {
        max = x;
        min = x;
        return;
    }
    if (x > max)
        max = x;
    if (x < min)
        min = x;
}
