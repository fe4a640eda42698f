"""``Hm2Sim``: the simulated card as a UDP server in a background thread."""

from __future__ import annotations

import errno
import heapq
import random
import socket
import struct
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Optional, TextIO, Union

from . import lbp16
from .card import TABLE_MODE, Card, Coupling, Switch
from .profiles import Profile, profile

#: the longest a select() of the server thread waits, so stop() is prompt
_POLL = 0.05
#: the longest the server thread may take to stop
STOP_TIMEOUT = 5.0
#: the kernel's receive timestamp of a datagram (Linux: SO_TIMESTAMPNS)
_SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)
_ANCILLARY = socket.CMSG_SPACE(16)


class SimError(RuntimeError):
    """The simulated card cannot start (one line, for the user)."""


@dataclass
class Fault:
    """One fault mode: applies to the next ``count`` replies, and then to
    each reply with ``probability``."""

    count: int = 0
    probability: float = 0.0

    def fire(self, rng: random.Random) -> bool:
        if self.count > 0:
            self.count -= 1
            return True
        return self.probability > 0 and rng.random() < self.probability

    @property
    def active(self) -> bool:
        return self.count > 0 or self.probability > 0


class Faults:
    """The faults of the link, set from a test or the command line.

    ``lose`` (datagrams to the card), ``drop``, ``duplicate``, ``truncate``
    and ``delay`` (its replies) each take either ``next=N`` (the next N)
    or ``probability=P`` (each), or both.  ``delay`` also takes the delay
    in ``seconds``; ``truncate`` the number of bytes to keep (``keep``,
    default half of the reply).
    """

    def __init__(self, seed: Optional[int] = None) -> None:
        self.rng = random.Random(seed)
        self.dropped = Fault()
        self.lost = Fault()
        self.duplicated = Fault()
        self.truncated = Fault()
        self.delayed = Fault()
        self.delay_seconds = 0.0
        self.truncate_keep: Optional[int] = None
        self.away = False

    @staticmethod
    def _set(fault: Fault, next: int, probability: float) -> None:
        if next < 0:
            raise ValueError(f"next={next}: expected a count >= 0")
        if not 0.0 <= probability <= 1.0:
            raise ValueError(f"probability={probability}: expected 0..1")
        fault.count = next
        fault.probability = probability

    def drop(self, next: int = 0, probability: float = 0.0) -> None:
        """The card does what a datagram asks but its reply is lost."""
        self._set(self.dropped, next, probability)

    def lose(self, next: int = 0, probability: float = 0.0) -> None:
        """Datagrams are lost on the way to the card (reads and writes
        alike): the card never sees them."""
        self._set(self.lost, next, probability)

    def duplicate(self, next: int = 0, probability: float = 0.0) -> None:
        self._set(self.duplicated, next, probability)

    def truncate(self, next: int = 0, probability: float = 0.0,
                 keep: Optional[int] = None) -> None:
        if keep is not None and keep < 0:
            raise ValueError(f"keep={keep}: expected bytes >= 0")
        self._set(self.truncated, next, probability)
        self.truncate_keep = keep

    def delay(self, seconds: float, next: int = 0,
              probability: float = 0.0) -> None:
        if not 0.0 <= seconds <= 60.0:
            raise ValueError(f"delay of {seconds} s: expected 0..60 s")
        self._set(self.delayed, next, probability)
        self.delay_seconds = seconds

    def clear(self) -> None:
        """No faults (the card stays away if it is away)."""
        for f in (self.dropped, self.lost, self.duplicated, self.truncated,
                  self.delayed):
            f.count, f.probability = 0, 0.0


@dataclass(frozen=True)
class Stats:
    requests: int
    replies: int
    dropped: int
    duplicated: int
    truncated: int
    delayed: int
    ignored: int            # requests while away
    lost: int               # requests lost on the way (faults.lose)
    malformed: int


