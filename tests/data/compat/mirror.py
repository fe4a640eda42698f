#!/usr/bin/env python3
"""A userspace component that wires itself, written as for LinuxCNC.

Usage: mirror.py NAME.  Makes pins NAME.in (s32) and NAME.out (s32),
creates the signal NAME-loop and connects NAME.out to it with the module
functions, and copies in to out.  It also reports what the module
functions say, on stdout, for the test to check.
"""

import sys
import time

import hal

name = sys.argv[1]
h = hal.component(name)
h.newpin("in", hal.HAL_S32, hal.HAL_IN)
h.newpin("out", hal.HAL_S32, hal.HAL_OUT)
h.setprefix(name + ".extra")
h.newpin("seen", hal.HAL_U32, hal.HAL_OUT)
failed = hal.new_sig(name + "-loop", hal.HAL_S32)
failed |= hal.connect(name + ".out", name + "-loop")
h.ready()
print("wired", failed, hal.component_is_ready(name),
      hal.pin_has_writer(name + ".out"), flush=True)

try:
    while True:
        if h["out"] != h["in"]:
            h["out"] = h["in"]
            h["seen"] += 1
        time.sleep(0.002)
except KeyboardInterrupt:
    print("bye", flush=True)
    raise SystemExit  # noqa: B904 - the usual LinuxCNC idiom
