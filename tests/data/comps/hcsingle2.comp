component hcsingle2 "A second module with the same global name";
pin out s32 value;
pin in s32 in;
function _ nofp;
option singleton yes;
option extra_compile_args "-DSCALE=1000";
license "GPL";
;;
int shared_total;
FUNCTION(_) {
    shared_total += SCALE * in;
    value = shared_total;
}
