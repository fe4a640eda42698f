"""The periodic I/O loop of a userspace driver: read, write, timing
statistics, reconnect with exponential back-off, stop on a signal."""

from __future__ import annotations

import math
import threading
import time
from typing import Callable, Optional

from halsdk.component import Component
from halsdk.driverkit.backoff import Backoff
from halsdk.driverkit.base import (
    FAULT_OPEN,
    FAULT_READ,
    FAULT_WRITE,
    Driver,
    DriverError,
    log,
)
from halsdk.driverkit.signals import StopSignals
from halsdk.errors import HalError

#: the longest cycle of a loop, in seconds
MAX_PERIOD = 3600.0

#: timing pins created on the driver's component (float, seconds)
STAT_PINS = ("period", "max-period", "read-time", "write-time")


class IOLoop:
    """Run ``driver`` every ``period`` seconds.

    Each :meth:`cycle` either tries to (re)open a disconnected device --
    no sooner than the back-off delay allows -- or calls ``read()`` then
    ``write()``.  An exception from open, read or write sets the fault
    pins, closes the device and schedules a reconnect after ``backoff``
    seconds, doubling up to ``backoff_max`` while attempts keep failing;
    the first fully successful cycle clears the fault and resets the delay.

    Statistics pins on ``<device>.<num>``: ``period`` (time between the
    last two cycles), ``max-period`` (largest period seen; write 0 to
    restart it), ``read-time`` and ``write-time`` (duration of the last
    read and write).

    ``clock`` and ``sleep`` are replaceable: tests pass a fake clock and
    call :meth:`cycle` themselves.
    """

    def __init__(self, driver: Driver, period: float = 0.01,
                 backoff: float = 0.1, backoff_max: float = 5.0,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Optional[Callable[[float], None]] = None):
        if not (math.isfinite(period) and 0 < period <= MAX_PERIOD):
            raise ValueError(f"period must be > 0 and at most {MAX_PERIOD:g} "
                             f"s, not {period!r}")
        self.driver = driver
        self.period = period
        self.retry = Backoff(backoff, backoff_max)
        self.clock = clock
        self._stop = threading.Event()
        self.sleep = sleep or self._stop.wait
        self.connected = False
        self._last_start: Optional[float] = None
        self._thread: Optional[threading.Thread] = None

    # -- setup -------------------------------------------------------------
    def start(self) -> None:
        """Create the driver's component (if not done) with the stat pins."""
        if self.driver.comp is None:
            self.driver.start([(pin, "float") for pin in STAT_PINS])

    # -- one cycle ---------------------------------------------------------
    def cycle(self) -> None:
        """One iteration; never raises for device errors."""
        d = self.driver
        comp = d.comp
        if comp is None:
            raise DriverError(f"{d.prefix}: call start() before cycle()")
        now = self.clock()
        if self._last_start is not None:
            comp["period"] = now - self._last_start
            if comp["period"] > comp["max-period"]:
                comp["max-period"] = comp["period"]
        self._last_start = now
        if not self.connected:
            if not self.retry.ready(now):
                return
            try:
                d.open()
            except Exception as exc:
                self._failed(comp, FAULT_OPEN, exc, now)
                return
            self.connected = True
            comp["connected"] = True
        stage = FAULT_READ
        try:
            t0 = self.clock()
            d.read()
            t1 = self.clock()
            stage = FAULT_WRITE
            d.write()
            t2 = self.clock()
        except Exception as exc:
            self._failed(comp, stage, exc, now)
            return
        comp["read-time"] = t1 - t0
        comp["write-time"] = t2 - t1
        self.retry.succeeded()
        d.clear_fault()

    def _failed(self, comp: Component, code: int, exc: BaseException,
                now: float) -> None:
        d = self.driver
        d.set_fault(code, exc)
        if self.connected:
            d.safe_close()
            self.connected = False
            comp["connected"] = False
        wait = self.retry.failed(now)
        log.info("%s: reconnect in %.3g s", d.prefix, wait)

    # -- running -----------------------------------------------------------
    def run(self, handle_signals: bool = True) -> None:
        """Start, cycle every period until :meth:`stop` (or SIGTERM/SIGINT
        when ``handle_signals`` and on the main thread), until the
        component is removed (``unloadusr``) or until the instance's host
        is gone, then put the device in its safe state
        (:meth:`Driver.safe_state`), close it and remove the component.
        For ``loadusr`` processes; a component that cannot be created
        ends the process with a message and status 1."""
        signals = StopSignals(handle_signals).__enter__()
        try:
            try:
                self.start()
            except HalError as exc:
                log.error("%s: cannot create the component: %s",
                          self.driver.prefix, exc)
                raise SystemExit(1) from None
            deadline = self.clock()
            while not self._stop.is_set() and not signals.caught:
                comp = self.driver.comp
                if comp is None or not comp.exists:
                    log.warning("%s: component removed, stopping",
                                self.driver.prefix)
                    break
                if comp.host_gone:      # said on stderr by the core
                    break
                try:
                    self.cycle()
                except HalError:
                    if comp.exists:
                        raise
                    continue        # removed mid-cycle: reported above
                deadline += self.period
                wait = deadline - self.clock()
                if wait < 0:       # overrun: do not try to catch up
                    deadline = self.clock()
                    wait = 0.0
                self.sleep(wait)
        finally:
            if self.connected:
                self.connected = False
                self.go_safe()
            self.driver.shutdown()
            signals.__exit__(None, None, None)

    def go_safe(self) -> None:
        """Call the driver's :meth:`Driver.safe_state`; an error is
        logged (one line), never raised."""
        d = self.driver
        try:
            d.safe_state()
        except Exception as exc:
            log.error("%s: safe state: %s", d.prefix,
                      str(exc) or type(exc).__name__)

    def start_thread(self) -> threading.Thread:
        """Run the loop in a daemon thread (no signal handling)."""
        self.start()
        self._thread = threading.Thread(
            target=self.run, kwargs={"handle_signals": False},
            name=f"{self.driver.prefix}-io", daemon=True)
        self._thread.start()
        return self._thread

    def stop(self, timeout: Optional[float] = 5.0) -> None:
        """Ask the loop to end; wait for its thread if it has one."""
        self._stop.set()
        t = self._thread
        if t is not None and t is not threading.current_thread():
            t.join(timeout)
