# A 64-bit event counter in Cython: counts rising edges of `in`, with a
# `reset` input, an s64 `count` and a u64 `cycles` output.  Shows s64/u64
# pins and params past the 32-bit range, and instances made at run time
# (newinst / delinst).

from halsdk cimport hal

hal.import_halsdk()

cdef struct counter_t:
    hal.hal_bit_t *inp
    hal.hal_bit_t *reset
    hal.hal_s64_t *count
    hal.hal_u64_t *cycles
    hal.hal_s64_t step
    hal.hal_bit_t last


cdef void update(void *arg, long period) noexcept nogil:
    cdef counter_t *c = <counter_t *>arg
    if c.reset[0]:
        c.count[0] = 0
    elif c.inp[0] and not c.last:
        c.count[0] += c.step
    c.last = c.inp[0]
    c.cycles[0] += 1


modparams = {"names": ([str], "", "instance names")}
instance_params = {"step": (int, 1, "amount per edge")}

cdef int comp_id = -1


cdef int make(bytes name, int owner, long long step) except -1:
    cdef counter_t *c = <counter_t *>hal.hal_malloc(sizeof(counter_t))
    if c == NULL:
        raise MemoryError("hal_malloc failed")
    c.step = step
    if (hal.hal_pin_bit_newf(hal.HAL_IN, &c.inp, owner, b"%s.in",
                             <char *>name) < 0 or
            hal.hal_pin_bit_newf(hal.HAL_IN, &c.reset, owner, b"%s.reset",
                                 <char *>name) < 0 or
            hal.hal_pin_s64_newf(hal.HAL_OUT, &c.count, owner, b"%s.count",
                                 <char *>name) < 0 or
            hal.hal_pin_u64_newf(hal.HAL_OUT, &c.cycles, owner,
                                 b"%s.cycles", <char *>name) < 0 or
            hal.hal_param_s64_newf(hal.HAL_RW, &c.step, owner, b"%s.step",
                                   <char *>name) < 0 or
            hal.hal_export_functf(update, c, 0, 0, owner, b"%s",
                                  <char *>name) < 0):
        raise RuntimeError(f"{name.decode()}: cannot create its pins")
    return 0


def setup(names=("tcounter.0",)):
    global comp_id
    comp_id = hal.hal_init(b"tcounter")
    if comp_id < 0:
        raise RuntimeError("hal_init failed")
    for name in names:
        make(name.encode(), comp_id, 1)
    hal.hal_ready(comp_id)


def new_instance(name, step=1):
    cdef int inst = hal.halsdk_inst_new(name.encode(), comp_id)
    if inst < 0:
        raise RuntimeError(hal.halsdk_last_error().decode())
    make(name.encode(), inst, step)


deleted = []


def delete_instance(name):
    deleted.append(name)


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
