# _gate2.pxi: the body shared by the two-input gates (and2, or2, xor2).
#
# The including module defines COMP (its component name) and
#     cdef inline bint gate(bint in0, bint in1) noexcept nogil
# Each instance has bit pins in0, in1 (in) and out (out), and a function
# named after the instance (no floating point): out = gate(in0, in1).

from halsdk cimport hal

from halsdk.components._instances import (COUNT_NAMES_MODPARAMS, hal_error,
                                          instance_names)

hal.import_halsdk()

cdef struct gate_t:
    hal.hal_bit_t *in0
    hal.hal_bit_t *in1
    hal.hal_bit_t *out


cdef void update(void *arg, long period) noexcept nogil:
    cdef gate_t *g = <gate_t *>arg
    g.out[0] = gate(g.in0[0] != 0, g.in1[0] != 0)


modparams = dict(COUNT_NAMES_MODPARAMS)

cdef int comp_id = -1


cdef int check(int r) except -1:
    if r < 0:
        raise hal_error(r, hal.halsdk_last_error().decode("utf-8", "replace"))
    return r


def setup(count=0, names=None):
    """Make the gates: ``count`` of them named <COMP>.<i>, or one per name
    in ``names``."""
    global comp_id
    cdef gate_t *g
    cdef bytes b
    cdef char *n
    wanted = instance_names(COMP, count, names)
    comp_id = check(hal.hal_init(COMP.encode()))
    for name in wanted:
        b = name.encode("utf-8")
        n = b
        g = <gate_t *>hal.hal_malloc(sizeof(gate_t))
        if g == NULL:
            check(-12)
        check(hal.hal_pin_bit_newf(hal.HAL_IN, &g.in0, comp_id, b"%s.in0", n))
        check(hal.hal_pin_bit_newf(hal.HAL_IN, &g.in1, comp_id, b"%s.in1", n))
        check(hal.hal_pin_bit_newf(hal.HAL_OUT, &g.out, comp_id, b"%s.out", n))
        check(hal.hal_export_funct(n, update, g, 0, 0, comp_id))
    check(hal.hal_ready(comp_id))


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
