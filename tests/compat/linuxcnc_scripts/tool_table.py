#!/usr/bin/env python3
"""The tool table through the status: entry 0 is the tool in the
spindle; load a tool with M6 and see it there, change a tool's offsets
with command.tool_offset() and read the table file back with
load_tool_table()."""
import sys
import time

import linuxcnc

s = linuxcnc.stat()
c = linuxcnc.command()


def done(what, timeout=10.0):
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


def entry(tool):
    for t in s.tool_table[1:]:
        if t.id == tool:
            return t
    return None


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
    c.mdi("G49 T0 M6")
    done("unload")
    s.poll()
    print("no tool:", s.tool_in_spindle, s.tool_table[0].id)
    print("tools:", [t.id for t in s.tool_table[1:]])
    t2 = entry(2)
    print("tool 2:", t2.zoffset, t2.diameter)
    print("entry type:", type(t2).__name__, len(t2))

    c.mdi("T2 M6 G43")
    done("tool change")
    s.poll()
    print("in spindle:", s.tool_in_spindle, s.tool_table[0].id,
          s.tool_table[0].zoffset)
    print("tool length offset:", s.tool_offset[2])

    c.mdi("G49 T0 M6")
    done("unload")
    c.tool_offset(3, 20.0, 0.0, 3.5, 0.0, 0.0, 0)
    done("tool offset")
    s.poll()
    print("tool 3 now:", entry(3).zoffset, entry(3).diameter)
    c.load_tool_table()
    done("load tool table")
    s.poll()
    print("tool 3 read back:", entry(3).zoffset, entry(3).diameter)
    c.tool_offset(3, 18.0, 0.0, 3.0, 0.0, 0.0, 0)    # as it was
    done("tool offset")
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: no tool: 0 -1
# expect: tools: [1, 2, 3, 4]
# expect: tool 2: 32.5 10.0
# expect: entry type: tool_result 14
# expect: in spindle: 2 2 32.5
# expect: tool length offset: 32.5
# expect: tool 3 now: 20.0 3.5
# expect: tool 3 read back: 20.0 3.5
