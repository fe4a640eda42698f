# streamer: copy records from a stream to HAL pins once per thread cycle
# (or per clock edge); halstreamer fills the stream from a text file.
#
#     loadrt streamer depth=D0[,D1...] cfg=CFG0[,CFG1...]
#
# One channel per cfg string, one output pin per letter (f float, b bit,
# s s32, u u32, and beyond the reference l s64, k u64; up to 256 pins).
# Channel N: pins streamer.N.pin.M (out), streamer.N.curr-depth (out),
# streamer.N.empty (out), streamer.N.enable (in), streamer.N.underruns
# (io), streamer.N.clock (in), streamer.N.clock-mode (in: 0 every cycle,
# 1 falling edge, 2 rising edge, 3 both edges of clock), function
# streamer.N and stream "streamer.N" of D records.

from halsdk cimport hal

from ._channels import MODPARAMS, channels

hal.import_halsdk()

cdef struct channel_t:
    hal.hal_bit_t *enable
    hal.hal_bit_t *empty
    hal.hal_bit_t *clock
    hal.hal_s32_t *clock_mode
    hal.hal_s32_t *curr_depth
    hal.hal_s32_t *underruns
    hal.halsdk_stream_t stream
    int n
    int last_clock
    unsigned char types[256]
    void *pins[256]
    hal.halsdk_value_t rec[256]


cdef void play(void *arg, long period) noexcept nogil:
    cdef channel_t *c = <channel_t *>arg
    cdef int i, t, clk, tick, mode, depth
    cdef void *p
    # as the reference: curr-depth and empty follow the FIFO every cycle,
    # enabled or not, and an empty FIFO at a tick counts on the underruns
    # pin only (the stream's own underrun count is its reader's)
    depth = hal.halsdk_stream_depth(c.stream)
    c.curr_depth[0] = depth if depth > 0 else 0
    c.empty[0] = depth <= 0
    if not c.enable[0]:
        return
    clk = 1 if c.clock[0] else 0
    mode = c.clock_mode[0]
    if mode == 1:
        tick = c.last_clock and not clk
    elif mode == 2:
        tick = clk and not c.last_clock
    elif mode == 3:
        tick = clk != c.last_clock
    else:
        tick = 1
    c.last_clock = clk
    if not tick:
        return
    if depth <= 0 or hal.halsdk_stream_read(c.stream, c.rec, NULL) < 0:
        c.underruns[0] += 1
        return
    depth = hal.halsdk_stream_depth(c.stream)
    c.curr_depth[0] = depth if depth > 0 else 0
    c.empty[0] = depth <= 0
    for i in range(c.n):
        p = c.pins[i]
        t = c.types[i]
        if t == hal.HAL_FLOAT:
            (<hal.hal_float_t *>p)[0] = c.rec[i].f
        elif t == hal.HAL_BIT:
            (<hal.hal_bit_t *>p)[0] = c.rec[i].b != 0
        elif t == hal.HAL_S32:
            (<hal.hal_s32_t *>p)[0] = c.rec[i].s
        elif t == hal.HAL_U32:
            (<hal.hal_u32_t *>p)[0] = c.rec[i].u
        elif t == hal.HAL_S64:
            (<hal.hal_s64_t *>p)[0] = c.rec[i].ls
        else:
            (<hal.hal_u64_t *>p)[0] = c.rec[i].lu


modparams = dict(MODPARAMS)

cdef int comp_id = -1


def _fail(what):
    msg = hal.halsdk_last_error().decode("utf-8", "replace")
    raise RuntimeError(f"{what}: {msg}" if msg else what)


def setup(depth=None, cfg=None):
    global comp_id
    cdef channel_t *c
    cdef int i, m, r
    chans = channels("streamer", depth, cfg)
    comp_id = hal.hal_init(b"streamer")
    if comp_id < 0:
        _fail("streamer: hal_init failed")
    for i, (s, types, d) in enumerate(chans):
        c = <channel_t *>hal.hal_malloc(sizeof(channel_t))
        if c == NULL:
            raise MemoryError(f"streamer.{i}: hal_malloc failed")
        c.n = len(s)
        c.stream = hal.halsdk_stream_create(f"streamer.{i}".encode(),
                                            comp_id, d, s.encode())
        if c.stream < 0:
            _fail(f"streamer.{i}")
        for m in range(len(types)):
            c.types[m] = types[m]
            name = f"streamer.{i}.pin.{m}".encode()
            if hal.hal_pin_new(name, <hal.hal_type_t>c.types[m], hal.HAL_OUT,
                               &c.pins[m], comp_id) < 0:
                _fail(f"streamer.{i}")
        r = (hal.hal_pin_s32_newf(hal.HAL_OUT, &c.curr_depth, comp_id,
                                  b"streamer.%d.curr-depth", i) < 0
             or hal.hal_pin_bit_newf(hal.HAL_OUT, &c.empty, comp_id,
                                     b"streamer.%d.empty", i) < 0
             or hal.hal_pin_bit_newf(hal.HAL_IN, &c.enable, comp_id,
                                     b"streamer.%d.enable", i) < 0
             or hal.hal_pin_s32_newf(hal.HAL_IO, &c.underruns, comp_id,
                                     b"streamer.%d.underruns", i) < 0
             or hal.hal_pin_bit_newf(hal.HAL_IN, &c.clock, comp_id,
                                     b"streamer.%d.clock", i) < 0
             or hal.hal_pin_s32_newf(hal.HAL_IN, &c.clock_mode, comp_id,
                                     b"streamer.%d.clock-mode", i) < 0)
        if r:
            _fail(f"streamer.{i}")
        c.enable[0] = 1
        c.empty[0] = 1
        uses_fp = 1 if ("f" in s.lower()) else 0
        if hal.hal_export_functf(play, c, uses_fp, 0, comp_id,
                                 b"streamer.%d", i) < 0:
            _fail(f"streamer.{i}")
    hal.hal_ready(comp_id)


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
