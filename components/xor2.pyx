# xor2: two-input exclusive-OR gate.
#
#     loadrt xor2 [count=N | names=name1[,name2...]]
#
# Each instance has bit pins in0, in1 (in) and out (out), and a function
# named after the instance (no floating point): out = in0 XOR in1, true
# when exactly one input is true.

COMP = "xor2"


cdef inline bint gate(bint in0, bint in1) noexcept nogil:
    return in0 != in1


include "_gate2.pxi"
