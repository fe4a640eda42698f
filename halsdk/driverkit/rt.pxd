# Realtime driver helpers: the canonical channels for Cython components.
#
#     from halsdk cimport hal
#     from halsdk.driverkit cimport rt
#     hal.import_halsdk()          # once, at module level, as usual
#
# Each channel is a struct that lives in HAL shared memory (allocate it
# with hal.hal_malloc).  In setup(), rt.<type>_export() creates the pins
# and params of one channel, named
#     <device>.<num>.<io-type>.<chan>.<name>     (chan with two digits)
# and sets their defaults.  In the thread, the nogil inline functions
# convert between raw device values and the pins:
#     rt.digin_update(ch, level)     rt.digout_raw(ch)
#     rt.adcin_update(ch, raw)       rt.dacout_raw(ch)
#     rt.encoder_update(ch, counter, period)
# The export functions return 0 or a negative errno value (the first HAL
# call that failed, or -EDOM for a bad argument); rt.check() turns that
# into a Python exception.
#
# Nothing here allocates, locks or touches Python on the thread path.

from libc.errno cimport EDOM
from libc.math cimport llround
from libc.stdio cimport snprintf
from libc.string cimport strerror

from halsdk cimport hal

# ---------------------------------------------------------------------
# Limits and fault codes

cdef enum:
    RT_NAME_LEN = 48            # longest "<device>.<num>" kept for messages
    RT_FAULT_NONE = 0           # fault codes, as in the Python SDK
    RT_FAULT_OPEN = 1
    RT_FAULT_READ = 2
    RT_FAULT_WRITE = 3


# A realtime function: void f(void *arg, long period) noexcept nogil
ctypedef hal.hal_funct_t funct_t


cdef inline int check(int r, what) except -1:
    """Raise RuntimeError("what: <HAL's message>") when r < 0.  rt's own
    argument checks return -EDOM, which has no HAL message: the text is
    then that of the error number."""
    cdef const char *msg
    if r >= 0:
        return 0
    msg = hal.halsdk_last_error()
    text = msg.decode("utf-8", "replace") if msg != NULL else ""
    if r == -EDOM or not text:
        text = f"{strerror(-r).decode()} (error {r})"
    raise RuntimeError(f"{what}: {text}")


# ---------------------------------------------------------------------
# The device: fault pins and the read/write functions

cdef struct device_t:
    hal.hal_bit_t *fault        # out: the device is not working
    hal.hal_u32_t *fault_code   # out: RT_FAULT_* (0: ok)
    hal.hal_u32_t *fault_count  # out: how many times a fault began
    char name[RT_NAME_LEN]      # "<device>.<num>", for messages


cdef inline int device_export(device_t *d, int comp_id, const char *device,
                              int num) noexcept nogil:
    """Create <device>.<num>.fault, .fault-code and .fault-count."""
    cdef int r
    snprintf(d.name, RT_NAME_LEN, b"%s.%d", device, num)
    r = hal.hal_pin_bit_newf(hal.HAL_OUT, &d.fault, comp_id,
                             b"%s.%d.fault", device, num)
    if r < 0:
        return r
    r = hal.hal_pin_u32_newf(hal.HAL_OUT, &d.fault_code, comp_id,
                             b"%s.%d.fault-code", device, num)
    if r < 0:
        return r
    return hal.hal_pin_u32_newf(hal.HAL_OUT, &d.fault_count, comp_id,
                                b"%s.%d.fault-count", device, num)


cdef inline void device_fault(device_t *d, unsigned int code,
                              const char *why) noexcept nogil:
    """Set the fault (code != 0; fault-code shows the latest).  A fault
    that begins counts once and logs "<device>.<num>: why" once; calls
    while it lasts only update fault-code."""
    if code == RT_FAULT_NONE:
        return
    d.fault_code[0] = code
    if d.fault[0]:
        return
    d.fault[0] = 1
    d.fault_count[0] += 1
    hal.rtapi_print_msg(hal.RTAPI_MSG_ERR, b"%s: %s\n", d.name, why)


