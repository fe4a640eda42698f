#!/usr/bin/env python3
"""A session through the command channel: a refused command, E-stop
reset, machine on, homing, MDI lines with wait_complete(), the serial
numbers and their echo in the status, E-stop."""
import sys
import time

import linuxcnc

s = linuxcnc.stat()
c = linuxcnc.command()


def wait_for(cond, what, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        s.poll()
        if cond():
            return
        time.sleep(0.02)
    sys.exit("timed out waiting for " + what)


try:
    print("serial before any command:", c.serial)
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()
    c.mdi("G0 X1")                      # refused: the machine is in E-stop
    print("serial after two commands:", c.serial)
    print("mdi in E-stop:", c.wait_complete() == linuxcnc.RCS_ERROR)
    s.poll()
    print("echoed:", s.echo_serial_number == c.serial,
          s.state == linuxcnc.RCS_ERROR)

    c.state(linuxcnc.STATE_ESTOP_RESET)
    print("reset:", c.wait_complete() == linuxcnc.RCS_DONE)
    s.poll()
    print("task state reset:", s.task_state == linuxcnc.STATE_ESTOP_RESET)
    c.state(linuxcnc.STATE_ON)
    print("on:", c.wait_complete() == linuxcnc.RCS_DONE)
    s.poll()
    print("task state on:", s.task_state == linuxcnc.STATE_ON,
          "estop:", s.estop, "enabled:", s.enabled)

    c.mode(linuxcnc.MODE_MANUAL)
    c.wait_complete()
    if s.homed.count(1) != s.joints:
        c.home(-1)
        print("home sent:", c.wait_complete() == linuxcnc.RCS_DONE)
    else:
        print("home sent:", True)
    wait_for(lambda: s.homed.count(1) == s.joints and s.inpos, "homing")
    print("homed:", s.homed[:s.joints])

    c.mode(linuxcnc.MODE_MDI)
    c.wait_complete()
    s.poll()
    print("mode mdi:", s.task_mode == linuxcnc.MODE_MDI)
    for line in ("G21 G90", "G0 X20 Y10 Z-5", "G1 X25 Y15 F1200"):
        c.mdi(line)
        result = c.wait_complete(60)
        print("mdi", repr(line), "done:", result == linuxcnc.RCS_DONE)
    s.poll()
    print("position:", [round(v, 3) for v in s.position[:3]])
    print("interp idle:", s.interp_state == linuxcnc.INTERP_IDLE)
    print("echo is the last serial:", s.echo_serial_number == c.serial)
    print("last command:", s.command)

    c.mdi("G0 X500")                    # beyond the X limit: refused
    print("mdi beyond the limit:", c.wait_complete(10) == linuxcnc.RCS_ERROR)
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()
s.poll()
print("final E-stop:", s.task_state == linuxcnc.STATE_ESTOP)

# expect: serial before any command: 0
# expect: serial after two commands: 2
# expect: mdi in E-stop: True
# expect: echoed: True True
# expect: reset: True
# expect: task state reset: True
# expect: on: True
# expect: task state on: True estop: 0 enabled: True
# expect: homed: (1, 1, 1)
# expect: mode mdi: True
# expect: mdi 'G21 G90' done: True
# expect: mdi 'G0 X20 Y10 Z-5' done: True
# expect: mdi 'G1 X25 Y15 F1200' done: True
# expect: position: [25.0, 15.0, -5.0]
# expect: interp idle: True
# expect: echo is the last serial: True
# expect: last command: G1 X25 Y15 F1200
# expect: mdi beyond the limit: True
# expect: final E-stop: True
