#!/usr/bin/env python3
"""A three-axis stepper machine: CPU per second and base-thread jitter,
ours and the reference's.

The most common LinuxCNC machine, laid out as the reference's stepper
configurations are (one HAL file, run the same way by our ``halrun`` and,
when LinuxCNC 2.9 is installed, by the reference's, through the project's
``reference`` tool, in the same run of this script):

* motion (``trivkins``, ``homemod``, ``tpmod``, ``motmod`` with
  ``base_period_nsec=25000 servo_period_nsec=1000000``), which makes the
  two threads ``base-thread`` (25 us) and ``servo-thread`` (1 ms);
* base thread: ``timedelta.0`` (first: it measures the thread's
  jitter), ``encoder.update-counters`` (one channel),
  ``stepgen.make-pulses`` (three channels, step type 0, velocity mode),
  ``pwmgen.make-pulses`` (one channel, the spindle);
* servo thread: ``timedelta.1``, ``stepgen.capture-position``,
  ``encoder.capture-position``, ``motion-command-handler``,
  ``motion-controller``, ``siggen.N.update`` (three), three
  ``pid.N.do-pid-calcs`` (command in, ``stepgen.N.position-fb`` as
  feedback, output to ``stepgen.N.velocity-cmd``: the closed loop of a
  velocity-mode software stepgen), ``stepgen.update-freq``,
  ``pwmgen.update`` and the spindle glue: ``scale`` (spindle speed to
  the PWM command), ``near`` (spindle at speed, to
  ``spindle.0.at-speed``) and ``lowpass`` (the displayed spindle speed).

The joints' positions go to motion as its feedback
(``joint.N.motor-pos-fb``), the spindle encoder's to
``spindle.0.revs``/``speed-in``/``index-enable``, as in a machine.  The
reference's motion cannot be commanded without its task and NML layers,
so, as in ``bench/motion.py``, motion runs idle (not enabled) and three
``siggen`` sines (1 to 3 Hz, 5 mm at 200 steps/mm: up to 19 kHz of step
rate) stand in for the program: they command the pids, so the stepgens
step as when the machine moves.  The spindle encoder counts the X
stepgen's step pulses (counter mode): its counting runs as with a
spindle turning.  There is no parallel port (no hardware): its read and
write functions would cost the same on both sides.

Figures, per program, over ``--seconds`` after ``--warmup`` (the
timedeltas are reset at the start of the measurement):

* **CPU per second**: CPU time (user + system, all threads) of the
  process that runs the threads (ours: ``halrun``; the reference: its
  ``rtapi_app``) per second of wall time, in ms/s (1000 = one core);
* **base cycles per second**: the base thread's runs (a
  ``threadtest.0.increment`` in it) over the measurement; a thread that
  wakes late may run its missed cycles back to back (the reference) or
  skip them (ours), so this shows whether both sides did the same work,
  and **CPU per base cycle** the CPU per second over it;
* **wake-ups per second**: voluntary context switches of the process's
  threads per second (each sleep until the next cycle is one): the
  kernel's cost of a wake-up, not the functions, dominates the CPU;
* **base max jitter**: ``timedelta.0.jitter``, the largest deviation of
  an interval between two runs of the base thread from its period;
  also ``timedelta.0.max`` (the longest interval) and the servo
  thread's jitter;
* **base in-cycle**: the base thread's own time of a cycle (its
  ``base-thread.time``, read 20 times; the reference counts CPU clocks,
  converted with the CPU clock of /proc/cpuinfo), median.

Each side runs ``--repeat`` times, alternating (ours with realtime
scheduling when it may and with normal scheduling, ``--sched``); the
table shows the median (and the largest jitter of the runs).  The
scheduling each side got (SCHED_FIFO or normal) is read from /proc; the
ratio and the goals compare our runs under the scheduling the reference
got (the reference's rtapi_app, run as an unprivileged user by the
reference tool, gets normal scheduling).  Goals (issue 21): total CPU at
most 0.8x the reference's, base max jitter no worse.

Run: ``python bench/stepper_machine.py [--seconds 5] [--repeat 3]
[--warmup 1] [--sched both] [--no-reference] [--keep FILE]``.
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
    add_keep,
    add_no_reference,
    add_thread_runs,
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

BASE = 25_000
SERVO = 1_000_000
READS = 20
RESET_HOLD = 0.1
#: read at the end, in this order
FINAL = ("timedelta.0.jitter", "timedelta.0.max", "timedelta.1.jitter")
SCALE = 200.0       # steps per mm
AMPLITUDE = 5.0     # mm
FREQUENCIES = (1.0, 2.0, 3.0)


def machine_lines() -> list[str]:
    """The machine's HAL lines (loadrt, setp, net, addf), no start."""
    n = 3
    lines = [
        "# a three-axis stepper machine (bench/stepper_machine.py)",
        "loadrt trivkins coordinates=xyz",
        "loadrt homemod",
        "loadrt tpmod",
        f"loadrt motmod base_period_nsec={BASE} "
        f"servo_period_nsec={SERVO} num_joints={n}",
        "loadrt stepgen step_type=0,0,0 ctrl_type=v,v,v",
        "loadrt encoder num_chan=1",
        "loadrt pwmgen output_type=0",
        f"loadrt pid num_chan={n}",
        f"loadrt siggen num_chan={n}",
        "loadrt scale count=1",
        "loadrt near count=1",
        "loadrt lowpass count=1",
        "loadrt timedelta count=2",
        "loadrt threadtest count=1",
        "",
        "# base thread",
        "addf timedelta.0 base-thread",
        "addf threadtest.0.increment base-thread",
        "addf encoder.update-counters base-thread",
        "addf stepgen.make-pulses base-thread",
        "addf pwmgen.make-pulses base-thread",
        "",
        "# servo thread",
        "addf timedelta.1 servo-thread",
        "addf stepgen.capture-position servo-thread",
        "addf encoder.capture-position servo-thread",
        "addf motion-command-handler servo-thread",
        "addf motion-controller servo-thread",
    ]
    lines += [f"addf siggen.{i}.update servo-thread" for i in range(n)]
    lines += [f"addf pid.{i}.do-pid-calcs servo-thread" for i in range(n)]
    lines += [
        "addf stepgen.update-freq servo-thread",
        "addf scale.0 servo-thread",
        "addf pwmgen.update servo-thread",
        "addf near.0 servo-thread",
        "addf lowpass.0 servo-thread",
    ]
    for i, axis in enumerate("xyz"):
        lines += [
            "",
            f"# joint {i} ({axis.upper()})",
            f"setp siggen.{i}.frequency {FREQUENCIES[i]}",
            f"setp siggen.{i}.amplitude {AMPLITUDE}",
            f"setp stepgen.{i}.position-scale {SCALE}",
            f"setp stepgen.{i}.steplen 1",
            f"setp stepgen.{i}.stepspace 0",
            f"setp stepgen.{i}.dirhold 35000",
            f"setp stepgen.{i}.dirsetup 35000",
            f"setp stepgen.{i}.maxaccel 2500",
            f"setp stepgen.{i}.maxvel 120",
            f"setp pid.{i}.Pgain 1000",
            f"setp pid.{i}.Igain 0",
            f"setp pid.{i}.Dgain 0",
            f"setp pid.{i}.FF1 1",
            f"setp pid.{i}.maxoutput 120",
            f"setp pid.{i}.deadband {0.5 / SCALE}",
            f"setp pid.{i}.enable 1",
            f"setp stepgen.{i}.enable 1",
            f"net {axis}-pos-cmd siggen.{i}.sine => pid.{i}.command",
            f"net {axis}-pos-fb stepgen.{i}.position-fb => "
            f"pid.{i}.feedback joint.{i}.motor-pos-fb",
            f"net {axis}-output pid.{i}.output => stepgen.{i}.velocity-cmd",
            f"net {axis}-step stepgen.{i}.step"
            + (" => encoder.0.phase-A" if i == 0 else ""),
            f"net {axis}-dir stepgen.{i}.dir",
        ]
    lines += [
        "",
        "# spindle: PWM out, encoder back, at-speed",
        "setp pwmgen.0.scale 3000",
        "setp pwmgen.0.pwm-freq 100",
        "setp pwmgen.0.dither-pwm 1",
        "setp pwmgen.0.enable 1",
        "setp scale.0.gain 1",
        "setp encoder.0.counter-mode 1",
        "setp encoder.0.position-scale 400",
        "setp near.0.scale 1.1",
        "setp near.0.difference 10",
        "setp lowpass.0.gain 0.01",
        "net spindle-cmd-rpm scale.0.out => pwmgen.0.value near.0.in1",
        "net spindle-revs encoder.0.position => spindle.0.revs",
        "net spindle-rps encoder.0.velocity => spindle.0.speed-in "
        "lowpass.0.in near.0.in2",
        "net spindle-index encoder.0.index-enable <=> spindle.0.index-enable",
        "net spindle-at-speed near.0.out => spindle.0.at-speed",
        "net spindle-filtered lowpass.0.out",
        "",
    ]
    # scale.0.in is the commanded speed (not connected: the reference's
    # spindle.0.speed-out is 0 without its task)
    lines += ["setp scale.0.in 1000"]
    return lines


