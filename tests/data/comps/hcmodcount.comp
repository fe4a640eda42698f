component hcmodcount "The module-level count read as a variable, and default_count";
pin out s32 ninst;
pin out s32 index_;
variable int me;
option default_count 3;
option extra_setup yes;
function _;
license "GPL";
;;
EXTRA_SETUP() {
    me = extra_arg;
    return 0;
}

FUNCTION(_) {
    ninst = count;
    index_ = me * 100 + count;
}
