"""A userspace component in its own process, for the multi-process tests.

Usage: ``echo_comp.py NAME [--ignore-term]``

Creates component NAME in the instance of ``$HALSDK_INSTANCE`` with pins
``NAME.in`` (float in), ``NAME.out`` (float out), ``NAME.pid`` (s32 out,
set to this process's pid) and ``NAME.beat`` (s32 out, counts loops);
marks it ready, prints ``ready`` and then copies ``in`` to ``out`` every
millisecond until killed.  With ``--ignore-term`` SIGTERM is ignored.
"""

import os
import signal
import sys
import time

import halsdk


def main() -> int:
    name = sys.argv[1]
    if "--ignore-term" in sys.argv[2:]:
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    comp = halsdk.component(name)
    comp.newpin("in", "float", "in")
    comp.newpin("out", "float", "out")
    comp.newpin("pid", "s32", "out")
    comp.newpin("beat", "s32", "out")
    comp["pid"] = os.getpid()
    comp.ready()
    print("ready", flush=True)
    beat = 0
    while True:
        comp["out"] = comp["in"]
        beat = (beat + 1) % (1 << 31)
        comp["beat"] = beat
        time.sleep(0.001)


if __name__ == "__main__":
    sys.exit(main())