def hal_text(hold: str, warmup: float) -> str:
    lines = machine_lines() + [
        "start",
        f"loadusr -w sleep {warmup}",
        "setp timedelta.0.reset 1", "setp timedelta.1.reset 1",
        f"loadusr -w sleep {RESET_HOLD}",
        "setp timedelta.0.reset 0", "setp timedelta.1.reset 0",
        "getp threadtest.0.count",
        f"loadusr -w sleep {hold}",
        "getp threadtest.0.count",
    ]
    lines += ["loadusr -w sleep 0.05", "getp base-thread.time"] * READS
    lines += [f"getp {pin}" for pin in FINAL]
    lines += ["getp stepgen.0.counts", "stop", ""]
    return "\n".join(lines)


@dataclass
class Run:
    cpu_ms_per_s: float         # CPU ms per wall s of the host process
    in_cycle_ns: float          # median base-thread time per cycle
    jitter: int                 # timedelta.0.jitter (ns)
    max_interval: int           # timedelta.0.max (ns)
    servo_jitter: int           # timedelta.1.jitter (ns)
    counts: int                 # stepgen.0.counts at the end (it moved)
    sched: str                  # SCHED_FIFO or normal
    base_hz: float              # base-thread cycles per second
    wakeups_per_s: float        # voluntary context switches per second

    @property
    def cpu_per_cycle_us(self) -> float:
        """CPU per base cycle (all threads' CPU over the base cycles)."""
        return self.cpu_ms_per_s * 1e3 / self.base_hz if self.base_hz \
            else 0.0


