"""``halsdk latency``: the latency test in a terminal.

It runs a base thread (25 µs) and a servo thread (1 ms) in a HAL
instance of its own, which it creates and removes (it is the host; no
instance needs to run, and ``$HALSDK_INSTANCE`` is not used: a running
machine is left alone, its threads only share the CPU with the test).
While it runs it shows each thread's latency (the time between two runs
minus the period): the largest and smallest, the average and the
standard deviation, updated in place on a terminal and as plain lines
otherwise.  At the end (``--seconds``, Ctrl-C or SIGTERM) it prints a
summary and writes the histograms as CSV and PNG.  The measurement is
the engine of :mod:`halsdk.tools.latency`, shared with the web
workbench's Latency page.
"""

from __future__ import annotations

import argparse
import csv
import os
import re
import signal
import sys
import time
from decimal import Decimal
from types import FrameType
from typing import Any, Optional, TextIO

from halsdk.errors import HalError
from halsdk.hal import Hal
from halsdk.tools import histplot
from halsdk.tools.latency import (
    BASE_PERIOD,
    BINS,
    BINSIZE,
    MAX_BINS,
    MAX_BINSIZE,
    SERVO_PERIOD,
    Histogram,
    LatencyError,
    LatencyMonitor,
    LatencyTest,
    ThreadSetup,
    bin_range,
    setups,
)

PROG = "halsdk latency"
_UNITS = {"ns": 1, "us": 1_000, "µs": 1_000, "ms": 1_000_000,
          "s": 1_000_000_000}
_TIME = re.compile(r"^\s*(\d+(?:\.\d*)?|\.\d+)\s*(ns|us|µs|ms|s)?\s*$")


def parse_time(text: str) -> int:
    """A period: a number with a unit (ns, us or µs, ms, s; none: ns),
    as whole nanoseconds."""
    m = _TIME.match(text)
    if not m:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a time (a number and a unit: 25us, 1ms, "
            "50000ns)")
    # exact decimal arithmetic: 16.1us is 16100 ns, not 16100.000000002
    ns = Decimal(m.group(1)) * _UNITS[m.group(2) or "ns"]
    if ns != ns.to_integral_value():
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a whole number of nanoseconds")
    return int(ns)


def human(ns: int) -> str:
    """A period as the reference's latency test writes it (25µs, 1ms)."""
    for unit, scale in (("s", 10**9), ("ms", 10**6), ("µs", 10**3)):
        if ns >= scale:
            return f"{ns / scale:g}{unit}"
    return f"{ns}ns"


def _positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") \
            from None
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r} must be more than 0")
    return v


def _whole(lo: int, hi: int) -> Any:
    def check(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a whole number") from None
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not from {lo} to {hi}")
        return v
    return check


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=PROG, description=__doc__.split("\n\n")[0].strip("`: ")
        + ": how regularly this computer runs a base and a servo thread",
        epilog="It runs in a HAL instance of its own (no instance needs "
               "to run; $HALSDK_INSTANCE is not used). Exit status: 0 "
               "done, 1 the test could not run, 2 bad options.")
    p.add_argument("--base", type=parse_time, default=BASE_PERIOD,
                   metavar="TIME",
                   help="the base thread's period (default 25us; 0: no "
                        "base thread)")
    p.add_argument("--servo", type=parse_time, default=SERVO_PERIOD,
                   metavar="TIME",
                   help="the servo thread's period (default 1ms)")
    p.add_argument("--seconds", type=_positive, default=None, metavar="N",
                   help="stop after N seconds (default: run until Ctrl-C "
                        "or SIGTERM)")
    p.add_argument("--binsize", type=_whole(1, MAX_BINSIZE),
                   default=BINSIZE, metavar="NS",
                   help=f"the histograms' bin width in ns (default "
                        f"{BINSIZE})")
    p.add_argument("--bins", type=_whole(1, MAX_BINS), default=BINS,
                   metavar="N",
                   help=f"the bins on each side of 0 (default {BINS}); "
                        "latencies beyond them are counted apart")
    p.add_argument("--csv", default="latency.csv", metavar="FILE",
                   help="the histograms as CSV (default latency.csv; '' "
                        "for none)")
    p.add_argument("--png", default="latency.png", metavar="FILE",
                   help="the histograms as a PNG picture (default "
                        "latency.png; '' for none)")
    p.add_argument("--interval", type=_positive, default=None,
                   metavar="S",
                   help="seconds between two updates of the figures "
                        "(default 0.5 on a terminal, 1 otherwise)")
    p.add_argument("--no-realtime", action="store_true",
                   help="run the threads with normal scheduling, not "
                        "SCHED_FIFO with locked memory")
    p.add_argument("--reference-style", action="store_true",
                   help="show the figures LinuxCNC's latency-test shows: "
                        "each thread's longest interval, largest jitter "
                        "and last interval, in ns")
    return p


