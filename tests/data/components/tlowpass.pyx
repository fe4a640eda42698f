# A first-order low-pass filter in Cython that reads rtapi_get_time():
# out += (in - out) * (1 - exp(-period / tau)); `now` reports the time the
# function saw, so tests can check the simulated clock.

from libc.math cimport exp

from halsdk cimport hal

hal.import_halsdk()

cdef struct filt_t:
    hal.hal_float_t *inp
    hal.hal_float_t *out
    hal.hal_s64_t *now
    hal.hal_float_t tau


cdef void update(void *arg, long period) noexcept nogil:
    cdef filt_t *f = <filt_t *>arg
    cdef double k = 1.0
    if f.tau > 0:
        k = 1.0 - exp(-period * 1e-9 / f.tau)
    f.out[0] = f.out[0] + (f.inp[0] - f.out[0]) * k
    f.now[0] = hal.rtapi_get_time()


modparams = {"count": (int, 1, "number of filters")}

cdef int comp_id = -1


def setup(count=1):
    global comp_id
    cdef filt_t *f
    cdef int i
    comp_id = hal.hal_init(b"tlowpass")
    if comp_id < 0:
        raise RuntimeError("hal_init failed")
    for i in range(count):
        f = <filt_t *>hal.hal_malloc(sizeof(filt_t))
        if f == NULL:
            raise MemoryError("hal_malloc failed")
        f.tau = 0.01
        if (hal.hal_pin_float_newf(hal.HAL_IN, &f.inp, comp_id,
                                   b"tlowpass.%d.in", i) < 0 or
                hal.hal_pin_float_newf(hal.HAL_OUT, &f.out, comp_id,
                                       b"tlowpass.%d.out", i) < 0 or
                hal.hal_pin_s64_newf(hal.HAL_OUT, &f.now, comp_id,
                                     b"tlowpass.%d.now", i) < 0 or
                hal.hal_param_float_newf(hal.HAL_RW, &f.tau, comp_id,
                                         b"tlowpass.%d.tau", i) < 0 or
                hal.hal_export_functf(update, f, 1, 0, comp_id,
                                      b"tlowpass.%d", i) < 0):
            raise RuntimeError(f"tlowpass.{i}: cannot create pins")
    hal.hal_ready(comp_id)


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
