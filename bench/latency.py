#!/usr/bin/env python3
"""Latency: how regularly a base and a servo thread run, ours and LinuxCNC's.

Configuration, the same on both sides (the layout of LinuxCNC's
latency-test): a base thread (25 us) and a servo thread (1 ms), each
running one ``timedelta`` (``timedelta.0`` in the base thread,
``timedelta.1`` in the servo thread).  After a warm-up both are reset
(``reset`` held for 0.1 s), the threads run for ``--seconds``, and each
timedelta's ``jitter`` (the largest deviation of an interval from the
period) and ``max`` (the longest interval) are read.

Ours runs in a private HAL instance, with SCHED_FIFO and locked memory
when it may and with normal scheduling (``--sched``), in a child process
started in a session of its own, as the reference's rtapi_app runs: with
the kernel's autogroup scheduling a session is a scheduling group, and
under normal scheduling the group decides how soon a thread runs
(``--same-session`` runs it in this process instead).
The reference runs the same HAL file with its own ``halrun`` through the
project's ``reference`` tool (one reference HAL at a time: the bench
holds the reference lock); its rtapi_app is setuid root and says which
scheduling it got.  Each side runs ``--repeat`` times, alternating; the
table shows the median and the largest of the runs.  The ratio and the
goal compare our runs under the scheduling the reference got.

Run: ``python bench/latency.py [--seconds 10] [--repeat 3]
[--base 25000] [--servo 1000000] [--sched both] [--no-reference]``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass
from typing import Optional

from benchlib import (
    REFERENCE_HALRUN,
    REFERENCE_TOOL,
    add_no_reference,
    add_repeat,
    reference_lock,
    run_folder,
    use_reference,
)

#: the figures read at the end, in this order (thread, pin)
READ = [(i, pin) for i in (0, 1) for pin in ("jitter", "max", "out")]
RESET_HOLD = 0.1


@dataclass
class Run:
    """One measurement: per thread (0 base, 1 servo) jitter, longest
    and last interval in ns, and the scheduling it got."""

    figures: dict[tuple[int, str], int]
    sched: str


# ------------------------------------------------------------ ours

def run_ours(base: int, servo: int, seconds: float, warmup: float,
             realtime: bool) -> Run:
    import halsdk

    with halsdk.Hal(f"bench-latency-{os.getpid()}", create=True) as hal:
        hal.loadrt("timedelta", count=2)
        hal.newthread("fast", base, fp=False)
        hal.newthread("slow", servo, fp=False)
        hal.addf("timedelta.0", "fast")
        hal.addf("timedelta.1", "slow")
        note = hal.start(realtime=realtime)
        sched = ("normal (" + note.strip() + ")" if note else
                 "SCHED_FIFO" if realtime else "normal (--non-realtime)")
        time.sleep(warmup)
        for i in (0, 1):
            hal.setp(f"timedelta.{i}.reset", True)
        time.sleep(RESET_HOLD)
        for i in (0, 1):
            hal.setp(f"timedelta.{i}.reset", False)
        time.sleep(seconds)
        figures = {(i, pin): int(hal.getp(f"timedelta.{i}.{pin}"))
                   for i, pin in READ}
        hal.stop()
    return Run(figures, sched)


def run_ours_apart(base: int, servo: int, seconds: float, warmup: float,
                   realtime: bool) -> Run:
    """:func:`run_ours` in a child process in a session of its own, as
    the reference's rtapi_app runs (it starts a session): with the
    kernel's autogroup scheduling, a session is a scheduling group, so
    both sides compete for the processors the same way."""
    cmd = [sys.executable, os.path.abspath(__file__), "--ours-once",
           "realtime" if realtime else "normal", "--base", str(base),
           "--servo", str(servo), "--seconds", str(seconds),
           "--warmup", str(warmup)]
    proc = subprocess.run(cmd, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True,
                          start_new_session=True,
                          timeout=warmup + seconds + 120)
    if proc.returncode != 0:
        raise RuntimeError(f"our run failed ({proc.returncode}):\n"
                           + (proc.stdout + proc.stderr)[-2000:])
    data = json.loads(proc.stdout.splitlines()[-1])
    return Run({(i, pin): v for i, pin, v in data["figures"]},
               data["sched"])


# ------------------------------------------------------------ reference

def reference_hal(base: int, servo: int, seconds: float,
                  warmup: float) -> str:
    lines = [f"loadrt threads name1=fast period1={base} name2=slow "
             f"period2={servo}",
             "loadrt timedelta count=2",
             "addf timedelta.0 fast",
             "addf timedelta.1 slow",
             "start",
             f"loadusr -w sleep {warmup}",
             "setp timedelta.0.reset 1", "setp timedelta.1.reset 1",
             f"loadusr -w sleep {RESET_HOLD}",
             "setp timedelta.0.reset 0", "setp timedelta.1.reset 0",
             f"loadusr -w sleep {seconds}"]
    lines += [f"getp timedelta.{i}.{pin}" for i, pin in READ]
    lines += ["stop", ""]
    return "\n".join(lines)


def run_reference(base: int, servo: int, seconds: float,
                  warmup: float) -> Run:
    text = reference_hal(base, servo, seconds, warmup)
    with reference_lock(), run_folder("halsdk-bench-latency-",
                                      {"latency.hal": text}) as folder:
        proc = subprocess.run([REFERENCE_TOOL, "halrun", "-f",
                               "latency.hal"], cwd=folder,
                              stdin=subprocess.DEVNULL, capture_output=True,
                              text=True, timeout=warmup + seconds + 120)
    out = proc.stdout + proc.stderr
    values = [int(x) for x in re.findall(r"^\s*(-?\d+)\s*$", proc.stdout,
                                         re.M)]
    if proc.returncode != 0 or len(values) < len(READ):
        raise RuntimeError(f"reference run failed ({proc.returncode}):\n"
                           + out[-2000:])
    figures = dict(zip(READ, values[-len(READ):]))
    sched = ("normal (" + m.group(0).strip() + ")"
             if (m := re.search(r".*non-realtime.*", out)) else "SCHED_FIFO")
    return Run(figures, sched)


# ------------------------------------------------------------ report

def column(runs: list[Run], key: tuple[int, str]) -> str:
    if not runs:
        return "-"
    v = [r.figures[key] for r in runs]
    return f"{statistics.median(v):.0f} (max {max(v)})" if len(v) > 1 \
        else str(v[0])


def ratio(ours: list[Run], ref: list[Run], key: tuple[int, str]) -> str:
    if not ours or not ref:
        return "-"
    a = statistics.median(r.figures[key] for r in ours)
    b = statistics.median(r.figures[key] for r in ref)
    return f"{a / b:.2f}" if b else "-"


def same_side(ours: dict[str, list[Run]], ref: list[Run]) -> list[Run]:
    """Our runs under the scheduling the reference got (the normal ones
    when it ran without realtime)."""
    normal = bool(ref) and all(r.sched.startswith("normal") for r in ref)
    if normal and ours["normal"]:
        return ours["normal"]
    return ours["realtime"] or ours["normal"]


def report(a: argparse.Namespace, ours: dict[str, list[Run]],
           ref: list[Run]) -> None:
    print(f"\nlatency: base thread {a.base} ns and servo thread {a.servo} "
          f"ns, a timedelta each; {a.seconds:g} s per run after "
          f"{a.warmup:g} s warm-up, {a.repeat} run(s) per side")
    sides = [(k, v) for k, v in ours.items() if v]
    for k, v in sides:
        print(f"ours {k}: " + ", ".join(sorted({r.sched for r in v})))
    if ref:
        print("reference: " + ", ".join(sorted({r.sched for r in ref})))
    else:
        print("reference: not run")
    mine = same_side(ours, ref)
    head = ("", *(f"ours {k}" for k, _ in sides), "reference",
            "ours/ref")
    rows = [head]
    for i, name in ((0, "base"), (1, "servo")):
        for pin, what in (("jitter", "max jitter (ns)"),
                          ("max", "max interval (ns)")):
            rows.append((f"{name} {what}",
                         *(column(v, (i, pin)) for _, v in sides),
                         column(ref, (i, pin)), ratio(mine, ref, (i, pin))))
    widths = [max(len(r[k]) for r in rows) for k in range(len(head))]
    print()
    for r in rows:
        print("  ".join([r[0].ljust(widths[0])]
                        + [c.rjust(w) for c, w in zip(r[1:], widths[1:])]))
    if a.repeat > 1:
        print("\n(median of the runs, the largest in brackets)")
    if ref:
        print(f"ours/ref: ours {mine[0].sched.split()[0]} (the reference's "
              "scheduling when we have it) over the reference")
        for i, name in ((0, "base"), (1, "servo")):
            x = statistics.median(r.figures[(i, "jitter")] for r in mine)
            y = statistics.median(r.figures[(i, "jitter")] for r in ref)
            verdict = "met" if x <= y else "MISSED"
            print(f"goal (our max jitter no worse than the reference's), "
                  f"{name}: {verdict}")


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=10.0,
                   help="length of each run (default 10)")
    p.add_argument("--warmup", type=float, default=1.0,
                   help="run time before the reset (default 1)")
    p.add_argument("--base", type=int, default=25_000,
                   help="base period in ns (default 25000)")
    p.add_argument("--servo", type=int, default=1_000_000,
                   help="servo period in ns (default 1000000)")
    add_repeat(p, 1, "runs per side, alternating; the table shows the "
                     "median")
    add_no_reference(p)
    p.add_argument("--same-session", action="store_true",
                   help="run our side in this process's session (default: "
                        "a child in a session of its own, as the "
                        "reference's rtapi_app)")
    p.add_argument("--ours-once", choices=("realtime", "normal"),
                   help=argparse.SUPPRESS)
    p.add_argument("--sched", choices=("both", "realtime", "normal"),
                   default="both",
                   help="our threads with realtime scheduling (SCHED_FIFO "
                        "and locked memory, when we may), normal "
                        "scheduling, or both, one after the other "
                        "(default both)")
    a = p.parse_args(argv)
    if a.seconds <= 0 or a.warmup < 0:
        p.error("--seconds must be > 0, --warmup >= 0")
    if not 0 < a.base < a.servo:
        p.error("--base must be > 0 and shorter than --servo")
    if a.ours_once:
        run = run_ours(a.base, a.servo, a.seconds, a.warmup,
                       a.ours_once == "realtime")
        print(json.dumps({"sched": run.sched, "figures": [
            [i, pin, v] for (i, pin), v in run.figures.items()]}))
        return 0
    ours_run = run_ours if a.same_session else run_ours_apart
    with_ref = use_reference(not a.no_reference, REFERENCE_HALRUN)
    ours: dict[str, list[Run]] = {"realtime": [], "normal": []}
    ref: list[Run] = []
    for _ in range(a.repeat):
        for sched in ours:
            if a.sched in ("both", sched):
                ours[sched].append(ours_run(a.base, a.servo, a.seconds,
                                            a.warmup, sched == "realtime"))
        if with_ref:
            ref.append(run_reference(a.base, a.servo, a.seconds, a.warmup))
    report(a, ours, ref)
    return 0


if __name__ == "__main__":
    sys.exit(main())
