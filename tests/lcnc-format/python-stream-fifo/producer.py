import time

import hal

c = hal.component("producer")
c.newpin("again", hal.HAL_BIT, hal.HAL_IN)
s = hal.stream(c, 0x1234, 4, "fu")
written = 0
for k in range(6):
    try:
        s.write((k / 4, k * k))
        written += 1
    except OSError:
        pass
print("producer:", s, "wrote", written, "overruns", s.num_overruns)
c.ready()
while not c["again"]:
    time.sleep(0.01)
print("producer: readable", s.readable, "writable", s.writable,
      "underruns", s.num_underruns)
s.write((-1.0, 4294967295))
print("producer: readable", s.readable)
