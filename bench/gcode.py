#!/usr/bin/env python3
"""Throughput and memory of the G-code interpreter, ours against the
reference's ``rs274``.

Three generated programs (``--lines`` sets the size of the first two):

* ``lines``: 100,000 short ``G1`` moves with X, Y and Z to 4 decimals, a
  3-D surfacing path as CAM writes it;
* ``arcs``: 100,000 ``G2``/``G3`` half circles with ``I`` and ``J``;
* ``owords``: 10,000 lines of o-word control flow and expressions:
  subroutines with parameters called from ``while`` and ``repeat``
  loops, ``if``/``else``, named and numbered parameters, functions.

**Ours** runs each program through ``halsdk.gcode`` (``Program`` +
``Interpreter``) in a fresh interpreter process, in three ways:

* ``stream``: ``Program.from_file`` (the file streamed, as the machine
  runs a program), commands discarded;
* ``whole``: the file read into a string first, ``Program(text)``,
  commands discarded;
* ``record``: streamed, every command kept in a ``RecordingCanon`` (what
  a preview does), for information.

The times are the wall and CPU (user + system) time from before
``Program`` is made to the end of the run (the import of halsdk and the
start of Python are not in them; about 0.1 s).  Memory is the peak
resident set size of the process (``VmHWM`` of ``/proc/self/status``,
which holds Python and the imported modules: the ``baseline`` row is a
process that only imported them), and, in a separate run, the peak of
``tracemalloc`` during the run (Python allocations only).

**The reference** runs ``rs274 -g PROGRAM > /dev/null`` (reading the
program and printing its canonical commands, the standalone interpreter
of LinuxCNC 2.9) through the project's ``reference`` tool: a small
timing script (``TIMER``) starts it (after one run that warms the file
cache) and takes its wall time, CPU time and peak RSS from
``os.wait4``, so the tool's own cost (``su``, the copy of the folder) is
not counted.  The reference's figures include its start (a few
milliseconds).

The runs go in ``--repeat`` rounds: in each, the reference runs every
program once, then ours runs it in every mode; a slower spell of a
shared machine (run to run, the same CPU time varies by a quarter on
the virtual machines we use) then falls on both sides alike.

Lines per second are source lines (the lines of the file) divided by
the CPU time, and the speed ratio is the reference's CPU time over ours:
on a machine shared with other work the CPU time moves less than the
wall time.  In ``owords`` every line of a loop body runs several times,
so it measures the control flow per line of program, not per block.
Each figure is the best (time) or the largest (memory) of ``--repeat``
runs.

**Start of a long program**: a generated program of ``--big`` lines
(default 1,000,000, about 30 MB) runs streamed until its end; the script
prints the time from ``Program.from_file`` to the first motion command
(when a machine would start moving), the lines per second and the peak
RSS and tracemalloc figures (they must not grow with the length).

Run: ``python bench/gcode.py [--repeat 3] [--no-reference] [--big N]
[--markdown]``; ``--keep DIR`` keeps the generated programs.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shutil
import subprocess
import sys
from collections.abc import Sequence
from typing import Optional

from benchlib import (
    REFERENCE_TOOL,
    add_no_reference,
    add_repeat,
    run_folder,
    timed,
    use_reference,
)

REFERENCE_RS274 = "/usr/bin/rs274"
#: how ours runs each program (see the module docstring)
MODES = ("stream", "whole", "record")


# ------------------------------------------------------------ programs

def program_lines(count: int) -> str:
    """``count`` lines: short G1 moves over a wavy surface, rows of 400
    points 0.05 mm apart."""
    out = ["G21 G90 G17 G94", "F1500", "G0 X0 Y0 Z5", "G1 Z0"]
    row = 400
    for i in range(count - len(out) - 1):
        r, c = divmod(i, row)
        x = (c if r % 2 == 0 else row - 1 - c) * 0.05
        y = r * 0.5
        z = 0.5 * math.sin(x * 0.3) * math.cos(y * 0.2) - 1.0
        out.append(f"G1 X{x:.4f} Y{y:.4f} Z{z:.4f}")
    out.append("M2")
    return "\n".join(out) + "\n"


def program_arcs(count: int) -> str:
    """``count`` lines: half circles of radius 1 to 1.5, alternately G2
    and G3, along rows in X."""
    out = ["G21 G90 G17 G94", "F1000", "G0 X0 Y0 Z1", "G1 Z0"]
    x = y = 0.0
    i = 0
    while len(out) < count - 1:
        radius = 1.0 + (i % 5) * 0.125
        g = 2 if i % 2 == 0 else 3
        out.append(f"G{g} X{x + 2 * radius:.4f} Y{y:.4f} I{radius:.4f} "
                   "J0.0000")
        x += 2 * radius
        i += 1
        if x > 200 and len(out) < count - 1:
            y += 3.0
            x = 0.0
            out.append(f"G0 X0.0000 Y{y:.4f}")
    out.append("M2")
    return "\n".join(out) + "\n"


OWORD_HEAD = """\
G21 G90 G17 G94
F800
#<_depth> = -0.5
o<step> sub
  (#1 = x, #2 = angle, #3 = radius)
  #<r> = [#3 * [1 + 0.1 * SIN[#2 * 3]]]
  o<step_if> if [#<r> GT #3]
    G1 X[#1 + #<r> * COS[#2]] Y[#<r> * SIN[#2]] Z[#<_depth>]
  o<step_if> else
    G1 X[#1 + #<r> * COS[#2]] Y[#<r> * SIN[#2]] Z[#<_depth> + 0.1]
  o<step_if> endif
o<step> endsub
o<ring> sub
  #<a> = 0
  o<ring_loop> while [#<a> LT 360]
    o<step> call [#1] [#<a>] [#2]
    #<a> = [#<a> + 45]
  o<ring_loop> endwhile
  o<ring> return [#<a>]
o<ring> endsub
G0 X0 Y0 Z1
"""


def program_owords(count: int) -> str:
    """About ``count`` lines: chunks of a while loop calling a
    subroutine, a repeat loop, an if/elseif/else and expressions."""
    out = OWORD_HEAD.splitlines()
    k = 0
    while len(out) < count - 12:
        n = 1000 + k
        out += [
            "#<i> = 0",
            f"o{n} while [#<i> LT 2]",
            f"  o<ring> call [{k % 50} + #<i> * 3] [2 + #<i>]",
            "  #<i> = [#<i> + 1]",
            f"o{n} endwhile",
            f"o{n + 50000} repeat [2]",
            f"  G1 X[#<_value> / 36 + {k % 7}] Y[FIX[{k} / 3] MOD 20]",
            f"o{n + 50000} endrepeat",
            f"o{n + 100000} if [{k} MOD 3 EQ 0]",
            "  G0 Z[ABS[#<_depth>] + 1]",
            f"o{n + 100000} elseif [{k} MOD 3 EQ 1]",
            f"  G1 Z[#<_depth> * 2] F[600 + {k % 10} * 10]",
            f"o{n + 100000} else",
            f"  G1 X[SQRT[{k % 97 + 1}]] Y[ATAN[{k % 13}]/[7]]",
            f"o{n + 100000} endif",
        ]
        k += 1
    out.append("M2")
    return "\n".join(out) + "\n"


def program_big(count: int, path: str) -> None:
    """``count`` lines of program_lines' kind, written in pieces."""
    with open(path, "w", encoding="ascii") as f:
        f.write("G21 G90 G17 G94\nF1500\nG0 X0 Y0 Z5\nG1 Z0\n")
        row = 400
        for i in range(count - 5):
            r, c = divmod(i, row)
            x = (c if r % 2 == 0 else row - 1 - c) * 0.05
            f.write(f"G1 X{x:.4f} Y{r * 0.5:.4f} Z{-1 - (i % 7) * 0.01:.4f}"
                    "\n")
        f.write("M2\n")


# ------------------------------------------------------------ ours

#: one run of ours, in a fresh process: prints one JSON line
OURS = r'''
import json, resource, sys, time
mode, path, tracing = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
from halsdk.gcode import Parameters, Program
from halsdk.gcode.canon import Canon, RecordingCanon, StraightFeed, \
    StraightTraverse, ArcFeed
from halsdk.gcode.interp import Interpreter

def peak_rss():
    """VmHWM: the peak resident set of this process since its exec, in
    kB (ru_maxrss would also count the parent's at the fork)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss

class Discard(Canon):
    """Drops the commands; notes when the first motion came."""
    first = None
    def emit(self, command):
        if self.first is None and isinstance(
                command, (StraightFeed, StraightTraverse, ArcFeed)):
            self.first = time.perf_counter()

if mode == "baseline":
    print(json.dumps({"rss": peak_rss()}))
    sys.exit()
if tracing:
    import tracemalloc
    tracemalloc.start()
canon = RecordingCanon() if mode == "record" else Discard()
c0 = time.process_time()
t0 = time.perf_counter()
params = Parameters()
interp = Interpreter(params, None, canon)
if mode == "whole":
    with open(path, encoding="utf-8") as f:
        program = Program(f.read(), path, params)
else:
    program = Program.from_file(path, params)
interp.run(program)
wall = time.perf_counter() - t0
res = {"wall": wall, "cpu": time.process_time() - c0,
       "rss": peak_rss(),
       "first": None if getattr(canon, "first", None) is None
       else canon.first - t0}
if tracing:
    res["traced"] = tracemalloc.get_traced_memory()[1]
print(json.dumps(res))
'''

#: the reference's runs, inside one call of the reference tool
TIMER = r'''
import json, os, subprocess, sys, time
n, progs = int(sys.argv[1]), sys.argv[2:]
res = {}
for prog in progs:
    walls, cpus, rss = [], [], 0
    for _ in range(n + 1):                 # the first one warms the cache
        t0 = time.perf_counter()
        p = subprocess.Popen(["rs274", "-g", prog], stdin=subprocess.DEVNULL,
                             stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE)
        _, status, usage = os.wait4(p.pid, 0)
        walls.append(time.perf_counter() - t0)
        cpus.append(usage.ru_utime + usage.ru_stime)
        err = p.stderr.read().decode(errors="replace")
        if status != 0:
            sys.stderr.write(f"rs274 -g {prog}: status {status}\n{err}")
            sys.exit(1)
        rss = max(rss, usage.ru_maxrss)
    res[prog] = {"wall": min(walls[1:]), "cpu": min(cpus[1:]), "rss": rss}
print(json.dumps(res))
'''


def run_ours(mode: str, path: str, tracing: bool = False) -> dict:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    out = subprocess.run([sys.executable, "-c", OURS, mode, path,
                          "1" if tracing else "0"], env=env, check=True,
                         capture_output=True, text=True, timeout=3600,
                         cwd=os.path.dirname(path)).stdout
    return json.loads(out.splitlines()[-1])


def best(runs: list[dict]) -> dict:
    """The best of several runs: the least time, the largest memory."""
    return {"wall": min(r["wall"] for r in runs),
            "cpu": min(r["cpu"] for r in runs),
            "rss": max(r["rss"] for r in runs)}


def run_reference(folder: str, names: list[str], repeat: int) -> dict:
    out = timed([REFERENCE_TOOL, "python3", "timer.py", str(repeat),
                 *names], folder)[1]
    return json.loads(out.splitlines()[-1])


# ------------------------------------------------------------ output

def _lps(lines: int, wall: float) -> str:
    return f"{lines / wall:,.0f}"


def _mb(kib: float) -> str:
    return f"{kib / 1024:.1f}"


def table(rows: list[list[str]], markdown: bool) -> str:
    head = ["program", "lines", "run", "wall s", "CPU s", "lines/s (CPU)",
            "peak RSS MB", "tracemalloc MB", "speed vs ref (CPU)",
            "RSS vs ref"]
    if markdown:
        out = ["| " + " | ".join(head) + " |",
               "|" + "|".join("---" if i < 3 else "--:"
                              for i in range(len(head))) + "|"]
        out += ["| " + " | ".join(r) + " |" for r in rows]
        return "\n".join(out)
    widths = [max(len(r[i]) for r in [head] + rows) for i in range(len(head))]
    return "\n".join("  ".join(c.rjust(w) if i >= 3 else c.ljust(w)
                               for i, (c, w) in enumerate(zip(r, widths)))
                     for r in [head] + rows)


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_repeat(p, 3, "runs of each measurement; the best is shown")
    add_no_reference(p)
    p.add_argument("--lines", type=int, default=100_000,
                   help="lines of the lines and arcs programs "
                   "(default 100000)")
    p.add_argument("--owords", type=int, default=10_000,
                   help="lines of the o-word program (default 10000)")
    p.add_argument("--big", type=int, default=1_000_000,
                   help="lines of the long streamed program; 0 skips it "
                   "(default 1000000)")
    p.add_argument("--markdown", action="store_true",
                   help="print the table in Markdown (docs/benchmarks.md)")
    p.add_argument("--keep", metavar="DIR",
                   help="also copy the generated programs to DIR")
    a = p.parse_args(argv)
    use_ref = use_reference(not a.no_reference, REFERENCE_RS274)
    texts = {"lines": program_lines(a.lines), "arcs": program_arcs(a.lines),
             "owords": program_owords(a.owords)}
    files = {f"{k}.ngc": v for k, v in texts.items()}
    files["timer.py"] = TIMER
    with run_folder("bench-gcode-", files) as folder:
        if a.keep:
            os.makedirs(a.keep, exist_ok=True)
            for name in files:
                shutil.copy(os.path.join(folder, name), a.keep)
        # one round after the other: in each, the reference runs every
        # program once (after a run that warms the file cache), then ours
        # runs it in every mode, so that a slower spell of a shared
        # machine falls on both
        refs: dict[str, list[dict]] = {}
        ours: dict[tuple[str, str], list[dict]] = {}
        for _ in range(a.repeat):
            if use_ref:
                for prog, r in run_reference(folder, list(files)[:3],
                                             1).items():
                    refs.setdefault(prog, []).append(r)
            for name in texts:
                path = os.path.join(folder, name + ".ngc")
                for mode in MODES:
                    ours.setdefault((name, mode), []).append(
                        run_ours(mode, path))
        ref = {prog: best(runs) for prog, runs in refs.items()}
        base = run_ours("baseline", os.path.join(folder, "lines.ngc"))
        rows = []
        for name, text in texts.items():
            count = text.count("\n")
            path = os.path.join(folder, name + ".ngc")
            theirs = ref.get(name + ".ngc")
            if theirs:
                rows.append([name, f"{count:,}", "reference rs274 -g",
                             f"{theirs['wall']:.3f}", f"{theirs['cpu']:.3f}",
                             _lps(count, theirs["cpu"]),
                             _mb(theirs["rss"]), "", "", ""])
            for mode in MODES:
                r = best(ours[(name, mode)])
                r["traced"] = run_ours(mode, path, tracing=True)["traced"]
                rows.append([
                    name, f"{count:,}", f"ours {mode}", f"{r['wall']:.3f}",
                    f"{r['cpu']:.3f}", _lps(count, r["cpu"]), _mb(r["rss"]),
                    f"{r['traced'] / 2**20:.1f}",
                    f"{theirs['cpu'] / r['cpu']:.2f}" if theirs else "",
                    f"{r['rss'] / theirs['rss']:.2f}" if theirs else ""])
        rows.append(["baseline", "", "ours: Python + import", "", "", "",
                     _mb(base["rss"]), "", "", ""])
        big = None
        if a.big:
            path = os.path.join(folder, "big.ngc")
            program_big(a.big, path)
            big = run_ours("stream", path)
            big["traced"] = run_ours("stream", path, tracing=True)["traced"]
            big["size"] = os.path.getsize(path)
    print(f"G-code interpreter, {datetime.date.today()}, "
          f"{platform.node()}, Python {platform.python_version()}, "
          f"load {os.getloadavg()[0]:.2f}; best of {a.repeat}")
    print(table(rows, a.markdown))
    if not use_ref:
        print("reference: not installed or disabled; no ratio")
    if big is not None:
        print(f"\nlong program: {a.big:,} lines ({big['size'] / 2**20:.0f} "
              f"MB) streamed: first motion after {big['first']:.3f} s, "
              f"run {big['wall']:.1f} s ({a.big / big['wall']:,.0f} "
              f"lines/s), peak RSS {_mb(big['rss'])} MB, tracemalloc peak "
              f"{big['traced'] / 2**20:.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
