#!/usr/bin/env python3
"""A userspace bit debouncer, written as for LinuxCNC.

``out`` takes the value of ``in`` once ``in`` has kept it for ``samples``
consecutive polls; ``changes`` counts the changes of ``out``.  Pins and
params are read and written as attributes (``h.out``).
"""

import time

import hal

h = hal.component("debounce", "db")
h.newpin("in", hal.HAL_BIT, hal.HAL_IN)
h.newpin("out", hal.HAL_BIT, hal.HAL_OUT)
h.newpin("changes", hal.HAL_U32, hal.HAL_OUT)
h.newparam("samples", hal.HAL_S32, hal.HAL_RW)
h.samples = 3
h.ready()

stable = 0
last = False
try:
    while True:
        now = h["in"]
        stable = stable + 1 if now == last else 1
        last = now
        if stable >= h.samples and h.out != now:
            h.changes += 1      # first: a reader that sees out sees it
            h.out = now
        time.sleep(0.002)
except KeyboardInterrupt:
    raise SystemExit  # noqa: B904 - the usual LinuxCNC idiom
