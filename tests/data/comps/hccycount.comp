component hccycount "count_function, a string modparam and variable defaults, in Cython";
pin out s32 len_ "length of the label modparam";
pin out float ramp "grows by step each run";
pin out u64 total "hits[0] * 1000 + hits[1]";
variable double step = 0.25;
variable int hits[2] = 3;
modparam string label = "abc" "a label";
function _ nofp;
option count_function yes;
option cython yes;
license "GPL";
;;
from libc.string cimport strlen

cdef int get_count() noexcept:
    return 3

FUNCTION(_):
    len_ = <int>strlen(label)
    ramp += step
    hits[1] += 1
    total = hits[0] * 1000 + hits[1]
