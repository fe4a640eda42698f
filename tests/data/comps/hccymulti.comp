component hccymulti "A Cython code section with helpers, arrays and options";
pin in float x#[4 : (personality & 3) or 1] "summed inputs";
pin out float sum "sum of the inputs times scale";
pin out float peak "largest |sum| seen while not held";
pin out float last "the sum that track saw last";
pin in bit hold "freezes track";
pin out s32 steps "runs of sum-up";
pin out u32 held "runs of track while held";
pin out s64 big;
pin io float acc "sum-up adds sum to it";
pin out bit odd if personality & 4 "steps is odd";
param rw float scale = 2.0;
param r s32 setup_value "extra_arg * 100 + bias, set by EXTRA_SETUP";
variable double hist[3];
variable int n = 10;
modparam int bias = 7 "added to setup_value";
function sum_up;
function track nofp;
option extra_setup yes;
option extra_cleanup yes;
option cython yes;
license "GPL";
;;
from libc.math cimport fabs

cdef int cleanups = 0

cdef double total(double *v, int k) noexcept nogil:
    cdef double s = 0
    cdef int i
    for i in range(k):
        s += v[i]
    return s

def cleanup_count():
    return cleanups

FUNCTION(sum_up):
    cdef int k = personality & 3
    if k == 0:
        k = 1
    sum = total(x, k) * scale
    acc += sum
    steps += 1
    big = big * 1000 + 7
    if personality & 4:
        odd = (steps % 2) == 1

FUNCTION(track):
    if hold:
        held += 1
        return
    if fabs(sum) > fabs(peak):
        peak = sum
    hist[n % 3] = sum
    last = hist[n % 3]
    n += 1

EXTRA_SETUP():
    setup_value = extra_arg * 100 + bias
    return 0

EXTRA_CLEANUP():
    global cleanups
    cleanups += 1
