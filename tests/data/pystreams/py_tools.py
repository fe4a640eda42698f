# Python makes the FIFOs of a sampler and of a streamer channel: halsampler
# reads the one, halstreamer fills the other
import time

import hal

c = hal.component("pytools")
c.newpin("done", hal.HAL_BIT, hal.HAL_IN)
out = hal.stream(c, hal.sampler_base + 1, 6, "fsb")
inp = hal.stream(c, hal.streamer_base + 2, 8, "us")
for k in range(4):
    out.write((k * 0.5 - 1, -k, k % 2))
c.ready()
while not c["done"]:
    time.sleep(0.01)
print("sampler.1:", out.readable, out.num_overruns, out.num_underruns)
while True:
    rec = inp.read()
    if rec is None:
        break
    print("streamer.2:", inp.sampleno, rec)
print("underruns", inp.num_underruns, "overruns", inp.num_overruns)
