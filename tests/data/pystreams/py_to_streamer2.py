# attach again with a type check; the FIFO was emptied by the streamer,
# which counts its underruns on its pin only
import hal

c = hal.component("feeder2")
s = hal.stream(c, hal.streamer_base + 0, "fbsu")
print(repr(s), "underruns", s.num_underruns, "overruns", s.num_overruns)
print("readable", s.readable, "writable", s.writable)
