component hcglobal2 "The same global names as hcglobal1, which must stay separate";
pin out s32 out;
pin out s32 shared;
function _ nofp;
license "GPL";
;;
#define STEP 5
struct acc { int total; };
struct acc state = {200};
int counter = 0;
int helper(void) { return 10; }

FUNCTION(_) {
    counter += STEP;
    state.total += helper();
    out = state.total;
    shared = counter;
}
