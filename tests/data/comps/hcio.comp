component hcio "An io pin, r and rw params";
pin io s32 acc "incremented by step, clamped by limit";
pin io bit toggle;
param rw s32 step = 2;
param rw s32 limit = 9;
param r s32 wraps;
function _ nofp;
license "GPL";
;;
FUNCTION(_) {
    acc += step;
    if (acc > limit) {
        acc = 0;
        wraps++;
    }
    toggle = !toggle;
}
