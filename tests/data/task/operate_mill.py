#!/usr/bin/env python3
"""Operate a running machine the way a LinuxCNC user interface does,
through the reference's documented Python interface only (no halsdk
import): reset the E-stop, turn on, home, MDI, open and run a program
while reading the status, read the error channel, E-stop.

    python3 operate_mill.py PROGRAM.ngc
"""
import sys
import time

import linuxcnc

s = linuxcnc.stat()
c = linuxcnc.command()
e = linuxcnc.error_channel()


def wait_for(cond, what, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        s.poll()
        if cond():
            return
        time.sleep(0.02)
    sys.exit("timed out waiting for " + what)


def done(what, timeout=5.0):
    r = c.wait_complete(timeout)
    if r != linuxcnc.RCS_DONE:
        sys.exit(f"{what}: wait_complete() gave {r}")


s.poll()
print("start in estop:", s.task_state == linuxcnc.STATE_ESTOP)
c.state(linuxcnc.STATE_ESTOP_RESET)
done("estop reset")
c.state(linuxcnc.STATE_ON)
done("machine on")
c.mode(linuxcnc.MODE_MANUAL)
done("manual mode")
c.home(-1)
done("home")
wait_for(lambda: all(s.homed[:s.joints]), "homing", 120)
print("homed:", s.homed[:s.joints])

c.mode(linuxcnc.MODE_MDI)
done("mdi mode")
c.mdi("G21 G90 G0 X100 Y50 Z-10")
done("mdi", 60)
s.poll()
print("after mdi:", tuple(round(v, 3) for v in s.position[:3]))

c.mode(linuxcnc.MODE_AUTO)
done("auto mode")
c.program_open(sys.argv[1])
done("program open")
c.auto(linuxcnc.AUTO_RUN, 0)
wait_for(lambda: s.interp_state != linuxcnc.INTERP_IDLE, "the start", 10)
lines = set()
deadline = time.monotonic() + 120
while time.monotonic() < deadline:
    s.poll()
    lines.add(s.motion_line)
    if s.interp_state == linuxcnc.INTERP_IDLE:
        break
    time.sleep(0.01)
done("program run", 10)
print("file:", s.file.endswith(".ngc"))
print("lines seen:", sorted(n for n in lines if n > 0))
s.poll()
print("after program:", tuple(round(v, 3) for v in s.position[:3]))

# MDI in AUTO mode is refused, with the reason on the error channel
c.mdi("G0 X0")
print("mdi in auto:", c.wait_complete() == linuxcnc.RCS_ERROR)
messages = []
while True:
    m = e.poll()
    if not m:
        break
    messages.append(m)
print("refusal reported:", any(kind == linuxcnc.OPERATOR_ERROR and
                               "MDI" in text for kind, text in messages))

c.state(linuxcnc.STATE_ESTOP)
done("estop")
s.poll()
print("end in estop:", s.task_state == linuxcnc.STATE_ESTOP,
      "enabled:", s.enabled)
