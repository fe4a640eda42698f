# A two-input AND gate written in Cython: the smallest realtime component.

from halsdk cimport hal

hal.import_halsdk()

cdef struct gate_t:
    hal.hal_bit_t *in0
    hal.hal_bit_t *in1
    hal.hal_bit_t *out


cdef void update(void *arg, long period) noexcept nogil:
    cdef gate_t *g = <gate_t *>arg
    g.out[0] = g.in0[0] and g.in1[0]


modparams = {"count": (int, 1, "number of gates")}

cdef int comp_id = -1


def setup(count=1):
    global comp_id
    cdef gate_t *g
    cdef int i
    if count < 1 or count > 10000:
        raise ValueError(f"count={count} must be 1..10000")
    comp_id = hal.hal_init(b"tand2")
    if comp_id < 0:
        raise RuntimeError("hal_init failed")
    for i in range(count):
        g = <gate_t *>hal.hal_malloc(sizeof(gate_t))
        if g == NULL:
            raise MemoryError("hal_malloc failed")
        if (hal.hal_pin_bit_newf(hal.HAL_IN, &g.in0, comp_id,
                                 b"tand2.%d.in0", i) < 0 or
                hal.hal_pin_bit_newf(hal.HAL_IN, &g.in1, comp_id,
                                     b"tand2.%d.in1", i) < 0 or
                hal.hal_pin_bit_newf(hal.HAL_OUT, &g.out, comp_id,
                                     b"tand2.%d.out", i) < 0 or
                hal.hal_export_functf(update, g, 0, 0, comp_id,
                                      b"tand2.%d", i) < 0):
            raise RuntimeError(f"tand2.{i}: cannot create pins")
    hal.hal_ready(comp_id)


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
