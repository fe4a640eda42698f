# the errors of hal.stream and hal.shm that scripts meet
import struct

import hal


def attempt(label, f):
    try:
        r = f()
    except Exception as e:
        if label.startswith("*"):       # the words differ: the type only
            print(label, "->", type(e).__name__)
        else:
            print(label, "->", type(e).__name__, e)
    else:
        print(label, "->", r)
    return None


c = hal.component("errs")
s = hal.stream(c, 0x1237, 3, "fbsu")
attempt("attach, cfg prefix", lambda: hal.stream(c, 0x1237, "FB"))
attempt("attach, cfg ok", lambda: hal.stream(c, 0x1237, "fbsu"))
attempt("created", lambda: (repr(s), s.element_types, s.maxdepth))
attempt("write a list", lambda: s.write([1.0, 1, 1, 1]))
attempt("write None", lambda: s.write(None))
attempt("write nothing", lambda: s.write())
attempt("*write short", lambda: type(s.write((1.0, 1, 1))))
attempt("write a word as float", lambda: s.write(("x", 1, 1, 1)))
attempt("write u32 -1", lambda: s.write((1.0, 1, 1, -1)))
attempt("write s32 2**31", lambda: s.write((1.0, 1, 2 ** 31, 1)))
attempt("write s32 nan", lambda: s.write((1.0, 1, float("nan"), 1)))
attempt("read with an argument", lambda: s.read(1))
attempt("read empty", lambda: s.read())
attempt("write 1", lambda: s.write(("2.5", [], 3.9, 4.2)))
attempt("write 2", lambda: s.write((True, "x", "-5", True)))
attempt("write 3, full", lambda: s.write((3.0, 1, 1, 1)))
attempt("write 4, full", lambda: s.write((3.0, 1, 1, 1)))
attempt("counts", lambda: (s.num_overruns, s.num_underruns, s.readable, s.writable))
attempt("read 1", lambda: (s.read(), s.sampleno))
attempt("read 2", lambda: (s.read(), s.sampleno))
attempt("read 3", lambda: (s.read(), s.sampleno))
attempt("counts", lambda: (s.num_overruns, s.num_underruns, s.readable, s.writable))
attempt("set sampleno", lambda: setattr(s, "sampleno", 3))
m = hal.shm(c, 0x4321, 16)
attempt("shm", lambda: repr(m).split(" id=")[0])
buf = m.getbuffer()
attempt("buffer", lambda: (buf.format, buf.nbytes, buf.readonly))
attempt("cast", lambda: buf.cast("I").tolist())
struct.pack_into("<I", buf, 4, 0x01020304)
buf.cast("B")[0] = 7
attempt("bytes", lambda: bytes(buf))
m2 = hal.shm(c, 0x4321, 16)
attempt("same key", lambda: repr(m2).split(" id=")[0])
attempt("shm size 0", lambda: hal.shm(c, 0x4322, 0))
attempt("shm two arguments", lambda: hal.shm(c, 0x4322))
attempt("shm not a component", lambda: hal.shm(None, 0x4322, 8))
attempt("setsize word", lambda: m.setsize("x"))
attempt("attach, no such key", lambda: hal.stream(c, 0x1234))
attempt("attach, no such key, cfg", lambda: hal.stream(c, 0x1234, "f"))
attempt("attach, no sampler", lambda: hal.stream(c, hal.sampler_base + 3))
attempt("depth 0", lambda: hal.stream(c, 0x1235, 0, "f"))
attempt("not a component", lambda: hal.stream(1, 0x1236, 4, "f"))
attempt("one argument", lambda: hal.stream(c))
attempt("attach, cfg mismatch", lambda: hal.stream(c, 0x1237, "ff"))
attempt("attach, cfg too long", lambda: hal.stream(c, 0x1237, "fbsuf"))
