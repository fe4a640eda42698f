#!/usr/bin/env python3
"""HAL file loading: the wall time of ``halrun -f`` on a 10,000-line file.

The generated file (``generate()``) uses only the shipped logic components
and ``threads``, which the reference has too:

* ``loadrt threads`` (two threads) and ``loadrt and2/or2/xor2/not count=N``
  (N = 250 by default: 1,000 gates, 3,750 pins; the reference's HAL memory
  has a fixed size and holds about 1,300 such gates, not 10,000 lines' worth);
* one ``addf`` per gate function (1,000), alternating between the threads;
* one ``net`` per gate output (999), chaining every gate to the next one
  (both arrow directions are used);
* ``setp`` lines on the free ``in1`` inputs, cycling over them (about 10
  per pin) until the file has the requested number of lines;
* a last ``getp`` line, whose output is compared between the two runs.

Figures printed (wall time of the whole program, start-up and tear-down
included; median of ``--repeat`` runs, the spread beside it):

* ours: ``python -m halsdk.halcmd.cli halrun -f FILE``;
* the reference (when ``/usr/bin/halrun`` exists): ``reference halrun -f
  FILE`` run by the project's ``reference`` tool from a temp folder that
  holds only the file.  Its time includes the tool itself (``su`` to an
  unprivileged user and a copy of the folder); that overhead is measured
  separately with ``reference true`` from a folder holding the same file
  and printed, but not subtracted;
* the ratio ours / reference, for the 10,000-line file and for an empty
  file (start-up and tear-down only).

Only one reference HAL can run on a machine: when the reference says that
realtime is already running (another user), the run waits and retries.

Run: ``python bench/halfile_load.py [--lines 10000] [--instances 250]
[--repeat 3] [--no-reference] [--keep FILE]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Sequence
from typing import Optional

from benchlib import (
    REFERENCE_HALRUN,
    REFERENCE_TOOL,
    RunError,
    add_keep,
    add_no_reference,
    add_repeat,
    run_folder,
    timed,
    use_reference,
)

OURS = [sys.executable, "-m", "halsdk.halcmd.cli", "halrun"]
BUSY = "Realtime already running"
GATES = ("and2", "or2", "xor2", "not")
THREADS = ("fast", "slow")
# gates per kind: 4 x 250 fit in the reference's fixed-size HAL memory
# (about 1,300 gates do; 4 x 908 do not)
INSTANCES = 250


# ------------------------------------------------------------ the file

def _in0(kind: str, i: int) -> str:
    return f"{kind}.{i}.in" if kind == "not" else f"{kind}.{i}.in0"


def generate(lines: int = 10_000, instances: int = INSTANCES) -> str:
    """A HAL file of exactly ``lines`` lines, with ``instances`` gates of
    each kind (4 x ``instances`` functions, pins and nets)."""
    chain = [(kind, i) for i in range(instances) for kind in GATES]
    in1 = [f"{kind}.{i}.in1" for kind, i in chain if kind != "not"]
    # loadrt lines, addf and net lines, one setp per in1, the final getp
    need = 1 + len(GATES) + 2 * len(chain) - 1 + len(in1) + 1
    if instances < 1 or lines < need:
        raise ValueError(f"{instances} instances per kind need at least "
                         f"{need} lines")
    out = [f"loadrt threads name1={THREADS[0]} period1=100000 "
           f"name2={THREADS[1]} period2=1000000"]
    out += [f"loadrt {kind} count={instances}" for kind in GATES]
    for k, (kind, i) in enumerate(chain):
        out.append(f"addf {kind}.{i} {THREADS[k % 2]}")
    for k in range(len(chain) - 1):
        (kind, i), (nkind, ni) = chain[k], chain[k + 1]
        src, dst = f"{kind}.{i}.out", _in0(nkind, ni)
        if k % 2:
            out.append(f"net s{k:05d} {dst} <= {src}")
        else:
            out.append(f"net s{k:05d} {src} => {dst}")
    k = 0
    while len(out) < lines - 1:
        out.append(f"setp {in1[k % len(in1)]} {(k // len(in1) + k) % 2}")
        k += 1
    out.append(f"getp {in1[-1]}")
    assert len(out) == lines, (len(out), lines)
    return "\n".join(out) + "\n"


# ------------------------------------------------------------ timing

def time_ours(path: str) -> tuple[float, str]:
    folder = os.path.dirname(path)
    return timed(OURS + ["-f", os.path.basename(path)], folder)


def time_reference(path: str, retry_s: float = 300) -> tuple[float, str]:
    """``reference halrun -f FILE``; waits while another reference HAL
    runs on the machine."""
    folder = os.path.dirname(path)
    deadline = time.monotonic() + retry_s
    while True:
        try:
            return timed([REFERENCE_TOOL, "halrun", "-f",
                           os.path.basename(path)], folder)
        except RunError as e:
            if BUSY not in str(e) or time.monotonic() > deadline:
                raise
            time.sleep(2)


def time_wrapper(path: str) -> float:
    """The reference tool's own cost: ``reference true`` from a folder
    holding the same file (the tool copies the folder)."""
    return timed([REFERENCE_TOOL, "true"], os.path.dirname(path))[0]


def measure(fn, repeat: int) -> tuple[list[float], str]:
    walls, out = [], ""
    for _ in range(repeat):
        wall, out = fn()
        walls.append(wall)
    return walls, out


def _fmt(walls: list[float]) -> str:
    med = statistics.median(walls)
    return f"{med:8.3f} s  ({min(walls):.3f}..{max(walls):.3f})"


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--lines", type=int, default=10_000,
                   help="lines of the generated file (default 10000)")
    p.add_argument("--instances", type=int, default=INSTANCES,
                   help="gates of each of the 4 kinds (default "
                        f"{INSTANCES}; the reference's HAL memory holds "
                        "about 1,300 gates)")
    add_repeat(p, 3, "runs of each case; the median is printed")
    add_no_reference(p)
    add_keep(p)
    a = p.parse_args(argv)
    try:
        text = generate(a.lines, a.instances)
    except ValueError as e:
        p.error(str(e))
    if a.keep:
        with open(a.keep, "w") as f:
            f.write(text)
    use_ref = use_reference(not a.no_reference, REFERENCE_HALRUN)
    with run_folder("halsdk-bench-load-", {"load.hal": text}) as big_dir, \
            run_folder("halsdk-bench-load-", {"empty.hal": ""}) as empty_dir:
        big = os.path.join(big_dir, "load.hal")
        empty = os.path.join(empty_dir, "empty.hal")
        print(f"file: {a.lines} lines ({len(GATES)} gate kinds x "
              f"{a.instances} instances); "
              f"{a.repeat} run(s) per case, median (min..max)")
        res: dict[str, list[float]] = {}
        res["ours"], ours_out = measure(lambda: time_ours(big), a.repeat)
        res["ours empty"], _ = measure(lambda: time_ours(empty), a.repeat)
        big_label = f"halrun -f {a.lines}-line file:"
        width = max(len(big_label), len("reference tool (reference true):"))

        def show(who: str, label: str, walls: list[float],
                 note: str = "") -> None:
            print(f"{who:<10} {label:<{width}} {_fmt(walls)}{note}")

        show("ours", big_label, res["ours"])
        show("ours", "halrun -f empty file:", res["ours empty"])
        if not use_ref:
            print("reference: not installed or disabled; no ratio")
            return 0
        res["ref"], ref_out = measure(lambda: time_reference(big), a.repeat)
        res["ref empty"], _ = measure(lambda: time_reference(empty),
                                      a.repeat)
        res["wrapper"], _ = measure(lambda: (time_wrapper(big), ""),
                                    a.repeat)
        show("reference", big_label, res["ref"])
        show("reference", "halrun -f empty file:", res["ref empty"])
        show("reference", "tool (reference true):", res["wrapper"],
             "  (included above, not subtracted)")
        if ours_out != ref_out:
            print(f"WARNING: outputs differ: ours {ours_out!r}, reference "
                  f"{ref_out!r}")
        med = {k: statistics.median(v) for k, v in res.items()}
        print(f"ratio ours / reference, {a.lines}-line file: "
              f"{med['ours'] / med['ref']:.2f}   (goal <= 1)")
        print(f"ratio ours / reference, empty file:       "
              f"{med['ours empty'] / med['ref empty']:.2f}")
        net_big = med["ref"] - med["wrapper"]
        net_empty = med["ref empty"] - med["wrapper"]
        if net_big > 0 and net_empty > 0:
            print(f"(for information, with the tool overhead subtracted "
                  f"from the reference: {med['ours'] / net_big:.2f} and "
                  f"{med['ours empty'] / net_empty:.2f})")
        return 0


if __name__ == "__main__":
    sys.exit(main())
