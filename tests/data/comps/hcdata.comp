component hcdata "option data and count_function";
pin out s32 n;
pin out s32 which;
function _ nofp;
option data hcdata_state;
option count_function yes;
license "GPL";
;;
typedef struct { int calls; int id; } hcdata_state;

static int get_count(void) { return 3; }

FUNCTION(_) {
    data.calls++;
    n = data.calls;
}
