component hcglobal1 "A mutable global, a #define, a struct and a helper named like those of hcglobal2";
pin out s32 out;
pin out s32 shared;
function _ nofp;
license "GPL";
;;
#define STEP 3
struct acc { int total; };
struct acc state = {100};
int counter = 0;
int helper(void) { return 1; }

FUNCTION(_) {
    counter += STEP;
    state.total += helper();
    out = state.total;
    shared = counter;
}
