#!/usr/bin/env python3
"""Open a program by a relative path and run it in AUTO mode, reading the
status while it runs (the interpreter state, the line numbers, the
position), until it ends."""
import os
import sys
import time

import linuxcnc

PROGRAM = """\
G21 G90
G0 X0 Y0 Z-10
G1 X30 F2400
G1 Y20
G1 X0
G1 Y0
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


with open("square.ngc", "w") as f:
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
    c.program_open("square.ngc")        # relative to this folder
    done("program open")
    s.poll()
    print("file:", s.file == os.path.abspath("square.ngc"))
    print("idle before the run:", s.interp_state == linuxcnc.INTERP_IDLE)

    c.auto(linuxcnc.AUTO_RUN, 0)
    states, lines, xs = set(), set(), []
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        s.poll()
        states.add(s.interp_state)
        lines.add(s.motion_line)
        xs.append(s.position[0])
        if s.interp_state == linuxcnc.INTERP_IDLE and len(states) > 1:
            break
        time.sleep(0.01)
    else:
        sys.exit("the program did not end")
    print("ran:", linuxcnc.INTERP_IDLE in states and
          bool(states & {linuxcnc.INTERP_READING, linuxcnc.INTERP_WAITING}))
    print("moved in X up to:", round(max(xs), 3))
    print("saw motion lines:", max(lines) >= 3)
    print("run complete:", c.wait_complete(10) == linuxcnc.RCS_DONE)
    s.poll()
    print("back at:", [round(v, 3) for v in s.position[:3]])
    print("mode still auto:", s.task_mode == linuxcnc.MODE_AUTO)
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: file: True
# expect: idle before the run: True
# expect: ran: True
# expect: moved in X up to: 30.0
# expect: saw motion lines: True
# expect: run complete: True
# expect: back at: [0.0, 0.0, -10.0]
# expect: mode still auto: True