class Hm2Sim:
    """A simulated Mesa Ethernet card answering LBP16 on UDP.

    ``Hm2Sim(board="7i96s", address="127.0.0.1", port=27181)``; port 0
    takes a free port (see :attr:`port`).  Use it as a context manager
    or call :meth:`start` and :meth:`stop`.  With ``realtime=True`` (the
    default) the card's clock follows the wall clock; with ``False`` it
    moves only by :meth:`step`.  ``log`` (a path or an open text file)
    records every datagram in both directions, decoded.
    """

    def __init__(self, board: Union[str, Profile] = "7i96s",
                 address: str = "127.0.0.1", port: int = lbp16.PORT,
                 realtime: bool = True,
                 log: Union[str, Path, TextIO, None] = None,
                 seed: Optional[int] = None) -> None:
        self.profile = board if isinstance(board, Profile) else profile(board)
        self.card = Card(self.profile)
        self.address = address
        self._port = port
        self.realtime = realtime
        self.faults = Faults(seed)
        self._lock = threading.RLock()
        self._arrived = threading.Condition(self._lock)
        self._sock: Optional[socket.socket] = None
        self._thread: Optional[threading.Thread] = None
        self._stop = threading.Event()
        self._t0 = 0.0
        self._wall0 = 0.0
        self._pending: list[tuple[float, int, bytes, tuple[str, int]]] = []
        self._seq = 0
        self._log_path = log if isinstance(log, (str, Path)) else None
        self._log: Optional[TextIO] = None if self._log_path else log  # type: ignore[assignment]
        self._own_log = False
        self._counts = dict.fromkeys(Stats.__dataclass_fields__, 0)
        self.error: Optional[BaseException] = None

    # --- life cycle --------------------------------------------------
    @property
    def port(self) -> int:
        """The UDP port it listens on (the real one once started)."""
        return self._port

    def start(self) -> Hm2Sim:
        if self._thread is not None:
            raise SimError("the simulated card is already running")
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            sock.bind((self.address, self._port))
        except OSError as exc:
            sock.close()
            if exc.errno == errno.EADDRINUSE:
                raise SimError(
                    f"UDP {self.address}:{self._port} is in use (another "
                    "hm2-sim or card simulator?); choose another --port "
                    "or --address") from None
            raise SimError(f"cannot listen on UDP {self.address}:"
                           f"{self._port}: {exc.strerror}") from None
        try:
            sock.setsockopt(socket.SOL_SOCKET, _SO_TIMESTAMPNS, 1)
        except OSError:
            pass                    # no kernel timestamps: the thread's
        self._sock = sock
        self._port = sock.getsockname()[1]
        if self._log_path is not None:
            try:
                self._log = open(self._log_path, "w", encoding="utf-8")
            except OSError as exc:
                sock.close()
                raise SimError(f"cannot write the packet log "
                               f"{self._log_path}: {exc.strerror}") from None
            self._own_log = True
        self._set_epoch()
        self._stop.clear()
        self._thread = threading.Thread(target=self._serve,
                                        name=f"hm2-sim {self.profile.key}",
                                        daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop answering and close the socket (bounded wait)."""
        thread = self._thread
        if thread is None:
            return
        self._stop.set()
        thread.join(STOP_TIMEOUT)
        self._thread = None
        if self._sock is not None:
            self._sock.close()
            self._sock = None
        if self._log is not None:
            if self._own_log:
                self._log.close()
                self._log = None
            else:
                self._log.flush()

    def __enter__(self) -> Hm2Sim:
        return self.start()

    def __exit__(self, exc_type: Optional[type[BaseException]],
                 exc: Optional[BaseException],
                 tb: Optional[TracebackType]) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    # --- the server thread -------------------------------------------
    def _now(self) -> float:
        return time.monotonic() - self._t0

    def _set_epoch(self) -> None:
        """Card time 0: now (monotonic; the wall clock of the same
        moment converts the kernel's receive timestamps)."""
        self._t0 = time.monotonic()
        self._wall0 = time.time() - (time.monotonic() - self._t0)

    def _serve(self) -> None:
        sock = self._sock
        assert sock is not None
        try:
            while not self._stop.is_set():
                timeout = _POLL
                if self._pending:
                    timeout = min(timeout, max(1e-4, self._pending[0][0]
                                               - time.monotonic()))
                sock.settimeout(timeout)
                try:
                    packet, ancillary, _, peer = sock.recvmsg(
                        65536, _ANCILLARY)
                except (socket.timeout, BlockingIOError):
                    self._send_due(sock)
                    continue
                except OSError:
                    continue
                try:
                    self._handle(sock, packet, peer,
                                 self._arrival(ancillary))
                except Exception as exc:        # noqa: BLE001
                    # a bug in the model must not take the card down
                    # silently: keep serving, keep the first error
                    if self.error is None:
                        self.error = exc
                if self._pending:
                    self._send_due(sock)
        except BaseException as exc:        # noqa: BLE001 - kept for stop()
            self.error = exc

    def _send_due(self, sock: socket.socket) -> None:
        now = time.monotonic()
        while self._pending and self._pending[0][0] <= now:
            _, _, data, peer = heapq.heappop(self._pending)
            self._send(sock, data, peer)

    def _send(self, sock: socket.socket, data: bytes,
              peer: tuple[str, int]) -> None:
        try:
            sock.sendto(data, peer)
        except OSError:
            pass

    def _logline(self, text: str) -> None:
        # buffered: flushed when the card stops (a flush per datagram
        # would cost the next reply a system call)
        if self._log is not None:
            self._log.write(text + "\n")

    def _arrival(self, ancillary: list[tuple[int, int, bytes]]
                 ) -> Optional[float]:
        """The card time at which the kernel received a datagram (its
        SO_TIMESTAMPNS), so that a late server thread does not make the
        datagram late: the card acts on a datagram when it arrives."""
        for level, kind, data in ancillary:
            if (level == socket.SOL_SOCKET and kind == _SO_TIMESTAMPNS
                    and len(data) >= 16):
                sec, nsec = struct.unpack_from("@qq", data)
                return sec + nsec * 1e-9 - self._wall0
        return None

    def _handle(self, sock: socket.socket, packet: bytes,
                peer: tuple[str, int],
                arrival: Optional[float] = None) -> None:
        # the reply goes out first, the log is written after it: a driver
        # waits for the reply, not for the log
        now = self._now()
        stamp = now if arrival is None else min(arrival, now)
        note = ""
        reply = b""
        copies = 0
        delay = 0.0
        with self._lock:
            counts = self._counts
            counts["requests"] += 1
            self._arrived.notify_all()
            if self.faults.away:
                counts["ignored"] += 1
                note = "(away)"
            elif self.faults.lost.fire(self.faults.rng):
                counts["lost"] += 1
                note = "(lost)"
            else:
                try:
                    commands = lbp16.parse(packet)
                except lbp16.Lbp16Error as exc:
                    counts["malformed"] += 1
                    note = f"(malformed: {exc})"
                else:
                    if self.realtime:
                        self.card.advance_to(stamp)
                    reply = self.card.execute(commands)
            if reply:
                copies, delay, reply, note = self._faulty(reply)
        for _ in range(copies):
            if delay:
                self._seq += 1
                heapq.heappush(self._pending, (time.monotonic() + delay,
                                               self._seq, reply, peer))
            else:
                self._send(sock, reply, peer)
        if self._log is not None:
            took = (self._now() - stamp) * 1e6
            self._log_packet(stamp, packet, reply, note, took)

    def _faulty(self, reply: bytes) -> tuple[int, float, bytes, str]:
        """Copies, delay, data and log note of a reply after the faults."""
        f = self.faults
        counts = self._counts
        if f.dropped.fire(f.rng):
            counts["dropped"] += 1
            return 0, 0.0, reply, "(dropped)"
        notes = []
        if f.truncated.fire(f.rng):
            counts["truncated"] += 1
            keep = (f.truncate_keep if f.truncate_keep is not None
                    else len(reply) // 2)
            reply = reply[:keep]
            notes.append(f"(truncated to {len(reply)} bytes)")
        copies = 1
        if f.duplicated.fire(f.rng):
            counts["duplicated"] += 1
            copies = 2
            notes.append("(x2)")
        delay = 0.0
        if f.delayed.fire(f.rng):
            counts["delayed"] += 1
            delay = f.delay_seconds
            notes.append(f"(+{delay:g} s)")
        counts["replies"] += 1
        return copies, delay, reply, " ".join(notes)

    def _log_packet(self, stamp: float, packet: bytes, reply: bytes,
                    note: str, took: float) -> None:
        lines = [f"{stamp:10.6f} <- {packet.hex()}"]
        try:
            lines += [f"{'':13}{c.describe()}" for c in lbp16.decode(packet)]
        except lbp16.Lbp16Error:
            pass
        if reply or note:
            lines.append(f"{'':10} -> {reply.hex()} {note}".rstrip()
                         + (f" ({took:.0f} us)" if reply else ""))
        self._logline("\n".join(lines))

    # --- the card, from the test -------------------------------------
    def _sync(self) -> None:
        if self.realtime and self._thread is not None:
            self.card.advance_to(self._now())

    def step(self, seconds: float) -> None:
        """Advance the card's clock by ``seconds`` (``realtime=False``)."""
        if seconds < 0:
            raise ValueError("cannot step back in time")
        with self._lock:
            self.card.advance_to(self.card.time + seconds)

    def go_away(self, reset: bool = True) -> None:
        """The card stops answering (unplugged or powered off); with
        ``reset`` it comes back powered on again: its registers in their
        power-on state (stepgen accumulators and encoder counts at 0),
        the machine's axes where they were."""
        with self._lock:
            self.faults.away = True
            self._away_reset = reset

    def come_back(self) -> None:
        """The card answers again."""
        with self._lock:
            if self.faults.away and getattr(self, "_away_reset", True):
                self.card.power_cycle()
                self._set_epoch()
            self.faults.away = False

    @property
    def requests(self) -> int:
        """The number of datagrams received so far."""
        return self._counts["requests"]

    def wait_requests(self, count: int, timeout: float = 1.0) -> bool:
        """Wait until ``count`` datagrams have been received in all (see
        :attr:`requests`), at most ``timeout`` seconds; whether they
        were."""
        with self._arrived:
            return self._arrived.wait_for(
                lambda: self._counts["requests"] >= count, timeout)

    @property
    def stats(self) -> Stats:
        with self._lock:
            return Stats(**self._counts)

    def set_input(self, pin: int, level: bool) -> None:
        """The field level of I/O pin ``pin`` (its input)."""
        with self._lock:
            self._check_pin(pin)
            self.card.set_input(pin, bool(level))

    def pin(self, pin: int) -> bool:
        """The level of I/O pin ``pin`` (an output's driven level)."""
        with self._lock:
            self._check_pin(pin)
            self._sync()
            return self.card.pin_level(pin)

    def is_output(self, pin: int) -> bool:
        with self._lock:
            self._check_pin(pin)
            return self.card.is_output(pin)

    def _check_pin(self, pin: int) -> None:
        if not 0 <= pin < self.card.npins:
            raise IndexError(f"I/O pin {pin}: the {self.profile.key} has "
                             f"pins 0..{self.card.npins - 1}")

    def _check(self, kind: str, n: int, items: list[object]) -> None:
        if not 0 <= n < len(items):
            raise IndexError(f"{kind} {n}: the {self.profile.key} has "
                             f"{len(items)}")

    def axis_position(self, n: int) -> float:
        """Position of stepgen ``n``'s axis, in steps."""
        with self._lock:
            self._check("stepgen", n, self.card.stepgens)  # type: ignore[arg-type]
            self._sync()
            return self.card.axis_steps(n)

    def stepgen(self, n: int) -> dict[str, float]:
        """The registers and position of stepgen ``n``; in table mode
        (``mode`` 3) ``table_index`` is the step table's entry on the
        pins and ``table_output`` its value (bit k: module pin k + 1);
        :meth:`step_table` lists the entries."""
        with self._lock:
            self._check("stepgen", n, self.card.stepgens)  # type: ignore[arg-type]
            self._sync()
            sg = self.card.stepgens[n]
            return {"position": self.card.axis_steps(n),
                    "accumulator": sg.steps, "rate": sg.rate,
                    "steps_per_second": sg.rate * self.card.clock / 2**32,
                    "mode": sg.mode, "dir_setup": sg.dir_setup,
                    "dir_hold": sg.dir_hold, "step_len": sg.step_len,
                    "step_space": sg.step_space,
                    "table_length": sg.table_length
                    if sg.mode & 3 == TABLE_MODE else 0,
                    "table_index": sg.table_index,
                    "table_output": sg.table_output}

    def step_table(self, n: int) -> list[int]:
        """The step table of stepgen ``n`` as loaded: its
        ``table_length`` entries (all 16 out of table mode)."""
        with self._lock:
            self._check("stepgen", n, self.card.stepgens)  # type: ignore[arg-type]
            sg = self.card.stepgens[n]
            return list(sg.table_data[:sg.table_length
                                      if sg.mode & 3 == TABLE_MODE
                                      else len(sg.table_data)])

    def set_encoder(self, n: int, counts: int) -> None:
        """Move encoder ``n``'s simulated position to ``counts``."""
        with self._lock:
            self._check("encoder", n, self.card.encoders)  # type: ignore[arg-type]
            self._sync()
            self.card.set_encoder(n, counts)

    def encoder(self, n: int) -> dict[str, int]:
        with self._lock:
            self._check("encoder", n, self.card.encoders)  # type: ignore[arg-type]
            self._sync()
            e = self.card.encoders[n]
            return {"position": e.position, "count": e.count,
                    "latch": e.latch, "control": e.control,
                    "index_events": e.events}

    def set_encoder_velocity(self, n: int, counts_per_second: float) -> None:
        with self._lock:
            self._check("encoder", n, self.card.encoders)  # type: ignore[arg-type]
            self._sync()
            self.card.encoders[n].velocity = float(counts_per_second)

    def set_index_period(self, n: int, counts: int) -> None:
        """An index pulse every ``counts`` counts (0: none)."""
        if counts < 0:
            raise ValueError("the index period is >= 0 counts")
        with self._lock:
            self._check("encoder", n, self.card.encoders)  # type: ignore[arg-type]
            self.card.encoders[n].index_period = int(counts)

    def pulse_index(self, n: int) -> None:
        """An index pulse of encoder ``n`` now."""
        with self._lock:
            self._check("encoder", n, self.card.encoders)  # type: ignore[arg-type]
            self._sync()
            self.card.pulse_index(n)

    def couple(self, encoder: int, stepgen: int,
               counts_per_step: float = 1.0) -> None:
        """Drive encoder ``encoder`` from stepgen ``stepgen``'s axis."""
        with self._lock:
            self._check("encoder", encoder, self.card.encoders)  # type: ignore[arg-type]
            self._check("stepgen", stepgen, self.card.stepgens)  # type: ignore[arg-type]
            self.card.couplings.append(Coupling(
                encoder, stepgen, counts_per_step,
                self.card.axis_steps(stepgen),
                self.card.encoders[encoder].position))

    def add_switch(self, pin: int, stepgen: int, at: float,
                   above: bool = True, on_level: bool = True) -> None:
        """A switch on stepgen ``stepgen``'s axis wired to input ``pin``:
        on when the axis is at ``at`` steps or beyond (above it, or below
        it with ``above=False``); the pin reads ``on_level`` when the
        switch is on (``False`` for a normally closed switch), the
        opposite otherwise.  Home and limit switches of a machine."""
        with self._lock:
            self.card.add_switch(Switch(pin, stepgen, float(at), above,
                                        on_level))

    def pwm_duty(self, n: int) -> float:
        with self._lock:
            self._check("pwmgen", n, self.card.pwm_value)  # type: ignore[arg-type]
            return self.card.pwm_duty(n)

    @property
    def watchdog_bitten(self) -> bool:
        with self._lock:
            self._sync()
            return self.card.watchdog.bitten

    @property
    def leds(self) -> int:
        with self._lock:
            return self.card.leds
