import hal

c = hal.component("consumer")
s = hal.stream(c, 0x1234, "fu")
print("consumer:", s, s.element_types, s.maxdepth, "overruns",
      s.num_overruns)
while True:
    rec = s.read()
    if rec is None:
        break
    print("consumer:", s.sampleno, rec)
print("consumer: underruns", s.num_underruns, s.read(), s.num_underruns)
