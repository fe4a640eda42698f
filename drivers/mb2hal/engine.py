"""The mb2hal engine: the HAL component, its pins and one worker thread
per link that runs the link's transactions in turn."""

from __future__ import annotations

import logging
import threading
import time
from typing import Callable, Optional

from halsdk.component import Component, component
from halsdk.driverkit.backoff import Backoff
from halsdk.driverkit.signals import StopSignals

from .client import LinkDown, ModbusLink, Refused
from .config import VERSION_1_1, Config, Link, Transaction

log = logging.getLogger("halsdk.mb2hal")

DEBUG_ERR, DEBUG_OK, DEBUG_DEBUG = 1, 2, 3
#: shortest repetition period, s, of a transaction that cannot be sent
UNUSABLE_PERIOD = 0.01


def pin_specs(tx: Transaction, version: int) -> list[tuple[str, str, str]]:
    """(pin suffix, type, direction) of each element pin, in order."""
    new = version >= VERSION_1_1
    specs = []
    for name in tx.pin_names:
        base = f"{tx.name}.{name}"
        if tx.function in (1, 2):
            specs += ([(f"{base}.bit", "bit", "out"),
                       (f"{base}.bit-inv", "bit", "out")] if new
                      else [(base, "bit", "out")])
        elif tx.function in (3, 4):
            specs += [(f"{base}.float", "float", "out"),
                      (f"{base}.int", "s32", "out")]
        elif tx.function in (5, 15):
            specs.append((f"{base}.bit" if new else base, "bit", "in"))
        else:
            specs += ([(f"{base}.float", "float", "in"),
                       (f"{base}.int", "s32", "in")] if new
                      else [(base, "float", "in")])
    specs.append((f"{tx.name}.num_errors", "u32", "out"))
    return specs


class TxRunner:
    """Pins and schedule of one transaction."""

    def __init__(self, tx: Transaction, comp: Component, version: int):
        self.tx = tx
        self.comp = comp
        self.new = version >= VERSION_1_1
        self.period = 1.0 / tx.max_update_rate if tx.max_update_rate else 0.0
        self.next_due = 0.0
        self.failing = False
        self.ok_count = 0

    def pin(self, name: str, suffix: str = "") -> str:
        return f"{self.tx.name}.{name}{suffix}"

    def outputs(self) -> list[int]:
        """Values to send, from the in pins."""
        c, tx = self.comp, self.tx
        if tx.function in (5, 15):
            sfx = ".bit" if self.new else ""
            return [int(bool(c[self.pin(n, sfx)])) for n in tx.pin_names]
        values = []
        for n in tx.pin_names:
            if self.new:
                total = c[self.pin(n, ".float")] + c[self.pin(n, ".int")]
            else:
                total = c[self.pin(n)]
            values.append(int(min(max(total, 0.0), 65535.0)))
        return values

    def publish(self, values: list[int]) -> None:
        c, tx = self.comp, self.tx
        for n, v in zip(tx.pin_names, values):
            if tx.function in (1, 2):
                if self.new:
                    c[self.pin(n, ".bit")] = bool(v)
                    c[self.pin(n, ".bit-inv")] = not v
                else:
                    c[self.pin(n)] = bool(v)
            else:
                c[self.pin(n, ".float")] = float(v)
                c[self.pin(n, ".int")] = int(v)

    def count_error(self) -> None:
        key = f"{self.tx.name}.num_errors"
        self.comp[key] = (self.comp[key] + 1) & 0xFFFFFFFF


