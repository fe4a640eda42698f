component hcgetcount "count_function returning a modparam-driven count";
pin out s32 id;
pin out s32 total;
variable int mine;
modparam int how_many = 2 "instances get_count() reports";
option count_function yes;
option extra_setup yes;
function _ nofp;
license "GPL";
;;
int get_count(void) { return how_many; }

EXTRA_SETUP() {
    mine = extra_arg;
    return 0;
}

FUNCTION(_) {
    id = mine;
    total = get_count();
}
