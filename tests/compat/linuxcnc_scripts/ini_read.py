#!/usr/bin/env python3
"""Read the machine's own INI file: its name from stat.ini_filename,
then linuxcnc.ini find() and findall() (the manual's INI examples)."""
import os

import linuxcnc

stat = linuxcnc.stat()
stat.poll()

inifile = linuxcnc.ini(stat.ini_filename)

# find() returns None if the key wasn't found: the idiom for a default
machine_name = inifile.find("EMC", "MACHINE") or "unknown"
print("machine name:", machine_name)
print("no such key:", inifile.find("EMC", "NO_SUCH_KEY") or "unknown")

# findall() returns a list of matches, or an empty list
halfiles = inifile.findall("HAL", "HALFILE")
print("hal files:", [os.path.basename(f) for f in halfiles])
print("no such list:", inifile.findall("FILTER", "PROGRAM_EXTENSION"))
print("second hal file:", os.path.basename(inifile.find("HAL", "HALFILE", 2)))

# override the default NML file by an INI entry if given
nmlfile = inifile.find("EMC", "NML_FILE")
if nmlfile:
    linuxcnc.nmlfile = os.path.join(os.path.dirname(stat.ini_filename),
                                    nmlfile)
print("nml file is a string:", isinstance(linuxcnc.nmlfile, str))

joints = int(inifile.find("KINS", "JOINTS"))
print("joints agree:", joints == stat.joints)
coordinates = inifile.find("TRAJ", "COORDINATES")
print("coordinates:", coordinates)
limits = [float(inifile.find(f"JOINT_{j}", "MAX_LIMIT"))
          for j in range(joints)]
print("limits agree:", limits ==
      [stat.joint[j]["max_position_limit"] for j in range(joints)])
print("case matters:", inifile.find("emc", "machine"))

# expect: machine name: halsdk simulated servo mill
# expect: no such key: unknown
# expect: hal files: ['mill.hal', 'toolchange.hal']
# expect: no such list: []
# expect: second hal file: toolchange.hal
# expect: nml file is a string: True
# expect: joints agree: True
# expect: coordinates: X Y Z
# expect: limits agree: True
# expect: case matters: None
