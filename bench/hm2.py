#!/usr/bin/env python3
"""hm2_eth's servo-cycle exchange with a 7I96S: CPU per cycle, datagrams
per cycle and lost datagrams, ours and the reference's.

The configuration is the one of a 7I96S machine, reduced to the card's
exchange (the same HAL file for both, run by our ``halrun`` and by the
reference's, through the project's ``reference`` tool, in the same run of
this script)::

    loadrt hostmot2
    loadrt hm2_eth board_ip=10.96.7.2 \
        config="num_encoders=1 num_pwmgens=1 num_stepgens=5"
    loadrt threads name1=servo-thread period1=1000000
    addf hm2_7i96s.0.read servo-thread
    addf hm2_7i96s.0.write servo-thread
    start

Each cycle ``read`` sends one datagram of reads and waits for the card's
answer, ``write`` sends one datagram of writes.

The card is ``hm2-sim --board 7i96s`` at 10.96.7.2 in the network
namespace of tests/data/hm2 (``netns.sh up 7i96s``: a veth pair, the far
end carrying the card's MAC address), with realtime scheduling (``chrt
-f 20``).  The reference's ``hm2_eth`` needs that: it sets a static ARP
entry for the card, which the loopback interface refuses.  Ours reaches
the same card the same way (board_ip=10.96.7.2 across the veth pair), so
both sides take the same network path to the same simulated card; one
card serves every run.  This needs root (the namespace, and the
reference's hm2_eth adds an iptables jump at each load, which this script
removes again as tests/data/hm2/regen.sh does).

Figures, per run, over ``--seconds`` after ``--warmup``:

* **CPU per cycle**: CPU time (user + system, all threads) of the process
  that runs the servo thread (ours: ``halrun``; the reference: its
  ``rtapi_app``) over the cycles of the measurement (its wall time over
  the 1 ms period), in us;
* **wake-ups per cycle**: voluntary context switches of the process's
  threads per cycle (the sleep until the next cycle, and the wait for
  the card's answer, are one each when they sleep);
* **datagrams per cycle**: the datagrams the card received over the
  measurement (``hm2-sim``'s count) per cycle: 2 when every cycle ran
  and sent its read request and its write;
* **replies per cycle**: the card's answers;
* **packet errors**: ``packet-error-total`` at the end less at the start
  of the hold (a reply that did not come within ``packet-read-timeout``,
  80 % of the period, or a lost write); and whether the driver gave up
  (``io_error``).

Each side runs ``--repeat`` times, alternating (ours with realtime
scheduling and with normal scheduling, ``--sched``); the table shows the
median.  The ratio compares our runs under the scheduling the reference
got.  Goal (issue 23): no more CPU per cycle than the reference's.

Run (as root): ``python bench/hm2.py [--seconds 5] [--repeat 3]
[--warmup 1] [--sched both] [--no-reference] [--markdown]``.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Optional

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchlib import (  # noqa: E402
    REFERENCE_HALRUN,
    REFERENCE_TOOL,
    REPO,
    add_no_reference,
    add_thread_runs,
    reference_lock,
    run_folder,
    session,
    use_reference,
    wait_host,
)
from stepper_machine import (  # noqa: E402
    NORMAL_HALRUN,
    same_side,
    scheduling,
    wakeups,
)
from thread_overhead import our_rtapi_app, process_cpu, rtapi_apps  # noqa: E402

PERIOD = 1_000_000
CARD_IP = "10.96.7.2"
NETNS = "hm2sim"
NETNS_SH = os.path.join(REPO, "tests", "data", "hm2", "netns.sh")
CONFIG = "num_encoders=1 num_pwmgens=1 num_stepgens=5"
NAME = "hm2_7i96s.0"
CHAIN = "hm2-eth-rules-output"
#: the bench's watchdog (ns) and packet-error-limit, the same on both
#: sides: a servo thread held up for 5 ms (the default) on a busy
#: machine would make the card bite, and ten late answers close together
#: would stop the board; either would end the exchange being measured
WATCHDOG = 1_000_000_000
ERROR_LIMIT = 1_000_000_000
SYSTEM_PATH = "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"


def hal_text(hold: str, warmup: float) -> str:
    return "\n".join([
        "# hm2_eth against hm2-sim (bench/hm2.py)",
        "loadrt hostmot2",
        f'loadrt hm2_eth board_ip={CARD_IP} config="{CONFIG}"',
        f"loadrt threads name1=servo-thread period1={PERIOD}",
        f"addf {NAME}.read servo-thread",
        f"addf {NAME}.write servo-thread",
        # measure the exchange, whatever the load: a bite or too many
        # late answers would stop it (the late ones are counted)
        f"setp {NAME}.watchdog.timeout_ns {WATCHDOG}",
        f"setp {NAME}.packet-error-limit {ERROR_LIMIT}",
        "start",
        f"loadusr -w sleep {warmup}",
        f"getp {NAME}.packet-error-total",
        f"loadusr -w sleep {hold}",
        f"getp {NAME}.packet-error-total",
        f"getp {NAME}.io_error",
        "stop",
        "",
    ])


# ------------------------------------------------------------ the card

class Card:
    """``hm2-sim`` in the namespace, read through its ``--control``
    input: :meth:`stats` is its datagram counters."""

    def __init__(self) -> None:
        env = dict(os.environ, HM2SIM_PYTHON=sys.executable, PATH=SYSTEM_PATH)
        subprocess.run([NETNS_SH, "up", "7i96s"], env=env, check=True,
                       cwd="/tmp", capture_output=True, timeout=60)
        self.proc = subprocess.Popen(
            ["ip", "netns", "exec", NETNS, "chrt", "-f", "20",
             sys.executable, "-m", "halsdk.drivers.hm2sim", "--board",
             "7i96s", "--address", CARD_IP, "--control"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, text=True, cwd="/tmp", bufsize=1)
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        if "on UDP" not in line:
            self.close()
            raise RuntimeError(f"hm2-sim did not start: {line.strip()}")

    def stats(self) -> dict[str, int]:
        """The datagram counters, and ``bitten`` (1: the watchdog has
        bitten)."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write("status\n")
        self.proc.stdin.flush()
        found: dict[str, int] = {}
        for line in self.proc.stdout:
            if line.startswith("stats "):
                found.update((k, int(v)) for k, v in
                             re.findall(r"(\w+)=(\d+)", line))
            if line.startswith("watchdog "):
                found["bitten"] = int("bitten" in line)
            if line.startswith("pins "):
                return found
        raise RuntimeError("hm2-sim ended")

    def power_cycle(self) -> None:
        """Power the card off and on (its registers, the watchdog too, in
        their power-on state) before each run, on both sides.  Our
        hm2_eth does not stop the card's watchdog when it loads (the
        reference's writes timer 0x80000000 first): a watchdog still
        running from the last run (ours does not bite it when it unloads)
        or set to bite at once (the reference's does, timer 1) bites
        between the load and the first write, and the run would start
        bitten, without writes."""
        assert self.proc.stdin is not None
        self.proc.stdin.write("away\nback\n")
        self.proc.stdin.flush()
        self.stats()                    # taken: it answers again

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                assert self.proc.stdin is not None
                self.proc.stdin.write("quit\n")
                self.proc.stdin.close()
                self.proc.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait()