# ------------------------------------------------------------ showing

def _us(ns: Optional[float], digits: int = 1) -> str:
    return "-" if ns is None else f"{ns / 1000:.{digits}f}"


def _max_jitter(t: dict[str, Any]) -> Optional[int]:
    if t["max"] is None:
        return None
    return max(abs(t["max"]), abs(t["min"]))


_HEAD: tuple[str, ...] = ("thread", "period", "samples", "min us",
                          "max us", "jitter us", "avg us", "sdev us",
                          "overruns")
_REF_HEAD: tuple[str, ...] = ("", "Max Interval (ns)", "Max Jitter (ns)",
             "Last interval (ns)")


def _ns(v: Optional[int]) -> str:
    return "-" if v is None else str(v)


def table(figures: dict[str, Any], reference_style: bool) -> list[str]:
    """The figures as lines of a table."""
    rows: list[tuple[str, ...]]
    if reference_style:
        # the reference lists the servo thread first
        threads = sorted(figures["threads"], key=lambda t: -t["period"])
        rows = [_REF_HEAD] + [
            (f"{t['role'].capitalize()} thread ({human(t['period'])}):",
             _ns(t["interval_max"]), _ns(t["jitter"]),
             _ns(t["interval_last"])) for t in threads]
    else:
        rows = [_HEAD] + [
            (t["role"], human(t["period"]), _ns(t["samples"]),
             _us(t["min"]), _us(t["max"]), _us(_max_jitter(t)),
             _us(t["avg"], 2), _us(t["sdev"], 2), str(t["overruns"]))
            for t in figures["threads"]]
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return ["  ".join([r[0].ljust(widths[0])]
                      + [c.rjust(w) for c, w in zip(r[1:], widths[1:])])
            for r in rows]


def one_line(figures: dict[str, Any], elapsed: float,
             reference_style: bool) -> str:
    """The figures of now on one line (output that is not a terminal)."""
    parts = []
    for t in figures["threads"]:
        if reference_style:
            parts.append(f"{t['role']}: max interval "
                         f"{_ns(t['interval_max'])} ns, max jitter "
                         f"{_ns(t['jitter'])} ns, last interval "
                         f"{_ns(t['interval_last'])} ns")
        else:
            parts.append(f"{t['role']}: max {_us(t['max'])} us, jitter "
                         f"{_us(_max_jitter(t))} us, avg "
                         f"{_us(t['avg'], 2)} us, sdev "
                         f"{_us(t['sdev'], 2)} us")
    return f"{elapsed:6.1f} s  " + "; ".join(parts)


