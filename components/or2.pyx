# or2: two-input OR gate.
#
#     loadrt or2 [count=N | names=name1[,name2...]]
#
# Each instance has bit pins in0, in1 (in) and out (out), and a function
# named after the instance (no floating point): out = in0 OR in1.

COMP = "or2"


cdef inline bint gate(bint in0, bint in1) noexcept nogil:
    return in0 or in1


include "_gate2.pxi"
