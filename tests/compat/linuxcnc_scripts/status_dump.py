#!/usr/bin/env python3
"""Explore the contents of linuxcnc.stat: poll once, print every public
attribute (the manual's status example), then check the shape of what
was printed: the types and tuple lengths scripts rely on."""
import sys

import linuxcnc

try:
    s = linuxcnc.stat()     # create a connection to the status channel
    s.poll()                # get current values
except linuxcnc.error as detail:
    print("error", detail)
    sys.exit(1)
for x in dir(s):
    if not x.startswith("_"):
        print(x, getattr(s, x))

print("task_state is estop:", s.task_state == linuxcnc.STATE_ESTOP)
print("joints:", s.joints)
print("lengths:", len(s.joint), len(s.axis), len(s.spindle), len(s.homed),
      len(s.din), len(s.dout), len(s.ain), len(s.aout), len(s.gcodes),
      len(s.mcodes), len(s.settings), len(s.position))
print("joint 0 keys:", len(s.joint[0]), s.joint[1]["max_position_limit"])
print("axis 0 keys:", " ".join(sorted(s.axis[0])))
print("spindle 0 keys:", len(s.spindle[0]), s.spindle[0]["override"])
print("types:", type(s.task_state).__name__, type(s.enabled).__name__,
      type(s.position).__name__, type(s.file).__name__,
      type(s.feedrate).__name__)
print("ini file ends with mill.ini:", s.ini_filename.endswith("mill.ini"))
print("axis mask:", s.axis_mask)

# expect: axis_mask 7
# expect: estop 1
# expect: joints 3
# expect: task_state 1
# expect: task_state is estop: True
# expect: joints: 3
# expect: lengths: 16 9 8 16 64 64 64 64 17 10 5 9
# expect: joint 0 keys: 22 151.0
# expect: axis 0 keys: max_position_limit min_position_limit velocity
# expect: spindle 0 keys: 9 1.0
# expect: types: int bool tuple str float
# expect: ini file ends with mill.ini: True
# expect: axis mask: 7