class Display:
    """The live figures: rewritten in place on a terminal, a line per
    update otherwise."""

    def __init__(self, out: TextIO, reference_style: bool):
        self.out = out
        self.reference_style = reference_style
        self.tty = out.isatty()
        self._shown = 0

    def show(self, figures: dict[str, Any], elapsed: float) -> None:
        if not self.tty:
            print(one_line(figures, elapsed, self.reference_style),
                  file=self.out, flush=True)
            return
        lines = [f"running {elapsed:.1f} s (Ctrl-C ends it)"]
        lines += table(figures, self.reference_style)
        text = "".join(f"\x1b[2K{line}\n" for line in lines)
        up = f"\x1b[{self._shown}F" if self._shown else ""
        self.out.write(up + text)
        self.out.flush()
        self._shown = len(lines)


# ------------------------------------------------------------ files

def write_csv(path: str, test: LatencyTest,
              histograms: dict[str, Histogram],
              figures: dict[str, Any]) -> None:
    """One row per bin that counted something (its latencies from
    ``low_ns`` to ``high_ns``), and one row for the latencies below and
    above the bins (``low_ns``/``high_ns``: the extreme seen)."""
    by_role = {t["role"]: t for t in figures["threads"]}
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(("thread", "period_ns", "bin", "low_ns", "high_ns",
                    "count"))
        for s in test.threads:
            h = histograms[s.role]
            t = by_role[s.role]
            edge = (h.bins + 1) * h.binsize
            if h.below:
                w.writerow((s.role, s.period, "below", t["min"], -edge,
                            h.below))
            for b in sorted(h.counts):
                if h.counts[b]:
                    lo, hi = bin_range(b, h.binsize)
                    w.writerow((s.role, s.period, b, lo, hi, h.counts[b]))
            if h.above:
                w.writerow((s.role, s.period, "above", edge, t["max"],
                            h.above))


def write_png(path: str, test: LatencyTest,
              histograms: dict[str, Histogram]) -> None:
    panels = []
    for s in test.threads:
        h = histograms[s.role]
        counts = dict(h.counts)
        # the latencies beyond the bins, one bin past the last
        if h.below:
            counts[-(h.bins + 1)] = h.below
        if h.above:
            counts[h.bins + 1] = h.above
        panels.append(histplot.Panel(
            f"{s.role} thread {human(s.period).replace('µ', 'u')}: "
            f"latency (us), {h.total} samples", h.binsize, counts))
    histplot.plot(path, panels)


# ------------------------------------------------------------ running