cdef inline void device_ok(device_t *d) noexcept nogil:
    """Clear the fault after a good cycle; logs one line if it was set."""
    if d.fault[0]:
        hal.rtapi_print_msg(hal.RTAPI_MSG_ERR, b"%s: recovered\n", d.name)
    d.fault[0] = 0
    d.fault_code[0] = RT_FAULT_NONE


cdef inline int export_funct(funct_t funct, void *arg, int comp_id,
                             const char *device, int num,
                             const char *io_type,
                             const char *what) noexcept nogil:
    """Export <device>.<num>.<io-type>.<what> (io_type NULL:
    <device>.<num>.<what>); what is "read" or "write" by convention.
    The function uses floating point and is not reentrant."""
    if io_type == NULL:
        return hal.hal_export_functf(funct, arg, 1, 0, comp_id, b"%s.%d.%s",
                                     device, num, what)
    return hal.hal_export_functf(funct, arg, 1, 0, comp_id, b"%s.%d.%s.%s",
                                 device, num, io_type, what)


# ---------------------------------------------------------------------
# digin: in, in-not (bit, out)

cdef struct digin_t:
    hal.hal_bit_t *in_          # "in"
    hal.hal_bit_t *in_not       # "in-not"


cdef inline int digin_export(digin_t *ch, int comp_id, const char *device,
                             int num, int chan) noexcept nogil:
    cdef int r
    r = hal.hal_pin_bit_newf(hal.HAL_OUT, &ch.in_, comp_id,
                             b"%s.%d.digin.%02d.in", device, num, chan)
    if r < 0:
        return r
    r = hal.hal_pin_bit_newf(hal.HAL_OUT, &ch.in_not, comp_id,
                             b"%s.%d.digin.%02d.in-not", device, num, chan)
    if r < 0:
        return r
    ch.in_[0] = 0
    ch.in_not[0] = 1
    return 0


cdef inline void digin_update(digin_t *ch, int level) noexcept nogil:
    """Publish the hardware level (any non-zero value is true)."""
    ch.in_[0] = level != 0
    ch.in_not[0] = level == 0


# ---------------------------------------------------------------------
# digout: out (bit, in); param invert

cdef struct digout_t:
    hal.hal_bit_t *out
    hal.hal_bit_t invert


cdef inline int digout_export(digout_t *ch, int comp_id, const char *device,
                              int num, int chan) noexcept nogil:
    cdef int r
    ch.invert = 0
    r = hal.hal_pin_bit_newf(hal.HAL_IN, &ch.out, comp_id,
                             b"%s.%d.digout.%02d.out", device, num, chan)
    if r < 0:
        return r
    return hal.hal_param_bit_newf(hal.HAL_RW, &ch.invert, comp_id,
                                  b"%s.%d.digout.%02d.invert", device, num,
                                  chan)


cdef inline int digout_raw(digout_t *ch) noexcept nogil:
    """The level to drive: out xor invert (0 or 1)."""
    return (ch.out[0] != 0) != (ch.invert != 0)


# ---------------------------------------------------------------------
# adcin: value (float, out); params scale, offset, bit_weight, hw_offset

cdef struct adcin_t:
    hal.hal_float_t *value
    hal.hal_float_t scale       # 1
    hal.hal_float_t offset      # 0
    hal.hal_float_t bit_weight  # 1: input units per count
    hal.hal_float_t hw_offset   # 0: counts read at zero input


cdef inline int adcin_export(adcin_t *ch, int comp_id, const char *device,
                             int num, int chan) noexcept nogil:
    cdef int r
    ch.scale = 1.0
    ch.offset = 0.0
    ch.bit_weight = 1.0
    ch.hw_offset = 0.0
    r = hal.hal_pin_float_newf(hal.HAL_OUT, &ch.value, comp_id,
                               b"%s.%d.adcin.%02d.value", device, num, chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.scale, comp_id,
                                 b"%s.%d.adcin.%02d.scale", device, num, chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.offset, comp_id,
                                 b"%s.%d.adcin.%02d.offset", device, num,
                                 chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.bit_weight, comp_id,
                                 b"%s.%d.adcin.%02d.bit_weight", device, num,
                                 chan)
    if r < 0:
        return r
    return hal.hal_param_float_newf(hal.HAL_RW, &ch.hw_offset, comp_id,
                                    b"%s.%d.adcin.%02d.hw_offset", device,
                                    num, chan)


