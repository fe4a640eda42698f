# not: inverter.
#
#     loadrt not [count=N | names=name1[,name2...]]
#
# Each instance has bit pins in (in) and out (out), and a function named
# after the instance (no floating point): out = NOT in.  The module is
# named "not", a Python keyword, so Python code imports it with
# importlib.import_module("halsdk.components.not").

from halsdk cimport hal

from halsdk.components._instances import (COUNT_NAMES_MODPARAMS, hal_error,
                                          instance_names)

hal.import_halsdk()

cdef struct inverter_t:
    hal.hal_bit_t *inp
    hal.hal_bit_t *out


cdef void update(void *arg, long period) noexcept nogil:
    cdef inverter_t *v = <inverter_t *>arg
    v.out[0] = v.inp[0] == 0


modparams = dict(COUNT_NAMES_MODPARAMS)

cdef int comp_id = -1


cdef int check(int r) except -1:
    if r < 0:
        raise hal_error(r, hal.halsdk_last_error().decode("utf-8", "replace"))
    return r


def setup(count=0, names=None):
    """Make the inverters: ``count`` of them named not.<i>, or one per
    name in ``names``."""
    global comp_id
    cdef inverter_t *v
    cdef bytes b
    cdef char *n
    wanted = instance_names("not", count, names)
    comp_id = check(hal.hal_init(b"not"))
    for name in wanted:
        b = name.encode("utf-8")
        n = b
        v = <inverter_t *>hal.hal_malloc(sizeof(inverter_t))
        if v == NULL:
            check(-12)
        check(hal.hal_pin_bit_newf(hal.HAL_IN, &v.inp, comp_id, b"%s.in", n))
        check(hal.hal_pin_bit_newf(hal.HAL_OUT, &v.out, comp_id, b"%s.out", n))
        check(hal.hal_export_funct(n, update, v, 0, 0, comp_id))
    check(hal.hal_ready(comp_id))


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