class LinkWorker:
    """Runs the transactions of one link until stopped."""

    def __init__(self, link: Link, runners: list[TxRunner], slowdown: float,
                 stop: threading.Event, backoff: float, backoff_max: float,
                 factory: Callable[[Link], ModbusLink] = ModbusLink):
        self.link = link
        self.runners = runners
        self.slowdown = slowdown
        self.stop = stop
        self.retry = Backoff(backoff, backoff_max)
        self.conn = factory(link)
        #: problems logged since the last good transaction (each once)
        self.reported: set[str] = set()
        self.working = False
        #: unexpected errors seen (each logged once for the whole run) and
        #: the pause after one, which grows while they go on
        self.crashes: set[str] = set()
        self.crash_pause = Backoff(backoff, backoff_max)
        self.debug = max(r.tx.debug for r in runners)
        self.thread = threading.Thread(target=self.run, daemon=True,
                                       name=f"mb2hal {link.describe()}")

    # -- connection --------------------------------------------------------
    def _connect(self, runner: TxRunner) -> bool:
        try:
            self.conn.open(runner.tx.response_timeout_ms / 1000.0)
        except LinkDown as exc:
            now = time.monotonic()
            for other in self.runners:     # every waiting one fails
                if other is runner or other.next_due <= now:
                    other.count_error()
            self._down(str(exc))
            return False
        # an accepted connection is not yet a working link: recovery is
        # only announced after a good transaction (see transact)
        if self.debug >= DEBUG_DEBUG:
            log.debug("%s: connected", self.link.describe())
        return True

    def _down(self, text: str) -> float:
        """Close the connection, back off; log ``text`` once until the
        link works again. Returns the wait before the next attempt."""
        self.conn.close()
        wait = self.retry.failed(time.monotonic())
        if text not in self.reported and self.debug >= DEBUG_ERR:
            log.error("%s (retry in %.3g s)", text, wait)
        self.reported.add(text)
        return wait

    def _recovered(self) -> None:
        """A transaction worked: the link is up (again)."""
        if self.reported:
            if self.debug >= DEBUG_ERR:
                log.warning("%s: connected again", self.link.describe())
            self.reported.clear()
        elif not self.working and self.debug >= DEBUG_OK:
            log.info("%s: connected", self.link.describe())
        self.working = True

    # -- one transaction -------------------------------------------------
    def transact(self, runner: TxRunner) -> None:
        tx = runner.tx
        if tx.unusable:
            # as the reference: nothing is sent, the repetition fails and
            # the link stays as it is
            self._failed(runner, f"{tx.line}: transaction {tx.name}: not "
                         f"sent: {tx.unusable}")
            return
        try:
            values = runner.outputs() if tx.is_write else None
            result = self.conn.execute(tx, values)
        except Refused as exc:         # the device answered: link is up
            self._recovered()
            self._failed(runner, f"{tx.line}: transaction {tx.name}: {exc}")
            return
        except LinkDown as exc:
            self._failed(runner, f"{tx.line}: transaction {tx.name}: {exc}")
            self._down(str(exc))
            return
        except Exception as exc:        # a bug or an unforeseen library error
            runner.count_error()        # logged by _crashed, once
            self._crashed(exc, f"{tx.line}: transaction {tx.name}: ")
            return
        if not tx.is_write:
            runner.publish(result)
        self._recovered()
        runner.ok_count += 1
        self.retry.succeeded()
        if runner.failing and tx.debug >= DEBUG_ERR:
            log.warning("%s: transaction %s: ok again", tx.line, tx.name)
        elif tx.debug >= DEBUG_DEBUG:
            log.debug("transaction %s: ok %s", tx.name, result or values)
        runner.failing = False

    def _failed(self, runner: TxRunner, text: str) -> None:
        runner.count_error()
        tx = runner.tx
        if tx.debug >= DEBUG_ERR and (not runner.failing
                                      or tx.debug >= DEBUG_DEBUG):
            log.error("%s", text)
        runner.failing = True

    # -- loop --------------------------------------------------------------
    def run(self) -> None:
        try:
            while not self.stop.is_set():
                try:
                    if not self.cycle():
                        self._idle()
                except Exception as exc:
                    self._crashed_outside(exc)
        finally:
            self.go_safe()
            self.conn.close()

    def go_safe(self) -> None:
        """The safe state, when the link stops for any reason (SIGTERM,
        ``unloadusr``, the HAL host gone): every coil that a write
        transaction (functions 5, 15) drives is written OFF once, if the
        link is open.  Registers are left as they are: a zero register is
        not safe for every device (use the device's own communication
        watchdog for those)."""
        if not self.conn.is_open:
            return
        for runner in self.runners:
            tx = runner.tx
            if tx.function not in (5, 15) or tx.unusable:
                continue
            try:
                self.conn.execute(tx, [0] * tx.count)
            except Exception as exc:    # the device may be gone already
                if self.debug >= DEBUG_ERR:
                    log.error("%s: transaction %s: coils OFF at stop: %s",
                              tx.line, tx.name,
                              str(exc) or type(exc).__name__)

    def _crashed(self, exc: Exception, where: str = "") -> None:
        """An unexpected error: log it once, close the connection and
        pause (0.1 s, doubling while it goes on), so that the link never
        dies silently nor floods the log."""
        text = where + _internal(self.link, exc)
        if text not in self.crashes and self.debug >= DEBUG_ERR:
            log.error("%s (logged once)", text)
            log.debug("%s", text, exc_info=True)
        self.crashes.add(text)
        self.conn.close()
        self.stop.wait(self.crash_pause.failed(time.monotonic()))

    def _crashed_outside(self, exc: Exception) -> None:
        """An unexpected error between transactions counts one error on
        every transaction of the link."""
        for runner in self.runners:
            try:
                runner.count_error()
            except Exception:           # e.g. the component is gone
                pass
        self._crashed(exc)

    def cycle(self) -> bool:
        """Run every due transaction once; False when none was run."""
        ran = False
        for runner in self.runners:
            if self.stop.is_set():
                break
            now = time.monotonic()
            if now < runner.next_due:
                continue
            if not self.conn.is_open and not runner.tx.unusable:
                if not self.retry.ready(now) or not self._connect(runner):
                    break
            period = runner.period
            if runner.tx.unusable:      # no I/O to pace it: no busy loop
                period = max(period, UNUSABLE_PERIOD)
            runner.next_due = now + period
            self.transact(runner)
            ran = True
            pause = self.slowdown
            if self.link.kind == "serial":
                pause += runner.tx.serial_delay_ms / 1000.0
            if pause:
                self.stop.wait(pause)
        return ran

    def _idle(self) -> None:
        wake = min(r.next_due for r in self.runners)
        if not self.conn.is_open:
            wake = max(wake, self.retry.next_attempt)
        wait = wake - time.monotonic()
        self.stop.wait(min(max(wait, 0.0005), 0.1))


