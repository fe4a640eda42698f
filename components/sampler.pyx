# sampler: copy HAL pins into a stream once per thread cycle, for
# halsampler (or Python: halsdk.core._core.stream_attach("sampler.N")).
#
#     loadrt sampler depth=D0[,D1...] cfg=CFG0[,CFG1...]
#
# One channel per cfg string, one input pin per letter (f float, b bit,
# s s32, u u32, and beyond the reference l s64, k u64; up to 256 pins).
# Channel N: pins sampler.N.pin.M, sampler.N.enable (in), sampler.N.full,
# sampler.N.curr-depth (out), sampler.N.overruns, sampler.N.sample-num (io),
# function sampler.N and stream "sampler.N" of D records.

from halsdk cimport hal

from ._channels import MODPARAMS, channels

hal.import_halsdk()

cdef struct channel_t:
    hal.hal_bit_t *enable
    hal.hal_bit_t *full
    hal.hal_s32_t *curr_depth
    hal.hal_s32_t *overruns
    hal.hal_s32_t *sample_num
    hal.halsdk_stream_t stream
    int n
    int maxdepth
    unsigned char types[256]
    void *pins[256]
    hal.halsdk_value_t rec[256]


cdef void sample(void *arg, long period) noexcept nogil:
    cdef channel_t *c = <channel_t *>arg
    cdef int i
    cdef void *p
    cdef int t
    if not c.enable[0]:
        # as the reference: curr-depth follows the reader while disabled
        t = hal.halsdk_stream_depth(c.stream)
        c.curr_depth[0] = t if t > 0 else 0
        return
    for i in range(c.n):
        p = c.pins[i]
        t = c.types[i]
        if t == hal.HAL_FLOAT:
            c.rec[i].f = (<hal.hal_float_t *>p)[0]
        elif t == hal.HAL_BIT:
            c.rec[i].lu = 0
            c.rec[i].b = 1 if (<hal.hal_bit_t *>p)[0] else 0
        elif t == hal.HAL_S32:
            c.rec[i].ls = (<hal.hal_s32_t *>p)[0]
        elif t == hal.HAL_U32:
            c.rec[i].lu = (<hal.hal_u32_t *>p)[0]
        elif t == hal.HAL_S64:
            c.rec[i].ls = (<hal.hal_s64_t *>p)[0]
        else:
            c.rec[i].lu = (<hal.hal_u64_t *>p)[0]
    if hal.halsdk_stream_write(c.stream, c.rec) < 0:
        c.overruns[0] += 1
        c.full[0] = 1
        c.curr_depth[0] = c.maxdepth
    else:
        c.full[0] = 0
        c.curr_depth[0] = hal.halsdk_stream_depth(c.stream)


modparams = dict(MODPARAMS)

cdef int comp_id = -1


def _fail(what):
    msg = hal.halsdk_last_error().decode("utf-8", "replace")
    raise RuntimeError(f"{what}: {msg}" if msg else what)


def setup(depth=None, cfg=None):
    global comp_id
    cdef channel_t *c
    cdef int i, m, r
    chans = channels("sampler", depth, cfg)
    comp_id = hal.hal_init(b"sampler")
    if comp_id < 0:
        _fail("sampler: hal_init failed")
    for i, (s, types, d) in enumerate(chans):
        c = <channel_t *>hal.hal_malloc(sizeof(channel_t))
        if c == NULL:
            raise MemoryError(f"sampler.{i}: hal_malloc failed")
        c.n = len(s)
        c.maxdepth = d
        c.stream = hal.halsdk_stream_create(f"sampler.{i}".encode(), comp_id,
                                            d, s.encode())
        if c.stream < 0:
            _fail(f"sampler.{i}")
        for m in range(len(types)):
            c.types[m] = types[m]
            name = f"sampler.{i}.pin.{m}".encode()
            if hal.hal_pin_new(name, <hal.hal_type_t>c.types[m], hal.HAL_IN,
                               &c.pins[m], comp_id) < 0:
                _fail(f"sampler.{i}")
        r = (hal.hal_pin_s32_newf(hal.HAL_OUT, &c.curr_depth, comp_id,
                                  b"sampler.%d.curr-depth", i) < 0
             or hal.hal_pin_bit_newf(hal.HAL_OUT, &c.full, comp_id,
                                     b"sampler.%d.full", i) < 0
             or hal.hal_pin_bit_newf(hal.HAL_IN, &c.enable, comp_id,
                                     b"sampler.%d.enable", i) < 0
             or hal.hal_pin_s32_newf(hal.HAL_IO, &c.overruns, comp_id,
                                     b"sampler.%d.overruns", i) < 0
             or hal.hal_pin_s32_newf(hal.HAL_IO, &c.sample_num, comp_id,
                                     b"sampler.%d.sample-num", i) < 0)
        if r:
            _fail(f"sampler.{i}")
        c.enable[0] = 1
        uses_fp = 1 if ("f" in s.lower()) else 0
        if hal.hal_export_functf(sample, c, uses_fp, 0, comp_id,
                                 b"sampler.%d", i) < 0:
            _fail(f"sampler.{i}")
    hal.hal_ready(comp_id)


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