cdef inline double adcin_update(adcin_t *ch, double raw) noexcept nogil:
    """value = raw * scale - offset; returns it."""
    cdef double v = raw * ch.scale - ch.offset
    ch.value[0] = v
    return v


cdef inline double adcin_update_counts(adcin_t *ch,
                                       long long counts) noexcept nogil:
    """For a converter: raw = (counts - hw_offset) * bit_weight, then
    adcin_update(raw).  With the defaults, raw = counts."""
    return adcin_update(ch, (counts - ch.hw_offset) * ch.bit_weight)


# ---------------------------------------------------------------------
# dacout: value (float, in), enable (bit, in); params scale, offset,
# high_limit, low_limit, bit_weight, hw_offset

cdef struct dacout_t:
    hal.hal_float_t *value
    hal.hal_bit_t *enable
    hal.hal_float_t scale       # 1
    hal.hal_float_t offset      # 0
    hal.hal_float_t high_limit  # 1e30
    hal.hal_float_t low_limit   # -1e30
    hal.hal_float_t bit_weight  # 1: output units per count
    hal.hal_float_t hw_offset   # 0: output when 0 is written


cdef inline int dacout_export(dacout_t *ch, int comp_id, const char *device,
                              int num, int chan) noexcept nogil:
    """Limits default to +-1e30; set ch.low_limit/high_limit after the
    call for a converter with a known range."""
    cdef int r
    ch.scale = 1.0
    ch.offset = 0.0
    ch.high_limit = 1e30
    ch.low_limit = -1e30
    ch.bit_weight = 1.0
    ch.hw_offset = 0.0
    r = hal.hal_pin_float_newf(hal.HAL_IN, &ch.value, comp_id,
                               b"%s.%d.dacout.%02d.value", device, num, chan)
    if r < 0:
        return r
    r = hal.hal_pin_bit_newf(hal.HAL_IN, &ch.enable, comp_id,
                             b"%s.%d.dacout.%02d.enable", device, num, chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.scale, comp_id,
                                 b"%s.%d.dacout.%02d.scale", device, num,
                                 chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.offset, comp_id,
                                 b"%s.%d.dacout.%02d.offset", device, num,
                                 chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.high_limit, comp_id,
                                 b"%s.%d.dacout.%02d.high_limit", device,
                                 num, chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.low_limit, comp_id,
                                 b"%s.%d.dacout.%02d.low_limit", device, num,
                                 chan)
    if r < 0:
        return r
    r = hal.hal_param_float_newf(hal.HAL_RW, &ch.bit_weight, comp_id,
                                 b"%s.%d.dacout.%02d.bit_weight", device,
                                 num, chan)
    if r < 0:
        return r
    return hal.hal_param_float_newf(hal.HAL_RW, &ch.hw_offset, comp_id,
                                    b"%s.%d.dacout.%02d.hw_offset", device,
                                    num, chan)


cdef inline double dacout_raw(dacout_t *ch) noexcept nogil:
    """The value to send: value * scale + offset, clamped to
    [low_limit, high_limit]; 0 while enable is false."""
    cdef double v
    if not ch.enable[0]:
        return 0.0
    v = ch.value[0] * ch.scale + ch.offset
    if v > ch.high_limit:
        v = ch.high_limit
    if v < ch.low_limit:
        v = ch.low_limit
    return v


cdef inline long long dacout_counts(dacout_t *ch) noexcept nogil:
    """For a converter: round((dacout_raw() - hw_offset) / bit_weight)
    (bit_weight 0 counts as 1); 0 while enable is false.  Clamp the
    result to the converter's range yourself."""
    cdef double w = ch.bit_weight
    if not ch.enable[0]:
        return 0
    if w == 0.0:
        w = 1.0
    return llround((dacout_raw(ch) - ch.hw_offset) / w)


# ---------------------------------------------------------------------
# encoder: count (s32, out), position, velocity (float, out), reset (bit,
# in), index-enable (bit, io; optional); param position-scale

