component blend "Linear interpolation between two inputs";

pin in float in1 "The output when select is 1.0";
pin in float in2 "The output when select is 0.0";
pin in float select "Where between in2 (0.0) and in1 (1.0) the output lies";
pin out float out "in1 * select + in2 * (1 - select)";

param rw bit open "When FALSE, select is limited to 0.0..1.0 so out stays between in2 and in1; when TRUE it is not, and out goes beyond them";

function _ fp "Compute out";

author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    double s = select;

    if (!open) {
        if (s > 1.0)
            s = 1.0;
        else if (s < 0.0)
            s = 0.0;
    }
    out = in1 * s + in2 * (1.0 - s);
}
