import hal

c = hal.component("reader")
s = hal.stream(c, hal.sampler_base, "sfb")
print(s, s.element_types, s.maxdepth, s.readable, s.writable)
while s.readable:
    print(s.read(), "sample", s.sampleno)
print(s.read(), "underruns", s.num_underruns, "writable", s.writable)
