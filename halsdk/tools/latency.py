"""The latency test's engine: how regularly the instance's threads run.

A latency test runs a fast *base* thread (25 µs by default) and a *servo*
thread (1 ms), as the reference's latency-test and latency-histogram do,
and measures each thread's latency: the time between two runs minus the
period.  Each thread calls two components of halsdk:

- ``timedelta`` (instance ``<thread>-td``): the largest jitter (the
  largest deviation from the period) and the longest interval;
- ``latencybins`` (instance ``<thread>-bins``): the histogram of the
  latencies (bins of ``binsize`` ns, ``bins`` on each side of 0, the
  latencies beyond them counted apart), their smallest and largest value
  and their variance.

:class:`LatencyTest` adds all of that to a running instance through the
public :class:`halsdk.Hal` API (so it works from an attached process: the
host loads the modules and makes the threads), reads the figures, and
removes everything it added.  :class:`LatencyMonitor` reads the figures
and the histograms over and over in a thread of its own, for a page or
a terminal to show.  The web workbench's Latency page
(:mod:`halsdk.web.latency`) and a ``halsdk latency`` command share them.

The average and the standard deviation come from the histogram (each
latency taken at the centre of its bin; the ones beyond the bins at the
largest or smallest latency seen), so they are exact to half a bin; the
standard deviation is latencybins' exact ``variance`` while it fits the
pin's 32 bits.
"""

from __future__ import annotations

import math
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Any, Optional

from halsdk.errors import HalError
from halsdk.hal import Hal

#: the reference's defaults (latency-histogram(1))
BASE_PERIOD = 25_000
SERVO_PERIOD = 1_000_000
BINSIZE = 100
BINS = 200
#: the shortest periods the reference accepts for each thread
MIN_PERIOD = {"base": 5_000, "servo": 25_000}
#: the longest period this test accepts (1 s)
MAX_PERIOD = 1_000_000_000
#: latencybins' bins on each side (its ``availablebins``)
MAX_BINS = 1000
#: the largest bin width, in ns (1 ms)
MAX_BINSIZE = 1_000_000
#: the prefix of everything the test adds to the instance
PREFIX = "latency"
ROLES = ("base", "servo")


class LatencyError(Exception):
    """The latency test cannot do what was asked; the message says why,
    naming the object (for the user, as is)."""


def bin_of(latency: int, binsize: int, bins: int) -> Optional[int]:
    """The bin of ``latency`` as latencybins counts it: the latency
    divided by the bin width, rounded towards zero; None beyond the last
    bin on either side (counted in ``pextra``/``nextra``)."""
    b = abs(latency) // binsize
    if b > bins:
        return None
    return b if latency >= 0 else -b


def bin_range(b: int, binsize: int) -> tuple[int, int]:
    """The latencies (ns, both ends included) that fall in bin ``b``:
    bin 0 holds -(binsize-1) .. binsize-1."""
    if b == 0:
        return -(binsize - 1), binsize - 1
    lo = abs(b) * binsize
    hi = lo + binsize - 1
    return (lo, hi) if b > 0 else (-hi, -lo)


def bin_centre(b: int, binsize: int) -> float:
    lo, hi = bin_range(b, binsize)
    return (lo + hi) / 2


@dataclass
class Histogram:
    """A thread's histogram: counts of the bins that are not empty, the
    latencies beyond the last bins (``below``, ``above``)."""

    binsize: int
    bins: int
    counts: dict[int, int] = field(default_factory=dict)
    below: int = 0
    above: int = 0

    @property
    def total(self) -> int:
        """Latencies counted: every bin and both extras."""
        return sum(self.counts.values()) + self.below + self.above

    def moments(self, lowest: Optional[int] = None,
                highest: Optional[int] = None
                ) -> tuple[Optional[float], Optional[float]]:
        """Average and standard deviation of the latencies, each at the
        centre of its bin (the extras at ``lowest``/``highest``, or the
        edge of the last bin); None while too few were counted."""
        n = self.total
        if n == 0:
            return None, None
        edge = (self.bins + 1) * self.binsize
        points = [(bin_centre(b, self.binsize), c)
                  for b, c in self.counts.items() if c]
        if self.above:
            points.append((float(highest if highest is not None
                                 else edge), self.above))
        if self.below:
            points.append((float(lowest if lowest is not None
                                 else -edge), self.below))
        mean = sum(x * c for x, c in points) / n
        if n < 2:
            return mean, None
        var = sum(c * (x - mean) ** 2 for x, c in points) / (n - 1)
        return mean, math.sqrt(var)

    def as_json(self) -> dict[str, Any]:
        return {"binsize": self.binsize, "bins": self.bins,
                "counts": [[b, c] for b, c in sorted(self.counts.items())
                           if c],
                "below": self.below, "above": self.above,
                "total": self.total}


