component hcsetup "extra_setup, extra_cleanup and a modparam";
pin out s32 out;
pin out s32 ninst "the module-level count";
param r s32 base;
param rw s32 step = 1;
function update nofp;
modparam int offset = 100 "added to each instance's base";
modparam dummy unused "a documented parameter the code does not read";
option extra_setup yes;
option extra_cleanup yes;
option default_count 2;
license "GPL";
;;
static int setups;

EXTRA_SETUP() {
    base = offset + 10 * extra_arg;
    setups++;
    return 0;
}

EXTRA_CLEANUP() {
    setups = 0;
}

FUNCTION(update) {
    out = base + step * setups;
    ninst = count;
}
