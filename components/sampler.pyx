# sampler: copy HAL pins into a stream once per thread cycle, for
# halsampler (or Python: halsdk._core.stream_attach("sampler.N")).
#
#     loadrt sampler depth=D0[,D1...] cfg=CFG0[,CFG1...]
#
# One channel per cfg string, one input pin per letter (f float, b bit,
# s s32, u u32, and beyond the reference l s64, k u64; up to 256 pins).
# Channel N: pins sampler.N.pin.M, sampler.N.enable (in), sampler.N.full,
# sampler.N.curr-depth (out), sampler.N.overruns, sampler.N.sample-num (io),
# function sampler.N and stream "sampler.N" of D records.

from halsdk cimport hal

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


_LETTERS = {"f": hal.HAL_FLOAT, "b": hal.HAL_BIT, "s": hal.HAL_S32,
            "u": hal.HAL_U32, "l": hal.HAL_S64, "k": hal.HAL_U64}

modparams = {
    "depth": ([int], None, "FIFO depth (records) of each channel"),
    "cfg": ([str], None, "pin types of each channel: letters f b s u l k"),
}

cdef int comp_id = -1


def _fail(what):
    msg = hal.halsdk_last_error().decode("utf-8", "replace")
    raise RuntimeError(f"{what}: {msg}" if msg else what)


def setup(depth=None, cfg=None):
    global comp_id
    cdef channel_t *c
    cdef int i, m, r
    cfgs = [s for s in (cfg or []) if s != ""]
    depths = list(depth or [])
    if not cfgs:
        raise ValueError("sampler: no channels specified (give "
                         "cfg=STRING[,STRING...])")
    for i, s in enumerate(cfgs):
        if i >= len(depths):
            raise ValueError(f"sampler.{i}: no depth given for cfg '{s}' "
                             "(give depth=D1[,D2...], one per cfg string)")
        if depths[i] < 1:
            raise ValueError(f"sampler.{i}: depth {depths[i]} is not a "
                             "positive number of samples")
        if len(s) > 256:
            raise ValueError(f"sampler.{i}: cfg string has {len(s)} "
                             "letters; at most 256")
        for ch in s:
            if ch.lower() not in _LETTERS:
                raise ValueError(
                    f"sampler.{i}: unknown type '{ch}' in cfg string "
                    f"'{s}' (letters: f float, b bit, s s32, u u32, "
                    "l s64, k u64)")
    comp_id = hal.hal_init(b"sampler")
    if comp_id < 0:
        _fail("sampler: hal_init failed")
    for i, s in enumerate(cfgs):
        c = <channel_t *>hal.hal_malloc(sizeof(channel_t))
        if c == NULL:
            raise MemoryError(f"sampler.{i}: hal_malloc failed")
        c.n = len(s)
        c.maxdepth = depths[i]
        c.stream = hal.halsdk_stream_create(f"sampler.{i}".encode(), comp_id,
                                            depths[i], s.encode())
        if c.stream < 0:
            _fail(f"sampler.{i}")
        for m, ch in enumerate(s):
            c.types[m] = _LETTERS[ch.lower()]
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
