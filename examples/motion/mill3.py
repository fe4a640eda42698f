#!/usr/bin/env python3
"""Enable, home, jog and read the status of the simulated mill of mill3.hal.

The machine is built by ``mill3.hal`` (motion + trivkins, a first-order
"drive" per joint and simulated home switches with index pulses); this
program configures motion from ``mill3.ini`` ([JOINT_n], [AXIS_L], [TRAJ]
with LinuxCNC's keys), turns motion on, homes all joints in sequence (Z
first, then X and Y together), jogs, and prints what the status snapshot
says.

    python mill3.py            # deterministic: the servo thread is stepped
    python mill3.py --realtime # the threads run on their own, in real time
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Optional

import halsdk
from halsdk.motion import Motion

HERE = os.path.dirname(os.path.abspath(__file__))

#: the motion part of the configuration: [KINS], [TRAJ], [AXIS_L], [JOINT_n]
INI = os.path.join(HERE, "mill3.ini")


def report(motion: Motion, title: str) -> None:
    s = motion.status()
    print(f"{title}: mode {s.mode.name.lower()}, "
          f"{'enabled' if s.enabled else 'disabled'}, "
          f"{'in position' if s.in_position else 'moving'}")
    for n, j in enumerate(s.joints[:3]):
        print(f"  joint {n} ({'XYZ'[n]}): pos_cmd {j.pos_cmd:9.4f}  "
              f"pos_fb {j.pos_fb:9.4f}  ferror {j.ferror:+.4f}  "
              f"{'homed' if j.homed else 'not homed'}")


def run(realtime: bool, instance: Optional[str] = None) -> dict:
    """Build the machine, run the session; returns the final joint
    positions and the largest following errors, for tests."""
    with halsdk.Hal(instance=instance) as hal:
        if hal.source(os.path.join(HERE, "mill3.hal")):
            raise SystemExit("mill3.hal failed")
        if realtime:
            hal.start()
        motion = Motion.connect(hal)
        motion.configure_ini(INI)
        motion.enable()
        report(motion, "enabled")

        motion.home()                   # all joints, by HOME_SEQUENCE
        motion.wait_homed(timeout=60)
        report(motion, "homed")

        motion.jog_incr(0, 25, 10)      # X +10 mm, twice: cumulative
        motion.jog_incr(0, 25, 10)
        motion.jog_abs(1, 25, 40)       # Y to 40 mm
        motion.wait_inpos(timeout=30)
        motion.jog_cont(2, -10)         # Z down until stopped
        motion.wait_for(lambda s: s.joints[2].pos_cmd < -5, timeout=30)
        motion.jog_stop(2)
        motion.wait_inpos(timeout=30)
        report(motion, "after jogs")

        s = motion.status()
        result = {"pos": [j.pos_cmd for j in s.joints[:3]],
                  "homed": [j.homed for j in s.joints[:3]],
                  "ferror_max": [j.ferror_high_mark for j in s.joints[:3]],
                  "errors": motion.errors()}
        motion.disable()
        if realtime:
            hal.stop()
        return result


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--realtime", action="store_true",
                   help="run the threads in real time instead of stepping")
    a = p.parse_args(argv)
    result = run(a.realtime)
    print("largest following errors:",
          ", ".join(f"{'XYZ'[n]} {e:.4f}"
                    for n, e in enumerate(result["ferror_max"])))
    for message in result["errors"]:
        print("motion:", message)
    return 0


if __name__ == "__main__":
    sys.exit(main())
