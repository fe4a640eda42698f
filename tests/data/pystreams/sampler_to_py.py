import hal

c = hal.component("reader")
s = hal.stream(c, hal.sampler_base, "fbsu")
print(repr(s), s.element_types, "maxdepth", s.maxdepth)
print("readable", s.readable, "writable", s.writable, "sampleno", s.sampleno)
print("overrun", s.num_overruns > 0)
before = s.num_underruns
while True:
    rec = s.read()
    if rec is None:
        break
    print(s.sampleno, rec)
print("readable", s.readable, "writable", s.writable, "depth", s.depth)
print("underruns", s.num_underruns - before)
print(s.read(), s.read(), "underruns", s.num_underruns - before)