def jumps() -> int:
    """The jumps to hm2_eth's chain in OUTPUT (the reference adds one at
    each load)."""
    r = subprocess.run(["iptables", "-S", "OUTPUT"], capture_output=True,
                       text=True, env=dict(os.environ, PATH=SYSTEM_PATH))
    return r.stdout.count(f"-j {CHAIN}")


@contextlib.contextmanager
def jumps_restored() -> Iterator[None]:
    before = jumps()
    try:
        yield
    finally:
        for _ in range(jumps() - before):
            subprocess.run(["iptables", "-D", "OUTPUT", "-j", CHAIN],
                           capture_output=True,
                           env=dict(os.environ, PATH=SYSTEM_PATH))


# ------------------------------------------------------------ runs

@dataclass
class Run:
    cpu_per_cycle_us: float     # CPU of the host process per cycle
    datagrams: float            # datagrams the card received per cycle
    replies: float              # replies the card sent per cycle
    errors: int                 # packet-error-total over the hold
    io_error: bool
    sched: str                  # SCHED_FIFO or normal
    cycles: int                 # cycles of the measurement
    wakeups: float              # voluntary context switches per cycle




def run_once(card: Card, seconds: float, warmup: float, reference: bool,
             realtime: bool = True) -> Run:
    """Run the HAL file and sample the process that runs its thread."""
    hold = f"{seconds + 1:.0f}.{os.getpid() % 100000:05d}"
    env = dict(os.environ)
    if reference:
        env["PATH"] = SYSTEM_PATH
        cmd = [REFERENCE_TOOL, "halrun", "-f", "hm2.hal"]
    else:
        env["HALSDK_INSTANCE"] = f"benchhm2-{os.getpid()}"
        cmd = [sys.executable, *(("-m", "halsdk.halcmd.cli") if realtime
                                 else ("-c", NORMAL_HALRUN)),
               "halrun", "-f", "hm2.hal"]
    side = "reference" if reference else "ours"
    with run_folder("halsdk-bench-hm2-",
                    {"hm2.hal": hal_text(hold, warmup)}) as folder, \
            tempfile.TemporaryFile("w+") as log, \
            session(cmd, cwd=folder, stdout=log, stderr=subprocess.STDOUT,
                    env=env) as proc:
        host = wait_host(proc, log, hold,
                         our_rtapi_app if reference else None, side)
        sched = scheduling(host)
        s0 = card.stats()
        t0, c0, w0 = time.monotonic(), process_cpu(host), wakeups(host)
        time.sleep(seconds)
        t1, c1, w1 = time.monotonic(), process_cpu(host), wakeups(host)
        s1 = card.stats()
        proc.wait(timeout=seconds + 60)
        log.seek(0)
        out = log.read()
    # the getp lines (a u32: ours prints it in decimal, the reference in
    # hex)
    lines = [line.strip() for line in out.splitlines()]
    totals = [int(w, 16 if w.startswith("0x") else 10) for w in lines
              if re.fullmatch(r"0x[0-9A-Fa-f]+|[0-9]+", w)]
    flags = [w for w in lines if w in ("TRUE", "FALSE")]
    if proc.returncode != 0 or len(totals) < 2 or not flags:
        raise RuntimeError(f"unexpected output ({side}, exit "
                           f"{proc.returncode}):\n" + out[-3000:])
    cycles = round((t1 - t0) * 1e9 / PERIOD)
    return Run((c1 - c0) * 1e6 / cycles,
               (s1["requests"] - s0["requests"]) / cycles,
               (s1["replies"] - s0["replies"]) / cycles,
               (totals[-1] - totals[-2]) % 2**32, flags[-1] == "TRUE",
               sched, cycles, (w1 - w0) / cycles)


