#!/usr/bin/env python3
"""CPU time per servo cycle of the motion module, ours and the reference's.

The motion module's two functions, ``motion-command-handler`` and
``motion-controller``, run in a 1 kHz servo thread with trivkins, the
homing module and the trajectory planner loaded, for 3 and 9 joints:

=========  ================================================================
case       what runs
=========  ================================================================
idle       motion loaded, not enabled (the reference's motion cannot be
           commanded without its task and NML layers, so this is the case
           both programs run)
jogging    ours only: motion enabled, every joint in a continuous jog
           (free mode, trapezoidal and jerk-limited profiles), commanded
           through ``halsdk.motion``
=========  ================================================================

The figure is the sum of the two functions' own times in a cycle (their
``<function>.time`` pins, read 60 times 50 ms apart, median).  The
reference counts CPU clocks; they are converted with the CPU clock of
/proc/cpuinfo.  The reference runs through the project's ``reference``
tool under the lock every reference run takes.  Goal: ours no slower than
the reference (ratio at most 1.00).

Run: ``python bench/motion.py [--joints 3,9] [--no-reference]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from typing import Optional

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import (  # noqa: E402
    REFERENCE_HALRUN,
    REFERENCE_TOOL,
    add_no_reference,
    reference_lock,
    run_folder,
    use_reference,
)
from thread_overhead import tsc_mhz  # noqa: E402

READS = 60
FUNCTIONS = ("motion-command-handler", "motion-controller")


def machine_lines(joints: int) -> list[str]:
    coords = "xyzabcuvw"[:joints] if joints <= 9 else "xyz"
    return [f"loadrt trivkins coordinates={coords}",
            "loadrt homemod", "loadrt tpmod",
            f"loadrt motmod servo_period_nsec=1000000 num_joints={joints}",
            "addf motion-command-handler servo-thread",
            "addf motion-controller servo-thread"]


def reference_idle(joints: int) -> Optional[float]:
    """ns per cycle of the reference's two functions, idle."""
    lines = machine_lines(joints) + ["start", "loadusr -w sleep 1"]
    for _ in range(READS):
        lines += ["loadusr -w sleep 0.05"]
        lines += [f"getp {f}.time" for f in FUNCTIONS]
    lines += ["stop", ""]
    with run_folder("halsdk-bench-motion-",
                    {"bench.hal": "\n".join(lines)}) as folder:
        with reference_lock():
            # the system PATH: a halsdk venv first on PATH would give the
            # reference's user our halrun
            env = dict(os.environ, PATH="/usr/sbin:/usr/bin:/sbin:/bin")
            proc = subprocess.run(
                ["timeout", "60", REFERENCE_TOOL, "halrun", "-f", "bench.hal"],
                cwd=folder, capture_output=True, text=True, env=env,
                stdin=subprocess.DEVNULL)
        values = [int(x) for x in proc.stdout.split()
                  if x.lstrip("-").isdigit()]
        if proc.returncode != 0 or len(values) < READS:
            print(f"reference run failed ({proc.returncode}):\n"
                  + proc.stderr[-1500:], file=sys.stderr)
            return None
        mhz = tsc_mhz() or 1000.0
        cycles = [(a + b) * 1000 / mhz
                  for a, b in zip(values[0::2], values[1::2])]
        return statistics.median(cycles)


def ours(joints: int, jog: Optional[str]) -> float:
    """ns per cycle of our two functions, idle (jog None) or with every
    joint jogging with the profile jog ("trapezoid" or "jerk")."""
    import halsdk
    from halsdk.motion import Motion

    name = f"benchmotion-{os.getpid()}-{joints}-{jog}"
    with halsdk.Hal(instance=name) as hal:
        for line in machine_lines(joints):
            hal.command(line)
        hal.start()
        if jog:
            motion = Motion.connect(hal)
            for j in range(joints):
                motion.set_joint_limits(j, -1e6, 1e6)
                motion.set_joint_max_velocity(j, 100.0)
                motion.set_joint_max_acceleration(j, 1000.0)
                motion.set_joint_ferror(j, 1e6, 1e6)
                if jog == "jerk":
                    motion.set_joint_max_jerk(j, 1e5)
            motion.enable()
            for j in range(joints):
                motion.jog_cont(j, 10.0 + j)
        time.sleep(1.0)
        cycles = []
        for _ in range(READS):
            time.sleep(0.05)
            cycles.append(sum(hal.getp(f"{f}.time") for f in FUNCTIONS))
        hal.stop()
        return statistics.median(cycles)


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--joints", default="3,9")
    add_no_reference(p)
    a = p.parse_args(argv)
    counts = [int(x) for x in a.joints.split(",") if x]
    with_ref = use_reference(not a.no_reference, REFERENCE_HALRUN)
    print("\nmotion-command-handler + motion-controller, ns per 1 kHz "
          "cycle (median of 60 reads)\n")
    rows = [("joints", "case", "ours", "reference", "ratio")]
    slower, missing = [], []
    for n in counts:
        idle = ours(n, None)
        ref = reference_idle(n) if with_ref else None
        if with_ref and ref is None:
            missing.append(f"{n} joints")
        rows.append((str(n), "idle", f"{idle:.0f}",
                     "-" if ref is None else f"{ref:.0f}",
                     "-" if not ref else f"{idle / ref:.2f}"))
        if ref and idle > ref:
            slower.append(f"{n} joints idle")
        for profile in ("trapezoid", "jerk"):
            rows.append((str(n), f"jogging ({profile})",
                         f"{ours(n, profile):.0f}", "-", "-"))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    for r in rows:
        print("  ".join([r[0].rjust(widths[0]), r[1].ljust(widths[1])]
                        + [x.rjust(w) for x, w in zip(r[2:], widths[2:])]))
    if with_ref and missing:
        print("\ngoal not checked: the reference did not run for "
              + ", ".join(missing))
    elif with_ref:
        print("\ngoal (idle no slower than the reference): "
              + ("met" if not slower else "MISSED for " + ", ".join(slower)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
