#!/usr/bin/env python3
"""Overrides, spindle and coolant: feedrate, rapidrate, maxvel, the
spindle in every direction with its override and brake, flood and mist,
each checked in the status."""
import sys

import linuxcnc

s = linuxcnc.stat()
c = linuxcnc.command()


def done(what, timeout=5.0):
    if c.wait_complete(timeout) != linuxcnc.RCS_DONE:
        sys.exit(what + " failed")
    s.poll()


try:
    c.state(linuxcnc.STATE_ESTOP_RESET)
    done("E-stop reset")
    c.state(linuxcnc.STATE_ON)
    done("machine on")
    c.mode(linuxcnc.MODE_MANUAL)
    done("manual mode")

    c.feedrate(1.5)
    done("feedrate")
    print("feedrate:", s.feedrate)
    c.rapidrate(0.5)
    done("rapidrate")
    print("rapidrate:", s.rapidrate)
    c.maxvel(30.0)
    done("maxvel")
    print("max velocity:", s.max_velocity)
    c.set_feed_override(0)
    done("feed override off")
    print("feed override enabled:", s.feed_override_enabled)
    c.set_feed_override(1)
    done("feed override on")
    print("feed override enabled:", s.feed_override_enabled)

    c.spindle(linuxcnc.SPINDLE_FORWARD, 1000)
    done("spindle forward")
    sp = s.spindle[0]
    print("forward:", sp["direction"], sp["enabled"], sp["speed"])
    c.spindle(linuxcnc.SPINDLE_INCREASE)
    done("spindle increase")
    print("faster:", s.spindle[0]["speed"] > 1000)
    c.spindleoverride(0.5)
    done("spindle override")
    print("spindle override:", s.spindle[0]["override"])
    c.spindleoverride(1.0, 0)
    done("spindle override")
    c.spindle(linuxcnc.SPINDLE_REVERSE, 500, 0)
    done("spindle reverse")
    sp = s.spindle[0]
    print("reverse:", sp["direction"], sp["speed"])
    c.spindle(linuxcnc.SPINDLE_OFF)
    done("spindle off")
    sp = s.spindle[0]
    print("off:", sp["direction"], sp["enabled"], sp["speed"])
    c.brake(linuxcnc.BRAKE_ENGAGE)
    done("brake")
    print("brake engaged:", s.spindle[0]["brake"])
    c.brake(linuxcnc.BRAKE_RELEASE)
    done("brake")
    print("brake released:", s.spindle[0]["brake"])

    c.flood(linuxcnc.FLOOD_ON)
    done("flood on")
    print("flood on:", s.flood == linuxcnc.FLOOD_ON)
    c.mist(linuxcnc.MIST_ON)
    done("mist on")
    print("mist on:", s.mist == linuxcnc.MIST_ON)
    c.flood(linuxcnc.FLOOD_OFF)
    c.mist(linuxcnc.MIST_OFF)
    done("coolant off")
    print("coolant off:", s.flood == linuxcnc.FLOOD_OFF,
          s.mist == linuxcnc.MIST_OFF)
finally:
    c.feedrate(1.0)
    c.rapidrate(1.0)
    c.maxvel(40.0)
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: feedrate: 1.5
# expect: rapidrate: 0.5
# expect: max velocity: 30.0
# expect: feed override enabled: False
# expect: feed override enabled: True
# expect: forward: 1 1 1000.0
# expect: faster: True
# expect: spindle override: 0.5
# expect: reverse: -1 -500.0
# expect: off: 0 0 0.0
# expect: brake engaged: 1
# expect: brake released: 0
# expect: flood on: True
# expect: mist on: True
# expect: coolant off: True True