@dataclass(frozen=True)
class ThreadSetup:
    """One thread of the test: its role, period, bin width and bins."""

    role: str
    period: int
    binsize: int = BINSIZE
    bins: int = BINS

    @property
    def thread(self) -> str:
        return f"{PREFIX}-{self.role}"

    @property
    def td(self) -> str:
        return f"{self.thread}-td"

    @property
    def hist(self) -> str:
        return f"{self.thread}-bins"

    def check(self) -> None:
        least = MIN_PERIOD[self.role]
        for what, value, lo, hi in (
                ("period", self.period, least, MAX_PERIOD),
                ("bin size", self.binsize, 1, MAX_BINSIZE),
                ("bins", self.bins, 1, MAX_BINS)):
            if (not isinstance(value, int) or isinstance(value, bool)
                    or not lo <= value <= hi):
                raise LatencyError(
                    f"latency test: thread '{self.thread}': {what} "
                    f"{value!r} is not an integer from {lo} to {hi}")


def setups(base: Optional[int] = BASE_PERIOD, servo: int = SERVO_PERIOD,
           *, base_binsize: int = BINSIZE, servo_binsize: int = BINSIZE,
           bins: int = BINS) -> list[ThreadSetup]:
    """The threads of a test (``base`` None or 0: the servo thread only,
    as the reference's ``--nobase``), checked."""
    out = []
    if base:
        out.append(ThreadSetup("base", base, base_binsize, bins))
    out.append(ThreadSetup("servo", servo, servo_binsize, bins))
    for s in out:
        s.check()
    if base and base >= servo:
        raise LatencyError(f"latency test: the base period ({base} ns) "
                           f"must be shorter than the servo period "
                           f"({servo} ns)")
    return out


def host_realtime(pid: int) -> Optional[bool]:
    """Whether a thread of process ``pid`` runs with realtime scheduling
    (SCHED_FIFO or SCHED_RR), read from /proc; None when unreadable."""
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return None
    seen = False
    for tid in tasks:
        try:
            with open(f"/proc/{pid}/task/{tid}/stat") as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat.rpartition(")")[2].split()
        # policy is field 41 of stat(5); fields[0] is field 3
        if len(fields) > 38:
            seen = True
            if fields[38] in ("1", "2"):
                return True
    return False if seen else None