def _internal(link: Link, exc: Exception) -> str:
    """One line for an unexpected exception on ``link``."""
    what = type(exc).__name__
    text = " ".join(str(exc).split())[:100]
    if text:
        what += f": {text}"
    return f"{link.describe()}: internal error: {what}"


class Mb2hal:
    """The component ``name`` (default: HAL_MODULE_NAME) for a parsed
    :class:`Config`; :meth:`start` creates the pins and starts one worker
    thread per link, :meth:`stop` ends them."""

    def __init__(self, config: Config, name: Optional[str] = None,
                 instance: Optional[str] = None, backoff: float = 0.1,
                 backoff_max: float = 2.0):
        self.config = config
        self.name = name or config.module_name
        self.instance = instance
        self.backoff = backoff
        self.backoff_max = backoff_max
        self.comp: Optional[Component] = None
        self.runners: list[TxRunner] = []
        self.workers: list[LinkWorker] = []
        self._stop = threading.Event()

    def create(self) -> Component:
        """Create the component and all pins and mark it ready."""
        comp = component(self.name, self.name, self.instance)
        try:
            for tx in self.config.transactions:
                for pin, type_, direction in pin_specs(
                        tx, self.config.version):
                    comp.newpin(pin, type_, direction)
                    if pin.endswith(".bit-inv"):
                        comp[pin] = True
            comp.ready()
        except BaseException:
            comp.exit()
            raise
        self.comp = comp
        self.runners = [TxRunner(tx, comp, self.config.version)
                        for tx in self.config.transactions]
        return comp

    def start(self) -> None:
        """Create the component (if needed) and start the link threads."""
        if self.comp is None:
            self.create()
        self._stop.clear()
        by_link: dict[tuple, list[TxRunner]] = {}
        for runner in self.runners:
            by_link.setdefault(runner.tx.link.key, []).append(runner)
        self.workers = [
            LinkWorker(runners[0].tx.link, runners, self.config.slowdown,
                       self._stop, self.backoff, self.backoff_max)
            for runners in by_link.values()]
        for worker in self.workers:
            worker.thread.start()

    def stop(self) -> None:
        """Stop the link threads (each ends within one request timeout)
        and remove the component."""
        self._stop.set()
        for worker in self.workers:
            limit = max(r.tx.response_timeout_ms for r in worker.runners)
            worker.thread.join(2 * limit / 1000.0 + 1.0)
        self.workers = []
        if self.comp is not None:
            if self.comp.exists:
                self.comp.exit()
            self.comp = None

    @property
    def transactions_done(self) -> int:
        """Successful transactions since start (all links)."""
        return sum(r.ok_count for r in self.runners)

    def run(self) -> None:
        """Start, then serve until SIGTERM/SIGINT, ``unloadusr`` or the
        end of the HAL host; coils go OFF then (:meth:`LinkWorker.go_safe`)."""
        with StopSignals() as signals:
            try:
                self.start()
                while not signals.caught:
                    if self.comp is None or not self.comp.exists:
                        break
                    if self.comp.host_gone:     # said on stderr by the core
                        break
                    time.sleep(0.02)
            finally:
                self.stop()
