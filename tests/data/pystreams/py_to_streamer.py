# fill the FIFO of "loadrt streamer" from Python, as halstreamer would
import hal

c = hal.component("feeder")
s = hal.stream(c, hal.streamer_base)
print(repr(s), s.element_types, s.maxdepth, s.depth)
print("readable", s.readable, "writable", s.writable)
rows = [(1.5, True, -3, 7), (2.25, False, 4, 8), (-0.5, 1, 2147483647, 4294967295),
        (4.0, 0, 5, 6), (5.0, 1, 6, 7)]
for row in rows:
    try:
        s.write(row)
        print("wrote", row, "depth", s.depth)
    except OSError as e:
        print("full:", e.errno, e.strerror, "overruns", s.num_overruns)
print("readable", s.readable, "writable", s.writable)
print("overruns", s.num_overruns, "underruns", s.num_underruns)
c.ready()