class _Stop:
    """SIGINT and SIGTERM end the test: a plain flag (a signal handler
    runs between two bytecodes of the main thread; it takes no lock)."""

    def __init__(self) -> None:
        self.signal: Optional[int] = None
        self._old: dict[int, Any] = {}

    def __enter__(self) -> _Stop:
        for s in (signal.SIGINT, signal.SIGTERM):
            self._old[s] = signal.signal(s, self._handler)
        return self

    def _handler(self, signum: int, frame: Optional[FrameType]) -> None:
        self.signal = signum

    def __exit__(self, *exc: Any) -> None:
        for s, handler in self._old.items():
            signal.signal(s, handler)

    def sleep(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while self.signal is None:
            left = end - time.monotonic()
            if left <= 0:
                return
            time.sleep(min(left, 0.05))


def named_instance_running() -> Optional[str]:
    """The name in ``$HALSDK_INSTANCE`` when that instance exists (its
    shared memory segment is there), else None."""
    name = os.environ.get("HALSDK_INSTANCE", "")
    shm = f"/dev/shm/halsdk-{os.getuid()}" + (f"-{name}" if name else "")
    if name and os.path.exists(shm):
        return name
    return None


def main(argv: Optional[list[str]] = None) -> int:
    p = parser()
    a = p.parse_args(argv)
    try:
        threads = setups(a.base or None, a.servo, base_binsize=a.binsize,
                         servo_binsize=a.binsize, bins=a.bins)
    except LatencyError as exc:
        p.error(str(exc).removeprefix("latency test: "))
    out = sys.stdout
    other = named_instance_running()
    if other:
        print(f"note: HAL instance '{other}' ($HALSDK_INSTANCE) is running; "
              "the test does not touch it, but its threads share the "
              "CPU with the test's", file=sys.stderr)
    interval = a.interval or (0.5 if out.isatty() else 1.0)
    name = f"latency-{os.getpid()}"
    with _Stop() as stop:
        try:
            hal = Hal(name, create=True)
        except HalError as exc:
            print(f"{PROG}: cannot create HAL instance '{name}': {exc}",
                  file=sys.stderr)
            return 1
        try:
            return _run(hal, threads, a, stop, interval, out)
        finally:
            hal.close()


def _run(hal: Hal, threads: list[ThreadSetup], a: argparse.Namespace,
         stop: _Stop, interval: float, out: TextIO) -> int:
    test = LatencyTest(hal, threads)
    try:
        test.start(realtime=not a.no_realtime)
    except LatencyError as exc:
        print(f"{PROG}: {exc}", file=sys.stderr)
        return 1
    sched = scheduling(test, a.no_realtime)
    print(f"halsdk latency test in HAL instance '{hal.instance}': "
          + ", ".join(f"{s.role} thread {human(s.period)}"
                      for s in threads), file=out)
    print(f"scheduling: {sched}", file=out, flush=True)
    monitor = LatencyMonitor(test, interval=0.05)
    display = Display(out, a.reference_style)
    t0 = time.monotonic()
    status = 0
    try:
        monitor.start()
        while stop.signal is None:
            elapsed = time.monotonic() - t0
            left = None if a.seconds is None else a.seconds - elapsed
            if left is not None and left <= 0:
                break
            stop.sleep(interval if left is None else min(interval, left))
            if monitor.error:
                print(f"{PROG}: {monitor.error}", file=sys.stderr)
                status = 1
                break
            display.show(monitor.figures(), time.monotonic() - t0)
        elapsed = time.monotonic() - t0
        monitor.stop()
        # the last reading: the histograms and the figures of the end
        histograms = {s.role: test.histogram(s) for s in threads}
        figures = test.figures(histograms)
    except (HalError, LatencyError) as exc:
        monitor.stop()
        print(f"{PROG}: {exc}", file=sys.stderr)
        try:
            test.stop()
        except LatencyError as again:
            print(f"{PROG}: {again}", file=sys.stderr)
        return 1
    test.stop()
    why = {int(signal.SIGINT): " (interrupted)",
           int(signal.SIGTERM): " (SIGTERM)"}.get(stop.signal or 0, "")
    print(f"\nsummary: {elapsed:.1f} s{why}, {sched}", file=out)
    for line in table(figures, a.reference_style):
        print(line, file=out)
    if not a.reference_style:
        print("latency: the time between two runs of a thread minus its "
              "period; jitter: its largest size", file=out)
    status = max(status, _files(a, test, histograms, figures, out))
    return status


def scheduling(test: LatencyTest, no_realtime: bool) -> str:
    """What the threads got, in words."""
    if test.realtime:
        return "realtime (SCHED_FIFO, locked memory)"
    if no_realtime:
        return "normal, not realtime (--no-realtime)"
    return f"normal, not realtime: {test.note.strip() or 'refused'}"


def _files(a: argparse.Namespace, test: LatencyTest,
           histograms: dict[str, Histogram], figures: dict[str, Any],
           out: TextIO) -> int:
    status = 0
    for path, write in ((a.csv, lambda p: write_csv(p, test, histograms,
                                                    figures)),
                        (a.png, lambda p: write_png(p, test, histograms))):
        if not path:
            continue
        try:
            write(path)
        except OSError as exc:
            print(f"{PROG}: cannot write {path}: {exc.strerror or exc}",
                  file=sys.stderr)
            status = 1
            continue
        print(f"histogram written: {path}", file=out)
    return status


if __name__ == "__main__":
    from halsdk import console
    sys.exit(console.run(main))
