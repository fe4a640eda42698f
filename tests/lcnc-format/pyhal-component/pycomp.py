#!/usr/bin/env python3
# a userspace component written with LinuxCNC's hal module: it doubles
# its input and counts how often its input changed, until told to stop
import time

import hal

c = hal.component("pycomp")
c.newpin("in", hal.HAL_FLOAT, hal.HAL_IN)
c.newpin("out", hal.HAL_FLOAT, hal.HAL_OUT)
c.newpin("changes", hal.HAL_S32, hal.HAL_OUT)
c.newpin("enable", hal.HAL_BIT, hal.HAL_IN)
c.newpin("done", hal.HAL_BIT, hal.HAL_IO)
c.newparam("gain", hal.HAL_FLOAT, hal.HAL_RW)
c["gain"] = 2.0
c["out"] = -1.0
c.ready()
last = c["in"]
try:
    while not c["done"]:
        if c["in"] != last:
            last = c["in"]
            c["changes"] += 1
        c["out"] = c["in"] * c["gain"] if c["enable"] else 0.0
        time.sleep(0.005)
except KeyboardInterrupt:
    pass
