import hal


def attempt(label, f):
    try:
        r = f()
    except Exception as e:
        print(label, "->", type(e).__name__, e)
    else:
        print(label, "->", r)


c = hal.component("errors")
s5 = hal.stream(c, 5, 2, "bb")
attempt("stream 5", lambda: s5)
attempt("depth 0", lambda: hal.stream(c, 6, 0, "f"))
attempt("no component", lambda: hal.stream("c", 6, 4, "f"))
attempt("missing key", lambda: hal.stream(c, 7))
attempt("missing streamer", lambda: hal.stream(c, hal.streamer_base))
attempt("missing sampler", lambda: hal.stream(c, hal.sampler_base + 2))
s = hal.stream(c, 5)
attempt("attached", lambda: (s, s.element_types, s.maxdepth))
attempt("write list", lambda: s.write([1, 1]))
attempt("write", lambda: s.write((1, 0)))
attempt("write, full", lambda: s.write((1, 0)))
attempt("read", lambda: s.read())
attempt("read, empty", lambda: s.read())
attempt("counts", lambda: (s.num_overruns, s.num_underruns))
attempt("read(1)", lambda: s.read(1))
attempt("attach, cfg mismatch", lambda: hal.stream(c, 5, "f"))