cdef struct encoder_t:
    hal.hal_s32_t *count
    hal.hal_float_t *position
    hal.hal_float_t *velocity
    hal.hal_bit_t *reset
    hal.hal_bit_t *index_enable  # NULL unless exported with index=1
    hal.hal_float_t position_scale  # 1: counts per unit (0 counts as 1)
    # private state of encoder_update
    long long total             # extended count since load
    long long zero              # total at the last reset or index
    unsigned int last           # the counter at the last update
    unsigned int shift          # 32 - counter width
    int primed                  # velocity is valid after one update


cdef inline int encoder_export(encoder_t *ch, int comp_id,
                               const char *device, int num, int chan,
                               int bits, int index) noexcept nogil:
    """bits: width of the hardware counter (1..32); it may wrap.  index:
    also create index-enable.  Returns -EDOM for a bad width."""
    cdef int r
    if bits < 1 or bits > 32:
        return -EDOM
    ch.position_scale = 1.0
    ch.total = 0
    ch.zero = 0
    ch.last = 0
    ch.shift = 32 - bits
    ch.primed = 0
    ch.index_enable = NULL
    r = hal.hal_pin_s32_newf(hal.HAL_OUT, &ch.count, comp_id,
                             b"%s.%d.encoder.%02d.count", device, num, chan)
    if r < 0:
        return r
    r = hal.hal_pin_float_newf(hal.HAL_OUT, &ch.position, comp_id,
                               b"%s.%d.encoder.%02d.position", device, num,
                               chan)
    if r < 0:
        return r
    r = hal.hal_pin_float_newf(hal.HAL_OUT, &ch.velocity, comp_id,
                               b"%s.%d.encoder.%02d.velocity", device, num,
                               chan)
    if r < 0:
        return r
    r = hal.hal_pin_bit_newf(hal.HAL_IN, &ch.reset, comp_id,
                             b"%s.%d.encoder.%02d.reset", device, num, chan)
    if r < 0:
        return r
    if index:
        r = hal.hal_pin_bit_newf(hal.HAL_IO, &ch.index_enable, comp_id,
                                 b"%s.%d.encoder.%02d.index-enable", device,
                                 num, chan)
        if r < 0:
            return r
    return hal.hal_param_float_newf(hal.HAL_RW, &ch.position_scale, comp_id,
                                    b"%s.%d.encoder.%02d.position-scale",
                                    device, num, chan)


cdef inline long long encoder_delta(encoder_t *ch,
                                    unsigned int counter) noexcept nogil:
    """Signed change of the counter since the last update, correct across
    a wrap of its width while it moves less than half its range."""
    cdef unsigned int d = (counter - ch.last) << ch.shift
    return (<int>d) >> ch.shift


cdef inline void encoder_index(encoder_t *ch,
                               unsigned int latched) noexcept nogil:
    """The hardware saw an index pulse with the counter at latched: if
    index-enable is true, that position becomes count 0 and index-enable
    is cleared.  Call it before encoder_update in the same cycle."""
    if ch.index_enable == NULL or not ch.index_enable[0]:
        return
    ch.zero = ch.total + encoder_delta(ch, latched)
    ch.index_enable[0] = 0


cdef inline void encoder_update(encoder_t *ch, unsigned int counter,
                                long period) noexcept nogil:
    """Publish the hardware counter read this cycle, period ns after the
    last read.  count and position count from the counter's value at load
    (read as a signed number of its width), from the last reset, or from
    the last index taken; while reset is true the count stays 0.
    velocity = counts moved / position-scale / period (0 on the first
    update)."""
    cdef long long delta = encoder_delta(ch, counter)
    cdef double scale = ch.position_scale
    if scale == 0.0:
        scale = 1.0
    ch.total += delta
    ch.last = counter
    if ch.reset[0]:
        ch.zero = ch.total
    ch.count[0] = <int>(ch.total - ch.zero)
    ch.position[0] = (ch.total - ch.zero) / scale
    if ch.primed and period > 0:
        ch.velocity[0] = delta / scale / (period * 1e-9)
    else:
        ch.velocity[0] = 0.0
    ch.primed = 1
