#!/usr/bin/env python3
"""Jog in manual mode, every form of command.jog(): a joint by an
increment and continuously (teleop off), then an axis by an increment
and continuously (teleop on), each continuous jog ended by JOG_STOP."""
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


def still():
    return s.inpos and all(abs(j["velocity"]) < 1e-9
                           for j in s.joint[:s.joints])


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
    wait_for(lambda: s.homed.count(1) == s.joints and still(), "homing")
    c.mode(linuxcnc.MODE_MDI)
    done("mdi mode")
    c.mdi("G0 X50 Y50 Z-20")
    done("move to the start", 60)
    c.mode(linuxcnc.MODE_MANUAL)
    done("manual mode")

    # joint jogs: teleop off
    c.teleop_enable(0)
    done("teleop off")
    wait_for(lambda: s.motion_mode == linuxcnc.TRAJ_MODE_FREE, "free mode")
    start = s.joint_position[0]
    c.jog(linuxcnc.JOG_INCREMENT, True, 0, 10.0, 5.0)
    done("joint increment")
    wait_for(lambda: abs(s.joint_position[0] - start - 5.0) < 1e-6
             and still(), "the joint increment")
    print("joint 0 moved by:", round(s.joint_position[0] - start, 4))
    start = s.joint_position[1]
    c.jog(linuxcnc.JOG_CONTINUOUS, True, 1, -10.0)
    done("joint continuous")
    wait_for(lambda: s.joint_position[1] < start - 1.0, "joint 1 to move")
    c.jog(linuxcnc.JOG_STOP, True, 1)
    done("joint stop")
    wait_for(still, "joint 1 to stop")
    print("joint 1 went down and stopped:", s.joint_position[1] < start - 1.0)

    # axis jogs: teleop on
    c.teleop_enable(1)
    done("teleop on")
    wait_for(lambda: s.motion_mode == linuxcnc.TRAJ_MODE_TELEOP,
             "teleop mode")
    start = s.position[2]
    c.jog(linuxcnc.JOG_INCREMENT, False, 2, 10.0, 3.0)
    done("axis increment")
    wait_for(lambda: abs(s.position[2] - start - 3.0) < 1e-6 and still(),
             "the Z increment")
    print("Z moved by:", round(s.position[2] - start, 4))
    start = s.position[0]
    c.jog(linuxcnc.JOG_CONTINUOUS, False, 0, 10.0)
    done("axis continuous")
    wait_for(lambda: s.position[0] > start + 1.0, "X to move")
    c.jog(linuxcnc.JOG_STOP, False, 0)
    done("axis stop")
    wait_for(still, "X to stop")
    print("X went up and stopped:", s.position[0] > start + 1.0)
    here = s.position[0]
    c.jog(linuxcnc.JOG_INCREMENT, False, 0, -10.0, 2.0)     # negative speed
    done("axis increment back")
    wait_for(lambda: abs(s.position[0] - here + 2.0) < 1e-6 and still(),
             "the X increment")
    print("X moved by:", round(s.position[0] - here, 4))
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: joint 0 moved by: 5.0
# expect: joint 1 went down and stopped: True
# expect: Z moved by: 3.0
# expect: X went up and stopped: True
# expect: X moved by: -2.0