def run_reference(card: Card, seconds: float, warmup: float,
                  attempts: int = 5) -> Run:
    """The reference's run; a load that timed out is tried again: the
    reference's hm2_eth gives the card's first answers only a few hundred
    microseconds ("Resource temporarily unavailable"), which a Python
    card on a busy machine does not always make (tests/data/hm2/regen.sh
    tries again too)."""
    for attempt in range(attempts):
        with reference_lock(), jumps_restored():
            deadline = time.monotonic() + 120
            while rtapi_apps() and time.monotonic() < deadline:
                time.sleep(0.5)
            try:
                return run_once(card, seconds, warmup, True)
            except RuntimeError as e:
                if "temporarily unavailable" not in str(e) or \
                        attempt + 1 == attempts:
                    raise
        print("note: the reference's load timed out; trying again",
              file=sys.stderr)
        time.sleep(2)
    raise AssertionError("unreachable")


# ------------------------------------------------------------ report

def med(runs: list[Run], attr: str) -> Optional[float]:
    return statistics.median(getattr(r, attr) for r in runs) if runs \
        else None


def cell(runs: list[Run], attr: str, spec: str) -> str:
    v = med(runs, attr)
    return "-" if v is None else format(v, spec)


def report(a: argparse.Namespace, ours: dict[str, list[Run]],
           ref: list[Run]) -> None:
    sides = [(f"ours {k}", v) for k, v in ours.items() if v]
    sides.append(("reference", ref))
    mine = same_side(ours, ref)
    head = [""] + [name for name, _ in sides] + ["ours/ref"]
    rows = []
    for label, attr, spec in (
            ("CPU per cycle (us)", "cpu_per_cycle_us", ".1f"),
            ("wake-ups per cycle", "wakeups", ".2f"),
            ("datagrams per cycle", "datagrams", ".3f"),
            ("replies per cycle", "replies", ".3f"),
            ("packet errors per run", "errors", ".0f")):
        a_, b_ = med(mine, attr), med(ref, attr)
        rows.append([label] + [cell(v, attr, spec) for _, v in sides]
                    + ["-" if a_ is None or not b_ else f"{a_ / b_:.2f}"])
    rows.append(["io_error (runs)"]
                + [str(sum(r.io_error for r in v)) if v else "-"
                   for _, v in sides] + [""])
    rows.append(["scheduling"]
                + [", ".join(sorted({r.sched for r in v})) if v else "-"
                   for _, v in sides] + [""])
    load = os.getloadavg()
    print(f"\nhm2_eth read + write of a 7I96S ({CONFIG}) against hm2-sim at "
          f"{CARD_IP} (namespace {NETNS}, veth), servo thread {PERIOD} ns;"
          f"\n{a.seconds:g} s per run after {a.warmup:g} s warm-up, "
          f"{a.repeat} run(s) per side, alternating; median; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load "
          f"{load[0]:.2f} on {os.cpu_count()} CPUs\n")
    if a.markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for r in rows:
            print("| " + " | ".join(r) + " |")
    else:
        widths = [max(len(r[k]) for r in [head] + rows)
                  for k in range(len(head))]
        for r in [head] + rows:
            print("  ".join([r[0].ljust(widths[0])]
                            + [c.rjust(w) for c, w in zip(r[1:],
                                                          widths[1:])]))
    print("\nruns (CPU us per cycle, datagrams per cycle, packet errors, "
          "io_error):")
    for name, v in sides:
        print(f"  {name}: " + "; ".join(
            f"{r.cpu_per_cycle_us:.1f}, {r.datagrams:.3f}, {r.errors}"
            + (", io_error" if r.io_error else "") for r in v))
    if ref and mine:
        x = med(mine, "cpu_per_cycle_us")
        y = med(ref, "cpu_per_cycle_us")
        assert x is not None and y is not None
        print(f"\nours/ref: ours {mine[0].sched} (the reference's scheduling "
              "when we have it) over the reference")
        print(f"goal (CPU per cycle <= the reference's): "
              f"{'met' if x <= y else 'MISSED'} (ratio {x / y:.2f})")


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        epilog="Needs root (a network namespace); see the module docstring "
               "and docs/benchmarks.md.")
    add_thread_runs(p, "our thread")
    p.add_argument("--markdown", action="store_true",
                   help="print the table as Markdown")
    add_no_reference(p)
    a = p.parse_args(argv)
    if a.seconds <= 0 or a.warmup < 0:
        p.error("--seconds must be > 0, --warmup >= 0")
    if os.geteuid() != 0:
        print("bench/hm2.py: needs root (the network namespace of "
              "tests/data/hm2/netns.sh)", file=sys.stderr)
        return 1
    with_ref = use_reference(not a.no_reference, REFERENCE_HALRUN)
    ours: dict[str, list[Run]] = {"realtime": [], "normal": []}
    ref: list[Run] = []
    try:
        card = Card()
    except (OSError, RuntimeError, subprocess.SubprocessError) as e:
        print(f"bench/hm2.py: cannot start the simulated card: {e}",
              file=sys.stderr)
        return 1
    try:
        for _ in range(a.repeat):
            for sched in ours:
                if a.sched in ("both", sched):
                    card.power_cycle()
                    ours[sched].append(run_once(card, a.seconds, a.warmup,
                                                False, sched == "realtime"))
            if with_ref:
                card.power_cycle()
                ref.append(run_reference(card, a.seconds, a.warmup))
    except RuntimeError as e:
        print(f"bench/hm2.py: {e}", file=sys.stderr)
        return 1
    finally:
        card.close()
    report(a, ours, ref)
    return 0


if __name__ == "__main__":
    sys.exit(main())
