#!/usr/bin/env python3
"""wait_complete() and the command status: nothing to wait for, a wait
that runs out (-1) while a slow MDI move goes on, the status's state
RCS_EXEC meanwhile, then abort, and a command's completion seen by a
second command object through the status echo."""
import sys
import time

import linuxcnc

s = linuxcnc.stat()
c = linuxcnc.command()


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


print("nothing sent yet:", c.serial, c.wait_complete() == linuxcnc.RCS_DONE)
try:
    c.state(linuxcnc.STATE_ESTOP_RESET)
    done("E-stop reset")
    c.state(linuxcnc.STATE_ON)
    done("machine on")
    c.mode(linuxcnc.MODE_MANUAL)
    done("manual mode")
    s.poll()
    if s.homed.count(1) != s.joints:
        c.home(-1)
        done("home")
    wait_for(lambda: s.homed.count(1) == s.joints and s.inpos, "homing")
    c.mode(linuxcnc.MODE_MDI)
    done("mdi mode")
    c.mdi("G0 X0 Y0 Z-10")
    done("start position", 60)

    c.mdi("G1 X100 F300")               # 20 s at 5 mm/s
    print("short wait runs out:", c.wait_complete(0.2))
    wait_for(lambda: s.position[0] > 0.5, "the move to start")
    print("still executing:", s.state == linuxcnc.RCS_EXEC,
          s.echo_serial_number == c.serial)
    print("interp busy:", s.interp_state != linuxcnc.INTERP_IDLE)

    other = linuxcnc.command()          # a second client
    other.abort()
    print("abort from another client:",
          other.wait_complete() == linuxcnc.RCS_DONE)
    print("the mdi ends:", c.wait_complete(10) == linuxcnc.RCS_ERROR)
    wait_for(lambda: s.interp_state == linuxcnc.INTERP_IDLE and s.inpos,
             "the stop")
    print("stopped short:", s.position[0] < 100.0)
    print("wait again gives the same:",
          c.wait_complete(0.1) == linuxcnc.RCS_ERROR)
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: nothing sent yet: 0 True
# expect: short wait runs out: -1
# expect: still executing: True True
# expect: interp busy: True
# expect: abort from another client: True
# expect: the mdi ends: True
# expect: stopped short: True
# expect: wait again gives the same: True
