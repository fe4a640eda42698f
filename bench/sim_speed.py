#!/usr/bin/env python3
"""Whole-machine simulation speed: machine-seconds per wall-second.

The demo mill (``examples/mill``: homing, then ``demo.ngc``) and a
generated 30-minute contouring program (many short G1, G2 and G3 moves)
on the same machine, stepped (simulated time, no sleeping), measured
three ways in one run:

* **before**: the in-process :class:`halsdk.machine.Machine` as the demo
  drives it: one task cycle per servo cycle, the I/O controller polled
  by a Python function in the servo thread (what ``halsdk-demo`` did);
* **simulate, every cycle**: ``halsdk run --simulate`` with the task
  looking every task cycle (``[TASK]CYCLE_TIME``, 10 servo cycles) and
  the I/O controller polled by the task;
* **simulate**: the same, skipping the task cycles in which the task
  provably only waits for motion to come to rest (the default).

``halsdk run --stepped`` itself paces its task cycles by the wall clock
(one task cycle per ``CYCLE_TIME``): 1x real time by construction.

Printed per row: machine seconds (homing, program), wall seconds of
homing plus program (start-up excluded, shown apart), and their ratio.
The program time of the simulate rows must agree (the skip changes no
servo cycle); the script says so.

    python bench/sim_speed.py                  # ~1 min
    python bench/sim_speed.py --minutes 5 --before-seconds 30
"""

from __future__ import annotations

import argparse
import io
import math
import os
import shutil
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
MILL = os.path.join(REPO, "examples", "mill")


