#!/usr/bin/env python3
"""Cost per call of shipped components: pid, stepgen, encoder, pwmgen, siggen,
limit3.

Each case is one HAL file, run the same way by our ``halrun`` and, when
LinuxCNC 2.9 is installed, by the reference's (through the project's
``reference`` tool), in the same run of this script:

============  ==============================================================
case          configuration
============  ==============================================================
pid           16 x ``pid.N.do-pid-calcs`` (gains, limits, moving command)
              in a 1 kHz thread
stepgen       16 channels, ``stepgen.make-pulses`` in a 25 us base thread
              (velocity mode, stepping), ``update-freq`` and
              ``capture-position`` in a 1 kHz thread
encoder       8 channels, ``encoder.update-counters`` and
              ``encoder.capture-position`` in a 1 kHz thread
pwmgen        8 channels of PWM at 1 kHz, ``pwmgen.make-pulses`` in a
              25 us base thread, ``pwmgen.update`` in a 1 kHz thread
siggen        16 x ``siggen.N.update`` in a 1 kHz thread
limit3        16 x ``limit3.N`` (a moving target) in a 1 kHz thread
============  ==============================================================

Every case also runs with the same threads and no function (its "empty"
variant).  Two figures per case and program:

* **in-cycle ns per call**: the measured thread's own time of a cycle
  (its ``<thread>.time`` pin, read 20 times; the reference counts CPU
  clocks, converted with the CPU clock of /proc/cpuinfo), median, minus
  the same for the empty variant, divided by the calls per cycle;
* **CPU ns per call** (with ``--cpu``): CPU time of the process that
  runs the threads (ours: ``halrun``; the reference: ``rtapi_app``) per
  cycle of the measured thread over a few seconds, minus the empty
  variant's, over the calls per cycle.  It includes the cost of waking
  up, which at 16 calls per cycle is far larger than the calls
  themselves: on a VM these figures are noise (even negative).

The ratio is ours / reference (goal: no component slower than the
reference, i.e. at most 1.00).

Run: ``python bench/components.py [--seconds 3] [--repeat 1]
[--cases pid,stepgen] [--no-reference]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from typing import Optional

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import (  # noqa: E402
    REFERENCE_HALRUN,
    REFERENCE_TOOL,
    add_no_reference,
    add_repeat,
    reference_lock,
    run_folder,
    session,
    use_reference,
    wait_host,
)
from thread_overhead import (  # noqa: E402
    our_rtapi_app,
    process_cpu,
    rtapi_apps,
    tsc_mhz,
)

SERVO = 1_000_000
BASE = 25_000
READS = 20


@dataclass
class Case:
    name: str
    threads: list[str]          # HAL lines that make the threads
    load: list[str]             # loadrt/setp/addf lines of the loaded run
    thread: str                 # the thread whose cycles are counted
    period: int
    calls: int                  # calls per cycle of that thread
    note: str


def _servo() -> list[str]:
    return [f"loadrt threads name1=servo period1={SERVO}"]


def cases() -> list[Case]:
    n = 16
    pid = [f"loadrt pid num_chan={n}"]
    for i in range(n):
        pid += [f"setp pid.{i}.Pgain 50", f"setp pid.{i}.Igain 2",
                f"setp pid.{i}.Dgain 0.1", f"setp pid.{i}.FF1 1",
                f"setp pid.{i}.maxoutput 100", f"setp pid.{i}.deadband 0.001",
                f"setp pid.{i}.command {i + 1}", f"setp pid.{i}.enable 1",
                f"addf pid.{i}.do-pid-calcs servo"]
    steps = ["loadrt stepgen step_type=" + ",".join(["0"] * n)
             + " ctrl_type=" + ",".join(["v"] * n)]
    for i in range(n):
        steps += [f"setp stepgen.{i}.position-scale 1000",
                  f"setp stepgen.{i}.maxaccel 0",
                  f"setp stepgen.{i}.velocity-cmd {2 + i % 5}",
                  f"setp stepgen.{i}.enable 1"]
    steps += ["addf stepgen.make-pulses base",
              "addf stepgen.update-freq servo",
              "addf stepgen.capture-position servo"]
    enc = ["loadrt encoder num_chan=8",
           "addf encoder.update-counters servo",
           "addf encoder.capture-position servo"]
    enc += [f"setp encoder.{i}.position-scale 4" for i in range(8)]
    pwm = ["loadrt pwmgen output_type=" + ",".join(["0"] * 8)]
    for i in range(8):
        pwm += [f"setp pwmgen.{i}.pwm-freq 1000",
                f"setp pwmgen.{i}.value {0.10 + 0.05 * i:.2f}",
                f"setp pwmgen.{i}.enable 1"]
    pwm += ["addf pwmgen.make-pulses base", "addf pwmgen.update servo"]
    sig = [f"loadrt siggen num_chan={n}"]
    sig += [f"setp siggen.{i}.frequency {i + 1}" for i in range(n)]
    sig += [f"addf siggen.{i}.update servo" for i in range(n)]
    lim = [f"loadrt limit3 count={n}"]
    for i in range(n):
        lim += [f"setp limit3.{i}.maxv 10", f"setp limit3.{i}.maxa 100",
                f"setp limit3.{i}.min -1000", f"setp limit3.{i}.max 1000",
                f"setp limit3.{i}.in {100 + i}", f"addf limit3.{i} servo"]
    return [
        Case("pid", _servo(), pid, "servo", SERVO, n,
             f"{n} x do-pid-calcs"),
        Case("stepgen",
             [f"loadrt threads name1=base period1={BASE} "
              f"name2=servo period2={SERVO}"],
             steps, "base", BASE, n,
             f"make-pulses, {n} channels (per channel; the 1 kHz "
             "update-freq and capture-position included)"),
        Case("encoder", _servo(), enc, "servo", SERVO, 8,
             "update-counters + capture-position, 8 channels (per "
             "channel)"),
        Case("pwmgen",
             [f"loadrt threads name1=base period1={BASE} "
              f"name2=servo period2={SERVO}"],
             pwm, "base", BASE, 8,
             "make-pulses, 8 channels of PWM at 1 kHz, duty 10 to 45 % "
             "(per channel; the 1 kHz update included)"),
        Case("siggen", _servo(), sig, "servo", SERVO, n,
             f"{n} x update"),
        Case("limit3", _servo(), lim, "servo", SERVO, n, f"{n} x limit3"),
    ]


@dataclass
class Result:
    cpu_per_cycle_ns: float
    in_cycle_ns: float


def hal_text(case: Case, loaded: bool, hold: str) -> str:
    lines = list(case.threads) + (case.load if loaded else [])
    lines += ["start", f"loadusr -w sleep {hold}"]
    lines += ["loadusr -w sleep 0.05", f"getp {case.thread}.time"] * READS
    lines += ["stop", ""]
    return "\n".join(lines)


def ours_command() -> list[str]:
    return [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-f",
            "bench.hal"]


def run_once(case: Case, loaded: bool, seconds: float, warmup: float,
             reference: bool) -> Result:
    """Run the case's HAL file and sample the process that runs its
    threads for ``seconds``, after ``warmup``."""
    hold = f"{warmup + seconds + 1:.0f}.{os.getpid() % 100000:05d}"
    env = dict(os.environ)
    if not reference:
        env["HALSDK_INSTANCE"] = f"benchcomp-{os.getpid()}"
    cmd = ([REFERENCE_TOOL, "halrun", "-f", "bench.hal"] if reference
           else ours_command())
    with run_folder("halsdk-bench-comp-",
                    {"bench.hal": hal_text(case, loaded, hold)}) as folder, \
            tempfile.TemporaryFile("w+") as log, \
            session(cmd, cwd=folder, stdout=log, stderr=subprocess.STDOUT,
                    env=env) as proc:
        host = wait_host(proc, log, hold,
                         our_rtapi_app if reference else None, case.name)
        time.sleep(warmup)
        t0, c0 = time.monotonic(), process_cpu(host)
        time.sleep(seconds)
        t1, c1 = time.monotonic(), process_cpu(host)
        cycles = (t1 - t0) * 1e9 / case.period
        proc.wait(timeout=warmup + seconds + 60)
        log.seek(0)
        values = [int(x) for x in log.read().split() if x.isdigit()]
        if reference:
            mhz = tsc_mhz() or 1000.0
            values = [v * 1000 / mhz for v in values]
        if proc.returncode != 0 or len(values) < READS // 2:
            raise RuntimeError(f"{case.name}: unexpected output")
        return Result((c1 - c0) * 1e9 / cycles, statistics.median(values))




def _run_locked(case: Case, loaded: bool, seconds: float, warmup: float,
                reference: bool) -> Result:
    if not reference:
        return run_once(case, loaded, seconds, warmup, False)
    with reference_lock():
        _wait_for_reference()
        return run_once(case, loaded, seconds, warmup, True)


def measure(case: Case, seconds: float, warmup: float, repeat: int,
            reference: bool) -> tuple[float, float]:
    """Median (over ``repeat``) ns per call: in-cycle and CPU."""
    in_cycle, cpu = [], []
    for _ in range(repeat):
        empty = _run_locked(case, False, seconds, warmup, reference)
        full = _run_locked(case, True, seconds, warmup, reference)
        in_cycle.append((full.in_cycle_ns - empty.in_cycle_ns) / case.calls)
        cpu.append((full.cpu_per_cycle_ns - empty.cpu_per_cycle_ns)
                   / case.calls)
    return statistics.median(in_cycle), statistics.median(cpu)


def _wait_for_reference() -> None:
    deadline = time.monotonic() + 120
    while rtapi_apps() and time.monotonic() < deadline:
        time.sleep(0.5)


def fmt(v: Optional[float]) -> str:
    return "-" if v is None else f"{v:.1f}"


def ratio(a: Optional[float], b: Optional[float]) -> str:
    return "-" if a is None or b is None or b <= 0 else f"{a / b:.2f}"


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=3.0,
                   help="length of each CPU measurement (default 3)")
    p.add_argument("--warmup", type=float, default=0.5)
    add_repeat(p, 1, "median of this many runs")
    p.add_argument("--cases", default="",
                   help="comma-separated subset of: pid, stepgen, "
                        "encoder, siggen, limit3")
    add_no_reference(p)
    p.add_argument("--cpu", action="store_true",
                   help="also print the CPU-time figures (with 16 calls "
                        "per cycle they drown in the wake-up cost; see "
                        "the module's docstring)")
    a = p.parse_args(argv)
    chosen = [c for c in cases()
              if not a.cases or c.name in a.cases.split(",")]
    if not chosen or a.seconds <= 0:
        p.error("nothing to run")
    with_ref = use_reference(not a.no_reference, REFERENCE_HALRUN)
    rows = []
    for case in chosen:
        ours = measure(case, a.seconds, a.warmup, a.repeat, False)
        ref = measure(case, a.seconds, a.warmup, a.repeat, True) \
            if with_ref else (None, None)
        rows.append((case, ours, ref))
    print(f"\ncost per call, ns ({a.seconds:g} s per CPU measurement, "
          f"median of {a.repeat}); ratio = ours / reference "
          "(goal: at most 1.00)\n")
    head = ("component", "in-cycle ours", "in-cycle ref", "ratio")
    table = [head] + [(c.name, fmt(o[0]), fmt(r[0]), ratio(o[0], r[0]))
                      for c, o, r in rows]
    if a.cpu:
        head += ("CPU ours", "CPU ref", "ratio")
        table = [head] + [row + (fmt(o[1]), fmt(r[1]), ratio(o[1], r[1]))
                          for row, (c, o, r) in zip(table[1:], rows)]
    widths = [max(len(row[i]) for row in table) for i in range(len(head))]
    for row in table:
        print("  ".join([row[0].ljust(widths[0])]
                        + [x.rjust(w) for x, w in zip(row[1:], widths[1:])]))
    print()
    for c, _, _ in rows:
        print(f"{c.name}: {c.note}")
    if with_ref:
        slower = [c.name for c, o, r in rows
                  if r[0] is not None and o[0] > r[0]]
        print("\ngoal (no component slower than the reference, in-cycle): "
              + ("met" if not slower else "MISSED for " + ", ".join(slower)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
