#!/usr/bin/env python3
"""Pause a running program with auto(AUTO_PAUSE), see it stand still,
resume it with auto(AUTO_RESUME), then abort it: the interpreter states
and the task_paused flag on the way."""
import sys
import time

import linuxcnc

PROGRAM = """\
G21 G90
G0 X0 Y0 Z-10
G1 X150 F600
M2
"""

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


with open("long.ngc", "w") as f:
    f.write(PROGRAM)
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
    c.mode(linuxcnc.MODE_AUTO)
    done("auto mode")
    c.program_open("long.ngc")
    done("program open")
    c.auto(linuxcnc.AUTO_RUN, 0)
    wait_for(lambda: s.position[0] > 2.0, "the long move to start")

    c.auto(linuxcnc.AUTO_PAUSE)
    print("pause:", c.wait_complete() == linuxcnc.RCS_DONE)
    wait_for(lambda: s.paused and s.current_vel == 0.0, "the pause")
    print("interp paused:", s.interp_state == linuxcnc.INTERP_PAUSED)
    print("task paused:", s.task_paused)
    here = s.position[0]
    for _ in range(5):                  # it stays where it stopped
        time.sleep(0.02)
        s.poll()
    print("stands still:", s.position[0] == here)

    c.auto(linuxcnc.AUTO_RESUME)
    print("resume:", c.wait_complete() == linuxcnc.RCS_DONE)
    wait_for(lambda: s.position[0] > here + 1.0, "the move to go on")
    print("moving again:", not s.paused,
          s.interp_state != linuxcnc.INTERP_PAUSED)

    c.abort()
    print("abort:", c.wait_complete() == linuxcnc.RCS_DONE)
    wait_for(lambda: s.interp_state == linuxcnc.INTERP_IDLE and s.inpos,
             "the abort")
    print("idle after abort:", s.position[0] < 150.0)
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: pause: True
# expect: interp paused: True
# expect: task paused: 1
# expect: stands still: True
# expect: resume: True
# expect: moving again: True True
# expect: abort: True
# expect: idle after abort: True
