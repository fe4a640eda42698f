#!/usr/bin/env python3
"""A userspace scaler, written as for LinuxCNC: out = in * gain + offset."""

import time

import hal

h = hal.component("scale")
h.newpin("in", hal.HAL_FLOAT, hal.HAL_IN)
h.newpin("out", hal.HAL_FLOAT, hal.HAL_OUT)
h.newparam("gain", hal.HAL_FLOAT, hal.HAL_RW)
h.newparam("offset", hal.HAL_FLOAT, hal.HAL_RW)
h["gain"] = 1.0
h.ready()

try:
    while True:
        h["out"] = h["in"] * h["gain"] + h["offset"]
        time.sleep(0.005)
except KeyboardInterrupt:
    raise SystemExit  # noqa: B904 - the usual LinuxCNC idiom