def scheduling(pid: int) -> str:
    """SCHED_FIFO when a thread of ``pid`` runs with it (its realtime
    threads), else normal."""
    try:
        tids = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return "?"
    for tid in tids:
        try:
            with open(f"/proc/{pid}/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        # field 41 (policy) is fields[38]: 1 SCHED_FIFO, 2 SCHED_RR
        if len(fields) > 38 and fields[38] in ("1", "2"):
            return "SCHED_FIFO" if fields[38] == "1" else "SCHED_RR"
    return "normal"


def wakeups(pid: int) -> int:
    """Voluntary context switches of all the threads of ``pid`` (each
    sleep of a thread until its next cycle is one)."""
    total = 0
    try:
        tids = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return 0
    for tid in tids:
        try:
            with open(f"/proc/{pid}/task/{tid}/status") as f:
                for line in f:
                    if line.startswith("voluntary_ctxt_switches:"):
                        total += int(line.split()[1])
        except (OSError, ValueError):
            continue
    return total




#: our halrun with ``start`` under normal scheduling (as the reference's
#: rtapi_app runs when it may not use realtime scheduling)
NORMAL_HALRUN = """\
import sys
import halsdk.hal
from halsdk.halcmd.cli import main
start = halsdk.hal.Hal.start
halsdk.hal.Hal.start = lambda self, realtime=True: start(self, False)
sys.exit(main(sys.argv[1:]))
"""


def run_once(seconds: float, warmup: float, reference: bool,
             realtime: bool = True) -> Run:
    """Run the machine's HAL file and sample the process that runs its
    threads for ``seconds`` (ours with realtime scheduling when it may,
    or with normal scheduling)."""
    hold = f"{seconds + 1:.0f}.{os.getpid() % 100000:05d}"
    env = dict(os.environ)
    if reference:
        # the system PATH: a halsdk venv first on PATH would give the
        # reference's user our halrun
        env["PATH"] = "/usr/sbin:/usr/bin:/sbin:/bin"
        cmd = [REFERENCE_TOOL, "halrun", "-f", "machine.hal"]
    else:
        env["HALSDK_INSTANCE"] = f"benchstepper-{os.getpid()}"
        cmd = [sys.executable, *(("-m", "halsdk.halcmd.cli") if realtime
                                 else ("-c", NORMAL_HALRUN)),
               "halrun", "-f", "machine.hal"]
    with run_folder("halsdk-bench-stepper-",
                    {"machine.hal": hal_text(hold, warmup)}) as folder, \
            tempfile.TemporaryFile("w+") as log, \
            session(cmd, cwd=folder, stdout=log, stderr=subprocess.STDOUT,
                    env=env) as proc:
        host = wait_host(proc, log, hold,
                         our_rtapi_app if reference else None,
                         "reference" if reference else "ours")
        sched = scheduling(host)
        t0, c0, w0 = time.monotonic(), process_cpu(host), wakeups(host)
        time.sleep(seconds)
        t1, c1, w1 = time.monotonic(), process_cpu(host), wakeups(host)
        proc.wait(timeout=seconds + 60)
        log.seek(0)
        out = log.read()
    values = [int(x) for x in out.split() if x.lstrip("-").isdigit()]
    if proc.returncode != 0 or len(values) < READS + len(FINAL) + 3:
        raise RuntimeError("unexpected output ("
                           + ("reference" if reference else "ours")
                           + f", exit {proc.returncode}):\n" + out[-3000:])
    tail = READS + len(FINAL) + 1
    before, after = values[-tail - 2:-tail]
    # the reference's thread time is in CPU clocks
    mhz = (tsc_mhz() or 1000.0) if reference else 1000.0
    times = [v * 1000 / mhz for v in values[-tail:-(len(FINAL) + 1)]]
    jitter, max_interval, servo_jitter, counts = values[-len(FINAL) - 1:]
    return Run((c1 - c0) * 1e3 / (t1 - t0), statistics.median(times),
               jitter, max_interval, servo_jitter, counts, sched,
               ((after - before) % 2**32) / float(hold),
               (w1 - w0) / (t1 - t0))


def run_reference(seconds: float, warmup: float) -> Run:
    with reference_lock():
        deadline = time.monotonic() + 120
        while rtapi_apps() and time.monotonic() < deadline:
            time.sleep(0.5)
        return run_once(seconds, warmup, True)


# ------------------------------------------------------------ report

def med(runs: list[Run], attr: str) -> Optional[float]:
    return statistics.median(getattr(r, attr) for r in runs) if runs \
        else None


def cell(runs: list[Run], attr: str, spec: str, worst: bool) -> str:
    if not runs:
        return "-"
    text = format(med(runs, attr), spec)
    if worst and len(runs) > 1:
        text += f" (max {max(getattr(r, attr) for r in runs):{spec}})"
    return text


def ratio(ours: list[Run], ref: list[Run], attr: str) -> str:
    a, b = med(ours, attr), med(ref, attr)
    return "-" if a is None or not b else f"{a / b:.2f}"


def same_side(ours: dict[str, list[Run]], ref: list[Run]) -> list[Run]:
    """Our runs under the scheduling the reference got (the normal ones
    when it ran without realtime)."""
    normal = bool(ref) and all(r.sched == "normal" for r in ref)
    if normal and ours["normal"]:
        return ours["normal"]
    return ours["realtime"] or ours["normal"]


def report(a: argparse.Namespace, ours: dict[str, list[Run]],
           ref: list[Run]) -> None:
    print(f"\nstepper machine: base thread {BASE} ns (timedelta, encoder, "
          f"3 stepgens, pwmgen), servo thread {SERVO} ns (motion, 3 pids, "
          f"glue);\n{a.seconds:g} s per run after {a.warmup:g} s warm-up, "
          f"{a.repeat} run(s) per side, alternating; median")
    sides = [(k, v) for k, v in ours.items() if v]
    for k, v in sides:
        print(f"ours {k}: got " + ", ".join(sorted({r.sched for r in v})))
    print("reference: " + ("got " + ", ".join(sorted({r.sched for r in ref}))
                           if ref else "not run"))
    mine = same_side(ours, ref)
    rows = [("", *(f"ours {k}" for k, _ in sides), "reference",
             "ours/ref")]
    for label, attr, spec, worst in (
            ("CPU per second (ms/s)", "cpu_ms_per_s", ".1f", False),
            ("base cycles per second", "base_hz", ".0f", False),
            ("CPU per base cycle (us)", "cpu_per_cycle_us", ".2f", False),
            ("wake-ups per second", "wakeups_per_s", ".0f", False),
            ("base in-cycle (ns)", "in_cycle_ns", ".0f", False),
            ("base max jitter (ns)", "jitter", ".0f", True),
            ("base max interval (ns)", "max_interval", ".0f", True),
            ("servo max jitter (ns)", "servo_jitter", ".0f", True)):
        rows.append((label, *(cell(v, attr, spec, worst) for _, v in sides),
                     cell(ref, attr, spec, worst), ratio(mine, ref, attr)))
    print()
    widths = [max(len(r[k]) for r in rows) for k in range(len(rows[0]))]
    for r in rows:
        print("  ".join([r[0].ljust(widths[0])]
                        + [c.rjust(w) for c, w in zip(r[1:], widths[1:])]))
    print("\n(the largest of the runs in brackets; X's position in steps "
          "at the end, to show it moved: "
          + "; ".join(f"ours {k} " + ", ".join(str(r.counts) for r in v)
                      for k, v in sides)
          + ("; reference " + ", ".join(str(r.counts) for r in ref)
             if ref else "") + ")")
    if ref:
        print(f"ours/ref: ours {mine[0].sched} (the reference's scheduling "
              "when we have it) over the reference")
        x = statistics.median(r.cpu_ms_per_s for r in mine)
        y = statistics.median(r.cpu_ms_per_s for r in ref)
        print(f"goal (total CPU <= 0.8 x the reference's): "
              f"{'met' if x <= 0.8 * y else 'MISSED'} (ratio {x / y:.2f})")
        x = statistics.median(r.jitter for r in mine)
        y = statistics.median(r.jitter for r in ref)
        print(f"goal (base max jitter no worse than the reference's): "
              f"{'met' if x <= y else 'MISSED'} (ratio {x / y:.2f})")


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_thread_runs(p, "our threads")
    add_no_reference(p)
    add_keep(p)
    a = p.parse_args(argv)
    if a.seconds <= 0 or a.warmup < 0:
        p.error("--seconds must be > 0, --warmup >= 0")
    if a.keep:
        with open(a.keep, "w", encoding="utf-8") as f:
            f.write("\n".join(machine_lines()) + "\n")
    with_ref = use_reference(not a.no_reference, REFERENCE_HALRUN)
    ours: dict[str, list[Run]] = {"realtime": [], "normal": []}
    ref: list[Run] = []
    for _ in range(a.repeat):
        for sched in ours:
            if a.sched in ("both", sched):
                ours[sched].append(run_once(a.seconds, a.warmup, False,
                                            sched == "realtime"))
        if with_ref:
            ref.append(run_reference(a.seconds, a.warmup))
    report(a, ours, ref)
    return 0


if __name__ == "__main__":
    sys.exit(main())
