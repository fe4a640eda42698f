#!/usr/bin/env python3
"""Instructions per channel of the base-thread functions, under callgrind.

On a busy VM the in-cycle times of ``bench/components.py`` move by a
third from run to run; an instruction count does not.  This script steps
(``hal.step``, simulated time, no sleeping) a 25 us base thread running
one of ``stepgen.make-pulses`` (16 channels, every step type asked for,
velocity mode, stepping at 2 to 6 kHz), ``encoder.update-counters`` (8
channels, idle inputs) or ``pwmgen.make-pulses`` (8 channels, PWM at
1 kHz, duty 10 to 45 %) under ``valgrind --tool=callgrind``, collecting
only inside the function, and prints the instructions per channel per
period.  Ours only: the reference's rtapi_app runs as another user and
is not traced.

``--path DIR`` puts DIR first on HALSDK_PATH: a component built there
(``python -m halcompile --compile -o DIR components/stepgen.comp``) is
measured instead of the installed one, to compare two builds.

Run: ``python bench/pulses_callgrind.py [--cases stepgen,encoder,pwmgen]
[--types 0,1,2,9] [--periods 10000] [--path DIR]``.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from typing import Optional

#: the C function of each case (static symbols of the module)
SYMBOL = {"stepgen": "make_pulses", "encoder": "update_counters",
          "pwmgen": "make_pulses"}
CHANNELS = {"stepgen": 16, "encoder": 8, "pwmgen": 8}


def drive(case: str, step_type: int, periods: int) -> None:
    """Make the case's instance and step it (runs under callgrind)."""
    import halsdk

    n = CHANNELS[case]
    with halsdk.Hal(f"benchpulses-{os.getpid()}", create=True) as hal:
        hal.newthread("base", 25000, fp=False)
        hal.newthread("servo", 1000000)
        if case == "stepgen":
            hal.loadrt("stepgen", step_type=",".join([str(step_type)] * n),
                       ctrl_type=",".join(["v"] * n))
            for i in range(n):
                hal.setp(f"stepgen.{i}.position-scale", 1000)
                hal.setp(f"stepgen.{i}.maxaccel", 0)
                hal.setp(f"stepgen.{i}.velocity-cmd", 2 + i % 5)
                hal.setp(f"stepgen.{i}.enable", True)
            hal.addf("stepgen.make-pulses", "base")
            hal.addf("stepgen.update-freq", "servo")
            hal.addf("stepgen.capture-position", "servo")
        elif case == "encoder":
            hal.loadrt("encoder", num_chan=n)
            hal.addf("encoder.update-counters", "base")
            hal.addf("encoder.capture-position", "servo")
        else:
            hal.loadrt("pwmgen", output_type=",".join(["1"] * n))
            for i in range(n):
                hal.setp(f"pwmgen.{i}.value", 0.1 + 0.05 * i)
                hal.setp(f"pwmgen.{i}.pwm-freq", 1000)
                hal.setp(f"pwmgen.{i}.enable", True)
            hal.addf("pwmgen.make-pulses", "base")
            hal.addf("pwmgen.update", "servo")
        hal.step(periods)


def measure(case: str, step_type: int, periods: int,
            path: Optional[str]) -> float:
    """Instructions per channel per period of the case's function."""
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = f"benchpulses-{os.getpid()}"
    if path:
        old = env.get("HALSDK_PATH")
        env["HALSDK_PATH"] = path + (os.pathsep + old if old else "")
    with tempfile.TemporaryDirectory(prefix="halsdk-callgrind-") as tmp:
        out = os.path.join(tmp, "cg.out")
        proc = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
             f"--toggle-collect={SYMBOL[case]}", sys.executable,
             os.path.abspath(__file__), "--drive", case, "--types",
             str(step_type), "--periods", str(periods)],
            env=env, capture_output=True, text=True, timeout=900,
            stdin=subprocess.DEVNULL)
        m = re.search(r"Collected : (\d+)", proc.stderr)
        if proc.returncode != 0 or not m:
            raise RuntimeError(f"{case}: callgrind run failed "
                               f"({proc.returncode}):\n"
                               + proc.stderr[-2000:])
    return int(m.group(1)) / (periods * CHANNELS[case])


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cases", default="stepgen,encoder,pwmgen")
    p.add_argument("--types", default="0,1,2,9",
                   help="stepgen step types (default 0,1,2,9)")
    p.add_argument("--periods", type=int, default=10000,
                   help="base periods stepped (default 10000)")
    p.add_argument("--path", help="a folder of components measured "
                                  "instead of the installed ones")
    p.add_argument("--drive", help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.drive:
        drive(a.drive, int(a.types), a.periods)
        return 0
    if not shutil.which("valgrind"):
        p.error("valgrind is not installed")
    cases = [c for c in a.cases.split(",") if c]
    if not cases or any(c not in SYMBOL for c in cases) or a.periods < 1:
        p.error("--cases: stepgen, encoder, pwmgen; --periods >= 1")
    rows = []
    for case in cases:
        types = [int(t) for t in a.types.split(",")] \
            if case == "stepgen" else [0]
        for t in types:
            label = f"stepgen type {t}" if case == "stepgen" else case
            rows.append((label, measure(case, t, a.periods, a.path)))
    print(f"\ninstructions per channel per base period (callgrind, "
          f"{a.periods} periods)\n")
    width = max(len(r[0]) for r in rows)
    for label, v in rows:
        print(f"{label.ljust(width)}  {v:7.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
