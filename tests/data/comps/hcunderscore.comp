component hcunderscore "Trailing underscores, keyword names, dashes and dots";
pin in float min_ = -1;
pin in float max_ = 1;
pin in float value "the clamped value";
pin out float out.clamped;
pin out bit is_low_;
pin out s32 long_name_here;
param rw s32 x-y.z = 3;
function do_it_;
license "GPL";
;;
FUNCTION(do_it_) {
    double v = value;
    if (v < min_) v = min_;
    if (v > max_) v = max_;
    out_clamped = v;
    is_low_ = value < min_;
    long_name_here = x_y_z * 2;
}
