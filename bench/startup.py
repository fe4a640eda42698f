#!/usr/bin/env python3
"""Start-up of the command-line tools: ``halcmd getp`` and ``halrun -f``.

Two commands that shell scripts run over and over, timed as whole
programs (start-up, the work, tear-down):

* ``halcmd getp and2.0.in0`` against a running instance (a ``halrun``
  host that loaded ``and2`` and waits);
* ``halrun -f empty.hal``: create the instance, run an empty file,
  remove the instance.

Both programs are timed by one small timing script (``TIMER`` below,
standard library only) that runs each command ``--repeat`` times after one
warm-up run and prints the wall times.  Ours runs it directly, with our
``halcmd``/``halrun`` console scripts (those next to ``sys.executable``) on
a private instance; the reference runs the same script *inside* the
project's ``reference`` tool (``reference python3 timer.py``), with
``/usr/bin/halcmd`` and ``/usr/bin/halrun``.  The tool's own cost (``su``
to another user and a copy of the folder) is paid once for the whole loop,
so it is not in the reference's per-command figures: those are the
figures compared, ``ours / reference``.

For information the script also times, through the tool, ``reference
true`` and ``reference halrun -f empty.hal`` (one tool call per run), and
prints the latter with the former subtracted: it should agree with the
in-tool figure.

Byte code: ours is timed with compiled byte code (a ``.pyc`` cache, as an
installed package has): ``PYTHONDONTWRITEBYTECODE`` is removed from our
environment and the warm-up run writes the cache.  The script also prints
our ``python -X importtime`` top entries for ``import halsdk.halcmd.cli``
and the cost of the interpreter alone (``python -c pass``, ``python -S -c
pass``: the second one without ``site``, whose editable-install finder an
installed wheel does not have).

Run: ``python bench/startup.py [--repeat 20] [--no-reference]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from typing import Optional

from benchlib import (
    REFERENCE_HALRUN,
    REFERENCE_TOOL,
    RunError,
    add_no_reference,
    add_repeat,
    reference_lock,
    run_folder,
    timed,
    use_reference,
)

BUSY = "Realtime already running"
PIN = "and2.0.in0"
HOLD_HAL = f"loadrt and2\nsetp {PIN} 1\nloadusr -w ./wait_stop.sh\n"
WAIT_STOP = "#!/bin/sh\nwhile [ ! -e stop ]; do sleep 0.05; done\n"

#: the timing script, run by ours and (inside the reference tool) by the
#: reference; standard library only, prints one JSON line
TIMER = r'''
import json, os, signal, subprocess, sys, time

def run(cmd):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True,
                       text=True, timeout=120)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.stderr.write(f"{' '.join(cmd)} exited with {p.returncode}:\n"
                         + p.stdout + p.stderr)
        sys.exit(1)
    return wall, p.stdout

def loop(cmd, n):
    run(cmd)                                   # warm-up (writes .pyc)
    walls, out = [], ""
    for _ in range(n):
        wall, out = run(cmd)
        walls.append(wall)
    return walls, out

n, halrun, halcmd = int(sys.argv[1]), sys.argv[2], sys.argv[3]
if os.path.exists("stop"):      # left by an earlier run
    os.remove("stop")
res = {}
res["halrun"], _ = loop([halrun, "-f", "empty.hal"], n)
host = subprocess.Popen([halrun, "-f", "hold.hal"], stdin=subprocess.DEVNULL,
                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                        start_new_session=True, text=True)
try:
    deadline = time.monotonic() + 60
    while True:
        p = subprocess.run([halcmd, "getp", "PIN"], capture_output=True,
                           stdin=subprocess.DEVNULL, text=True)
        if p.returncode == 0 and p.stdout.strip():
            break
        if host.poll() is not None or time.monotonic() > deadline:
            sys.stderr.write("the host did not start:\n" + p.stdout
                             + p.stderr + (host.stdout.read()
                                           if host.poll() is not None
                                           else ""))
            sys.exit(1)
        time.sleep(0.1)
    res["halcmd"], res["getp"] = loop([halcmd, "getp", "PIN"], n)
finally:
    open("stop", "w").close()
    try:
        host.wait(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(host.pid, signal.SIGTERM)
        host.wait(timeout=10)
print(json.dumps(res))
'''.replace("PIN", PIN)

FILES = {"timer.py": TIMER, "empty.hal": "", "hold.hal": HOLD_HAL,
         "wait_stop.sh": WAIT_STOP}


def _bin(name: str) -> str:
    """Our console script ``name``, next to the interpreter."""
    path = os.path.join(os.path.dirname(sys.executable), name)
    if not os.access(path, os.X_OK):
        raise SystemExit(f"{path} not found: install halsdk in this "
                         "interpreter's environment (pip install -e .)")
    return path


def our_env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["HALSDK_INSTANCE"] = f"bench-startup-{os.getpid()}"
    return env


def time_ours(folder: str, repeat: int) -> dict:
    out = timed([sys.executable, "timer.py", str(repeat), _bin("halrun"),
                 _bin("halcmd")], folder, env=our_env())[1]
    return json.loads(out.splitlines()[-1])


def time_reference(folder: str, repeat: int,
                   retry_s: float = 300) -> dict:
    """The timer inside the reference tool; waits while another
    reference HAL runs on the machine."""
    deadline = time.monotonic() + retry_s
    while True:
        try:
            with reference_lock():
                out = timed([REFERENCE_TOOL, "python3", "timer.py",
                             str(repeat), "halrun", "halcmd"], folder)[1]
            return json.loads(out.splitlines()[-1])
        except RunError as e:
            if BUSY not in str(e) or time.monotonic() > deadline:
                raise
            time.sleep(2)


def time_through_tool(folder: str, repeat: int) -> dict[str, list[float]]:
    """One tool call per run: ``reference true`` and ``reference halrun
    -f empty.hal``."""
    res: dict[str, list[float]] = {"true": [], "halrun": []}
    with reference_lock():
        for _ in range(repeat):
            res["true"].append(timed([REFERENCE_TOOL, "true"], folder)[0])
            res["halrun"].append(timed([REFERENCE_TOOL, "halrun", "-f",
                                        "empty.hal"], folder)[0])
    return res


def interpreter(repeat: int) -> dict[str, float]:
    """Median wall time of the bare interpreter, with and without site."""
    res = {}
    for label, cmd in (("python -c pass", [sys.executable, "-c", "pass"]),
                       ("python -S -c pass",
                        [sys.executable, "-S", "-c", "pass"])):
        walls = [timed(cmd, "/tmp")[0] for _ in range(repeat)]
        res[label] = statistics.median(walls)
    return res


def importtime(top: int) -> list[str]:
    """Our ``-X importtime`` of ``import halsdk.halcmd.cli``: the total,
    ``site`` and the ``top`` modules by cumulative time (µs)."""
    env = our_env()
    cmd = [sys.executable, "-X", "importtime", "-c",
           "import halsdk.halcmd.cli"]
    subprocess.run(cmd, env=env, capture_output=True, check=True)  # .pyc
    err = subprocess.run(cmd, env=env, capture_output=True, text=True,
                         check=True).stderr
    rows = []
    for line in err.splitlines()[1:]:
        parts = line.split("|")
        if len(parts) != 3 or not parts[1].strip().isdigit():
            continue
        self_us = int(parts[0].split(":")[-1])
        rows.append((int(parts[1]), self_us, parts[2].rstrip()))
    rows.sort(reverse=True)
    lines = ["  cumulative    self  module (python -X importtime, µs)"]
    lines += [f"  {c:10d} {s:7d}  {n}" for c, s, n in rows[:top]]
    return lines


def _fmt(walls: list[float]) -> str:
    return (f"{statistics.median(walls) * 1e3:7.1f} ms  "
            f"({min(walls) * 1e3:.1f}..{max(walls) * 1e3:.1f})")


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_repeat(p, 20, "runs of each command; the median is printed")
    p.add_argument("--top", type=int, default=15,
                   help="importtime entries shown (default 15)")
    add_no_reference(p)
    a = p.parse_args(argv)
    use_ref = use_reference(not a.no_reference, REFERENCE_HALRUN)
    print(f"{a.repeat} run(s) per command after one warm-up; median "
          "(min..max) wall time")
    with run_folder("halsdk-bench-startup-", FILES) as mine, \
            run_folder("halsdk-bench-startup-", FILES) as theirs:
        for folder in (mine, theirs):
            os.chmod(os.path.join(folder, "wait_stop.sh"), 0o755)
        ours = time_ours(mine, a.repeat)
        ref = time_reference(theirs, a.repeat) if use_ref else None
        tool = time_through_tool(theirs, a.repeat) if use_ref else None
    cases = (("halcmd", f"halcmd getp {PIN} (running):"),
             ("halrun", "halrun -f empty.hal:"))
    width = max(len(label) for _, label in cases)
    for key, label in cases:
        print(f"ours       {label:<{width}} {_fmt(ours[key])}")
        if ref is not None:
            print(f"reference  {label:<{width}} {_fmt(ref[key])}")
    for label, wall in interpreter(a.repeat).items():
        print(f"ours       {label + ':':<{width}} {wall * 1e3:7.1f} ms")
    if ref is None or tool is None:
        print("reference: not installed or disabled; no ratio")
    else:
        if ours["getp"] != ref["getp"]:
            print(f"WARNING: getp output differs: ours {ours['getp']!r}, "
                  f"reference {ref['getp']!r}")
        med = {k: statistics.median(ours[k]) / statistics.median(ref[k])
               for k, _ in cases}
        for key, label in cases:
            print(f"ratio ours / reference, {label:<{width}} "
                  f"{med[key]:.2f}   (goal <= 1.0)")
        true_med = statistics.median(tool["true"])
        through = statistics.median(tool["halrun"])
        print(f"through the tool, one call per run: reference true "
              f"{true_med * 1e3:.1f} ms, reference halrun -f empty.hal "
              f"{through * 1e3:.1f} ms, difference "
              f"{(through - true_med) * 1e3:.1f} ms (for information; the "
              "in-tool figure above is compared)")
    print("\n".join(importtime(a.top)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
