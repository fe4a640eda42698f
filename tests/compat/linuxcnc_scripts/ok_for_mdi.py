#!/usr/bin/env python3
"""The manual's "preparing to send commands" pattern: send an MDI command
only when the status says it is fine (not in E-stop, enabled, every joint
homed, the interpreter idle)."""
import sys
import time

import linuxcnc

s = linuxcnc.stat()
c = linuxcnc.command()


def ok_for_mdi():
    s.poll()
    return not s.estop and s.enabled and (s.homed.count(1) == s.joints) \
        and (s.interp_state == linuxcnc.INTERP_IDLE)


def done(what, timeout=5.0):
    if c.wait_complete(timeout) != linuxcnc.RCS_DONE:
        sys.exit(what + " failed")


def wait_for(cond, what, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        s.poll()
        if cond():
            return
        time.sleep(0.02)
    sys.exit("timed out waiting for " + what)


try:
    print("ok in E-stop:", ok_for_mdi())
    c.state(linuxcnc.STATE_ESTOP_RESET)
    done("E-stop reset")
    c.state(linuxcnc.STATE_ON)
    done("machine on")
    c.mode(linuxcnc.MODE_MANUAL)
    done("manual mode")
    c.unhome(-1)
    done("unhome")
    print("ok when not homed:", ok_for_mdi())
    c.home(-1)
    done("home")
    wait_for(lambda: s.homed.count(1) == s.joints, "homing")
    wait_for(lambda: s.inpos, "the joints to stop")
    print("ok when homed:", ok_for_mdi())
    if ok_for_mdi():
        c.mode(linuxcnc.MODE_MDI)
        c.wait_complete()       # wait until mode switch executed
        c.mdi("G0 X10 Y20 Z-30")
        print("mdi done:", c.wait_complete(60) == linuxcnc.RCS_DONE)
        s.poll()
        print("position:", [round(v, 3) for v in s.position[:3]])
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: ok in E-stop: False
# expect: ok when not homed: False
# expect: ok when homed: True
# expect: mdi done: True
# expect: position: [10.0, 20.0, -30.0]
