#!/usr/bin/env python3
"""A userspace edge counter with s32/u32 pins, written as for LinuxCNC.

Each rising edge of ``up`` adds ``step`` to ``count`` (s32, may go
negative); ``total`` (u32) counts every edge and survives ``reset``; ``state``
shows the level of ``up`` as last seen.  The pins are used through the
Pin/Param objects that newpin/newparam return.
"""

import time

import hal

h = hal.component("counter")
up = h.newpin("up", hal.HAL_BIT, hal.HAL_IN)
reset = h.newpin("reset", hal.HAL_BIT, hal.HAL_IN)
count = h.newpin("count", hal.HAL_S32, hal.HAL_OUT)
total = h.newpin("total", hal.HAL_U32, hal.HAL_OUT)
state = h.newpin("state", hal.HAL_BIT, hal.HAL_OUT)
step = h.newparam("step", hal.HAL_S32, hal.HAL_RW)
step.value = 1
edges = h.getpin("total")        # the same pin, looked up again
h.ready()

previous = False
try:
    while True:
        if reset.get():
            count.set(0)
        now = up.value
        if now and not previous:
            count.value = count.value + step.get()
            edges.set(edges.get() + 1)
        previous = now
        state.value = now
        time.sleep(0.002)
except KeyboardInterrupt:
    raise SystemExit  # noqa: B904 - the usual LinuxCNC idiom
