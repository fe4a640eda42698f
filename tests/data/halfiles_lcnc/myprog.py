import time

import hal
import linuxcnc  # noqa: F401  (importable too)

h = hal.component("myprog")
h.newpin("in", hal.HAL_FLOAT, hal.HAL_IN)
h.newpin("out", hal.HAL_S32, hal.HAL_OUT)
h.newparam("gain", hal.HAL_FLOAT, hal.HAL_RW)
h["out"] = 42
h.ready()
try:
    while True:        # until halrun ends it
        time.sleep(0.1)
except KeyboardInterrupt:   # the reference's halrun sends SIGINT
    raise SystemExit(0) from None