def contour_program(path: str, minutes: float = 30.0,
                    feed: float = 1500.0) -> float:
    """Write a contouring program of about ``minutes`` at ``feed`` mm/min:
    rounded squares of short G1 chords and G2/G3 corner arcs, stepped
    over the XY travel of the demo mill; returns its path length (mm)."""
    lines = ["(sim_speed.py: a generated contouring program)",
             "G21 G90 G17 G94 G40 G49 G54 G64", "G0 Z-5",
             f"F{feed:g}"]
    length = 0.0
    want = feed / 60.0 * minutes * 60.0
    k = 0
    while length < want:
        cx = 60.0 + 10.0 * (k % 8)          # centres over the travel
        cy = 40.0 + 8.0 * ((k // 8) % 6)
        side, r, chord = 40.0, 5.0, 0.5
        x0, y0 = cx - side / 2 + r, cy - side / 2
        lines.append(f"G0 X{x0:.3f} Y{y0:.3f}")
        x, y = x0, y0
        # four sides of short chords, corners as arcs (G3 ccw, a G2 bump
        # in the middle of every second side)
        for edge in range(4):
            dx, dy = [(1, 0), (0, 1), (-1, 0), (0, -1)][edge]
            n = int((side - 2 * r) / chord)
            for i in range(n):
                if edge % 2 and i == n // 2:
                    # a small G2 bump outward and back
                    nx, ny = x + dx * 2, y + dy * 2
                    lines.append(f"G2 X{nx:.3f} Y{ny:.3f} R1.2")
                    length += math.pi * 1.2 * 0.9
                    x, y = nx, ny
                    continue
                x, y = x + dx * chord, y + dy * chord
                lines.append(f"G1 X{x:.3f} Y{y:.3f}")
                length += chord
            # corner: a quarter circle, ccw (the centre is to the left)
            cxn, cyn = x - dy * r, y + dx * r
            nx, ny = cxn + dx * r, cyn + dy * r
            lines.append(f"G3 X{nx:.3f} Y{ny:.3f} I{cxn - x:.3f} "
                         f"J{cyn - y:.3f}")
            length += math.pi * r / 2
            x, y = nx, ny
        k += 1
    lines += ["G0 Z0", "M2"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return length


def before(folder: str, program: str, max_seconds: float) -> dict:
    """The in-process Machine as the demo drives it (see the docstring);
    the program for at most ``max_seconds`` of machine time."""
    from halsdk.machine import Machine, TaskMode, TaskState
    from halsdk.machine.launcher import Launcher
    w0 = time.perf_counter()
    launcher = Launcher(os.path.join(folder, "mill.ini"), out=io.StringIO())
    launcher.start(realtime=False)
    try:
        launcher.io.table.path = None
        m = Machine.from_launcher(launcher)
        hal = launcher.hal
        w1 = time.perf_counter()
        m.state(TaskState.ESTOP_RESET)
        m.state(TaskState.ON)
        t0 = hal.time
        m.home(timeout=120)
        homing = (hal.time - t0) * 1e-9
        m.mode(TaskMode.AUTO)
        m.program_open(program)
        t1 = hal.time
        m.program_run()
        period = m.motion.status().servo_period or 0.001
        ended = True
        for _ in range(round(max_seconds / period)):
            if m.task.interp_state.name == "IDLE":
                break
            m.update()
        else:
            ended = False
        prog = (hal.time - t1) * 1e-9
        w2 = time.perf_counter()
    finally:
        launcher.shutdown()
    return {"homing": homing, "program": prog, "ended": ended,
            "startup": w1 - w0, "wall": w2 - w1}


def after(folder: str, program: str, skipping: bool) -> dict:
    from halsdk.machine.simulate import simulate
    r = simulate(os.path.join(folder, "mill.ini"), program,
                 skipping=skipping, out=io.StringIO())
    if r.errors:
        raise SystemExit(f"sim_speed: the simulation failed: {r.errors}")
    return {"homing": r.homing_time, "program": r.program_time,
            "ended": True, "startup": r.wall_time - r.run_wall_time,
            "wall": r.run_wall_time}


def row(name: str, d: dict) -> None:
    machine = d["homing"] + d["program"]
    note = "" if d["ended"] else " (program cut short)"
    print(f"  {name:<26} {d['homing']:8.2f} {d['program']:9.2f} "
          f"{d['wall']:8.2f} {machine / d['wall']:8.1f}x "
          f"{d['startup']:7.2f}{note}")


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--minutes", type=float, default=30.0,
                   help="length of the contouring program (default 30)")
    p.add_argument("--before-seconds", type=float, default=60.0,
                   help="machine seconds of the contouring program that "
                        "'before' runs (default 60; it is slow)")
    p.add_argument("--repeat", type=int, default=1,
                   help="runs of each row (the fastest is shown)")
    a = p.parse_args()
    os.environ.setdefault("HALSDK_INSTANCE", f"bench-sim-{os.getpid()}")
    work = tempfile.mkdtemp(prefix="halsdk-sim-speed-")
    try:
        folder = os.path.join(work, "mill")
        shutil.copytree(MILL, folder)
        contour = os.path.join(folder, "contour.ngc")
        length = contour_program(contour, a.minutes)
        with open(contour) as f:
            nlines = sum(1 for _ in f)
        print(f"machine: {os.cpu_count()} cores, load "
              f"{os.getloadavg()[0]:.2f}; python {sys.version.split()[0]}")
        head = (f"  {'':<26} {'homing':>8} {'program':>9} {'wall':>8} "
                f"{'speed':>9} {'startup':>7}")
        for title, prog, cap in (
                ("demo mill (demo.ngc)", os.path.join(folder, "demo.ngc"),
                 600.0),
                (f"contouring ({a.minutes:g} min, {nlines} lines, "
                 f"{length / 1000:.1f} m of path)", contour,
                 a.before_seconds)):
            print(f"\n{title}: machine s, wall s (homing + program)")
            print(head)
            rows = {}
            for name, skip in (("before (Machine, 1:1)", None),
                               ("simulate, every cycle", False),
                               ("simulate", True)):
                best = None
                for _ in range(a.repeat):
                    d = before(folder, prog, cap) if skip is None else \
                        after(folder, prog, skip)
                    if best is None or d["wall"] < best["wall"]:
                        best = d
                assert best is not None
                rows[name] = best
                row(name, best)
            same = rows["simulate, every cycle"]["program"] == \
                rows["simulate"]["program"]
            print(f"  program time with and without the skip: "
                  f"{'the same' if same else 'DIFFERENT'}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