def _wait(what: str, ok: Callable[[], bool], tick: Callable[[], None],
          timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while not ok():
        if time.monotonic() > deadline:
            raise LatencyError(f"latency test: {what} did not happen "
                               f"within {timeout:g} s (is the thread "
                               "running?)")
        tick()


def _equals(pin: Any, value: int) -> bool:
    return bool(pin.value == value)


def _sleep() -> None:
    time.sleep(0.0002)


class LatencyTest:
    """A latency test in ``hal``'s instance: :meth:`start` adds it,
    :meth:`figures` and :meth:`histogram` read it, :meth:`stop` removes
    it.  ``tick`` is called while waiting for a thread to run (default: a
    short sleep; a test that steps the threads passes a step)."""

    def __init__(self, hal: Hal, threads: Optional[list[ThreadSetup]] = None,
                 *, tick: Callable[[], None] = _sleep,
                 timeout: float = 5.0):
        self.hal = hal
        self.threads = threads if threads is not None else setups()
        self.tick = tick
        self.timeout = timeout
        #: True/False once started: whether the threads got realtime
        #: scheduling (None: not known)
        self.realtime: Optional[bool] = None
        #: what the start said about the scheduling
        self.note = ""
        self.started = False
        self._lock = threading.RLock()
        self._modules: list[str] = []
        self._made_threads: list[str] = []
        self._added: list[tuple[str, str]] = []
        self._started_instance = False
        self._pins: dict[str, Any] = {}

    # ---------------------------------------------------------- lifetime

    def start(self, run: bool = True, realtime: bool = True) -> None:
        """Add the threads and components and start them (``run``
        False: leave a stopped instance stopped, for stepping).  On any
        refusal, what was added is removed and LatencyError says why.

        ``realtime``: ask for realtime scheduling when the test starts
        the instance (:meth:`halsdk.Hal.start`); threads made in an
        instance that runs already are scheduled as its threads are.
        :attr:`realtime` and :attr:`note` say what the threads got."""
        with self._lock:
            if self.started:
                raise LatencyError("latency test: already running")
            self._check_free()
            if run and self.hal.lock_level & Hal.LOCK_RUN:
                # a thread made while HAL runs starts at once: the lock
                # against starting threads must refuse it here
                raise LatencyError("latency test: cannot start: HAL is "
                                   "locked against starting threads")
            running = bool(self.hal.info()["threads_running"])
            others = [t.name for t in self.hal.threads()]
            if run and not running and others:
                raise LatencyError(
                    "latency test: the instance's threads are stopped, and "
                    "starting the test would start "
                    + ", ".join(f"'{n}'" for n in others)
                    + " too: start them first (halcmd start) or remove "
                    "them")
            try:
                self._build()
                if run and not running:
                    note = self.hal.start(realtime)
                    self._started_instance = True
                    self.realtime = realtime and note is None
                    self.note = note or ""
                elif run:
                    self.realtime = host_realtime(
                        int(self.hal.info()["host_pid"]))
                self.started = True
                if self.realtime is True:
                    self.note = "realtime scheduling (SCHED_FIFO)"
                elif self.realtime is False and not self.note:
                    self.note = ("Note: Using POSIX non-realtime (the "
                                 "threads run without SCHED_FIFO)")
                elif run and self.realtime is None:
                    self.note = ("the threads' scheduling is not known "
                                 "(the host's /proc cannot be read)")
                if run:
                    self.reset()
            except (HalError, LatencyError) as exc:
                self.started = True
                try:
                    self._remove()
                except (HalError, LatencyError):
                    pass
                self.started = False
                if isinstance(exc, LatencyError):
                    raise
                raise LatencyError(f"latency test: cannot start: "
                                   f"{exc}") from None

    def _check_free(self) -> None:
        for comp in ("timedelta", "latencybins"):
            if self.hal.find("component", comp) is not None:
                raise LatencyError(
                    f"latency test: component '{comp}' is already loaded "
                    "in this instance (another latency test?); the test "
                    "loads its own")
        for s in self.threads:
            for kind, name in (("thread", s.thread), ("function", s.td),
                               ("function", s.hist)):
                if self.hal.find(kind, name) is not None:
                    raise LatencyError(f"latency test: {kind} '{name}' "
                                       "already exists")

    def _build(self) -> None:
        hal = self.hal
        hal.loadrt("timedelta", names=",".join(s.td for s in self.threads))
        self._modules.append("timedelta")
        hal.loadrt("latencybins",
                   names=",".join(s.hist for s in self.threads))
        self._modules.append("latencybins")
        for s in self.threads:
            hal.setp(f"{s.hist}.nsbinsize", s.binsize)
            hal.setp(f"{s.hist}.maxbinnumber", s.bins)
        # slowest first: a thread made while HAL runs starts at once
        for s in sorted(self.threads, key=lambda s: -s.period):
            hal.newthread(s.thread, s.period, fp=False)
            self._made_threads.append(s.thread)
            for funct in (s.td, s.hist):
                hal.addf(funct, s.thread)
                self._added.append((funct, s.thread))
        self._pins = {}
        for s in self.threads:
            for comp, pins in ((s.td, ("jitter", "max", "min", "out",
                                       "reset")),
                               (s.hist, ("index", "check", "pbinvalue",
                                         "nbinvalue", "pextra", "nextra",
                                         "latency", "latency-max",
                                         "latency-min", "variance",
                                         "reset"))):
                for p in pins:
                    self._pins[f"{comp}.{p}"] = hal.pin(f"{comp}.{p}")

    def stop(self) -> None:
        """Remove everything the test added (idempotent); the instance
        stopped again when the test started it and no other thread came.
        LatencyError when the instance refuses (its lock): call again."""
        with self._lock:
            if not self.started:
                return
            try:
                self._remove()
            except HalError as exc:
                raise LatencyError(f"latency test: cannot remove it: "
                                   f"{exc}") from None
            self.started = False

    def _remove(self) -> None:
        hal = self.hal
        self._pins = {}
        while self._added:
            funct, thread = self._added[-1]
            if hal.find("function", funct) is not None and \
                    hal.find("thread", thread) is not None:
                hal.delf(funct, thread)
            self._added.pop()
        while self._made_threads:
            if hal.find("thread", self._made_threads[-1]) is not None:
                hal.delthread(self._made_threads[-1])
            self._made_threads.pop()
        while self._modules:
            if hal.find("component", self._modules[-1]) is not None:
                hal.unload(self._modules[-1])
            self._modules.pop()
        if self._started_instance:
            self._started_instance = False
            if not hal.threads() and hal.info()["threads_running"]:
                hal.stop()

    def __enter__(self) -> LatencyTest:
        self.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()

    # ---------------------------------------------------------- reading

    def _pin(self, name: str) -> Any:
        pin = self._pins.get(name)
        if pin is None:
            raise LatencyError("latency test: not running")
        return pin

    def _cycles(self, s: ThreadSetup) -> int:
        return int(self.hal.thread(s.thread).cycles)

    def _ran(self, s: ThreadSetup, cycles: int) -> bool:
        return self._cycles(s) >= cycles

    def reset(self) -> None:
        """Start measuring afresh: clear every thread's figures and
        histogram (holds each ``reset`` for two runs of its thread)."""
        with self._lock:
            if not self.started:
                raise LatencyError("latency test: not running")
            for s in self.threads:
                self._pin(f"{s.td}.reset").setp(True)
                self._pin(f"{s.hist}.reset").setp(True)
            for s in self.threads:
                _wait(f"a reset of thread '{s.thread}'",
                      partial(self._ran, s, self._cycles(s) + 2),
                      self.tick, self.timeout)
            for s in self.threads:
                self._pin(f"{s.td}.reset").setp(False)
                self._pin(f"{s.hist}.reset").setp(False)

    def histogram(self, s: ThreadSetup) -> Histogram:
        """Read thread ``s``'s histogram from its latencybins, one pair
        of bins per run of the thread (only the bins between the smallest
        and the largest latency seen can hold anything).  One reader at a
        time: the bins are read through latencybins' ``index`` pin."""
        h = Histogram(s.binsize, s.bins)
        pins = {p: self._pin(f"{s.hist}.{p}") for p in (
            "index", "check", "pbinvalue", "nbinvalue", "pextra",
            "nextra", "latency-max", "latency-min")}
        lo, hi = pins["latency-min"].value, pins["latency-max"].value
        if lo > hi:                           # nothing measured yet
            return h
        top = min(s.bins, max(abs(lo), abs(hi)) // s.binsize)
        index, check = pins["index"], pins["check"]
        if check.value == 0:
            index.setp(-1)
            _wait(f"a run of thread '{s.thread}'",
                  lambda: check.value == -1, self.tick, self.timeout)
        for i in range(top + 1):
            index.setp(i)
            _wait(f"a run of thread '{s.thread}'",
                  partial(_equals, check, i), self.tick, self.timeout)
            p, n = pins["pbinvalue"].value, pins["nbinvalue"].value
            if p > 0:
                h.counts[i] = p
            if n > 0 and i > 0:
                h.counts[-i] = n
        h.above = max(0, pins["pextra"].value)
        h.below = max(0, pins["nextra"].value)
        return h

    def thread_figures(self, s: ThreadSetup,
                       hist: Optional[Histogram] = None) -> dict[str, Any]:
        """Thread ``s``'s figures, in ns (None: nothing measured yet):
        ``max``/``min``/``last`` latency, ``jitter`` (the largest
        deviation from the period), ``interval_max`` (the longest time
        between two runs), ``interval_last`` (the last one), the
        thread's ``cycles`` and ``overruns``; with a histogram, ``avg``
        and ``sdev`` of the latency and ``samples`` (the latencies it
        counts)."""
        pin = self._pin
        lo = pin(f"{s.hist}.latency-min").value
        hi = pin(f"{s.hist}.latency-max").value
        measured = lo <= hi
        thread = self.hal.thread(s.thread)
        out: dict[str, Any] = {
            "thread": s.thread, "role": s.role, "period": s.period,
            "binsize": s.binsize, "bins": s.bins,
            "cycles": int(thread.cycles),
            "overruns": int(thread.overruns),
            "min": lo if measured else None,
            "max": hi if measured else None,
            "last": pin(f"{s.hist}.latency").value if measured else None,
            "jitter": pin(f"{s.td}.jitter").value if measured else None,
            "interval_max": (pin(f"{s.td}.max").value or None)
            if measured else None,
            "interval_last": (pin(f"{s.td}.out").value or None)
            if measured else None,
            "avg": None, "sdev": None, "samples": None,
        }
        if hist is not None:
            avg, sdev = hist.moments(lo if measured else None,
                                     hi if measured else None)
            variance = pin(f"{s.hist}.variance").value
            if (sdev is not None and variance >= 0
                    and sdev * sdev < 2 ** 30):
                sdev = math.sqrt(variance)
            out.update(avg=avg, sdev=sdev, samples=hist.total)
        return out

    def figures(self, histograms: Optional[dict[str, Histogram]] = None,
                read: bool = False) -> dict[str, Any]:
        """Every thread's figures, as JSON: with the histograms given
        (by role), or read now (``read``), their figures too."""
        threads = []
        for s in self.threads:
            hist = self.histogram(s) if read else \
                (histograms or {}).get(s.role)
            fig = self.thread_figures(s, hist)
            fig["histogram"] = None if hist is None else hist.as_json()
            threads.append(fig)
        return {"running": self.started, "realtime": self.realtime,
                "note": self.note, "threads": threads}

    def added(self) -> dict[str, list[str]]:
        """What the test adds to the instance: its threads, functions
        and modules."""
        return {"threads": [s.thread for s in self.threads],
                "functions": [f for s in self.threads
                              for f in (s.td, s.hist)],
                "modules": ["timedelta", "latencybins"]}


class LatencyMonitor:
    """Reads a running test's histograms over and over in a thread of its
    own (a histogram takes one run of its thread per pair of bins);
    :meth:`figures` gives the figures of now with the last histograms.
    :attr:`error` says what stopped the reading, if anything."""

    def __init__(self, test: LatencyTest, interval: float = 0.1):
        self.test = test
        self.interval = interval
        self.histograms: dict[str, Histogram] = {}
        #: complete readings of every histogram so far
        self.sweeps = 0
        self.error: Optional[str] = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name="halsdk-latency")

    def start(self) -> None:
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                hists = {s.role: self.test.histogram(s)
                         for s in self.test.threads}
            except (HalError, LatencyError) as exc:
                if not self._stop.is_set() and self.test.started:
                    self.error = str(exc)
                return
            self.histograms = hists
            self.sweeps += 1
            self._stop.wait(self.interval)

    def figures(self) -> dict[str, Any]:
        out = self.test.figures(self.histograms)
        out["sweeps"] = self.sweeps
        out["error"] = self.error
        return out

    def stop(self) -> None:
        """Stop reading (before the test is stopped)."""
        self._stop.set()
        if self._thread.is_alive() and \
                self._thread is not threading.current_thread():
            self._thread.join(timeout=30)
