component hccytypes "Cython code: every type, arrays and a conditional pin";
pin in bit b;
pin in float f = .5;
pin in s32 s = -3;
pin in u32 u = 0x20;
pin in s64 l;
pin in u64 ul;
pin out float fo;
pin out s32 so;
pin out u32 uo;
pin out s64 lo;
pin out u64 ulo;
pin out bit bo;
pin out float arr-#[3];
pin out s32 extra if personality & 1;
param rw float gain = 1e1;
option cython yes;
function _;
license "GPL";
;;
FUNCTION(_):
    cdef int i
    fo = f * gain
    so = s * 2
    uo = u + 1
    lo = l - 1
    ulo = ul + 1
    bo = not b
    for i in range(3):
        arr[i] = i * f
    if personality & 1:
        extra = 42
