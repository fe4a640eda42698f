"""The ``can-dbc`` driver: received frames decoded to out pins, in pins
encoded and sent cyclically, receive timeouts, bus faults."""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from typing import Any, Callable, Optional

import can
from cantools.database.can import Message

from halsdk.driverkit import Driver, DriverError

from .dbc import ConfigError, SignalPin
from .names import NameClash, unique_names
from .options import Config

log = logging.getLogger("halsdk.driverkit")

#: per-message pins that signals may not take
RESERVED = ("timeout", "count")
#: bus-level counters (u32, out)
COUNTERS = ("rx-unknown", "rx-errors", "tx-errors")
#: frames read per cycle at most, so a flooded bus cannot stall the loop
MAX_FRAMES_PER_CYCLE = 2000


class _Port:
    """One message and its pins, with its timing state."""

    def __init__(self, message: Message, name: str,
                 signals: list[SignalPin]):
        self.message = message
        self.name = name
        self.signals = signals
        self.by_signal = {sp.signal.name: sp for sp in signals}
        self.key = (message.frame_id, bool(message.is_extended_frame))
        self.period = 0.0        # tx
        self.next_due = 0.0      # tx
        self.last_sent: Optional[dict[str, Any]] = None
        self.timeout = 0.0       # rx
        self.last_seen = 0.0     # rx


def build_ports(messages: Sequence[Message], path: str) -> list[_Port]:
    """Ports with HAL names; a name clash raises :class:`ConfigError`."""
    try:
        names = unique_names([m.name for m in messages], "message")
        ports = []
        for message in messages:
            if message.is_container:
                raise NameClash(f"message {message.name!r} is a container "
                                "message, which is not supported")
            try:
                signal_names = unique_names(
                    [s.name for s in message.signals], "signal", RESERVED)
            except NameClash as exc:
                raise NameClash(f"message {message.name!r}: {exc}") from None
            mname = names[message.name]
            ports.append(_Port(message, mname, [
                SignalPin(message, s, f"{mname}.{signal_names[s.name]}")
                for s in message.signals]))
    except NameClash as exc:
        raise ConfigError(f"{path}: {exc}") from None
    return ports


class CanDbcDriver(Driver):
    """CAN messages of a DBC file as pins ``candbc.<num>.<msg>.<sig>``."""

    name = "candbc"

    def __init__(self, config: Config, instance: Optional[str] = None,
                 clock: Callable[[], float] = time.monotonic):
        super().__init__(config.num, instance, comp_name=config.name)
        self.config = config
        self.clock = clock
        self.bus: Optional[can.BusABC] = None
        ports = build_ports([*config.rx, *config.tx],
                            config.dbc_name or config.dbc_path)
        self.rx = ports[:len(config.rx)]
        self.tx = ports[len(config.rx):]
        for port in self.rx:
            port.timeout = config.timeouts.get(port.message.name, 0.0)
        for port in self.tx:
            port.period = config.periods.get(port.message.name, 0.0)
        self.rx_by_key = {port.key: port for port in self.rx}
        self._logged: set[str] = set()

    # -- component -----------------------------------------------------------
    def setup(self) -> None:
        comp = self._require()
        for pin in COUNTERS:
            comp.newpin(pin, "u32", "out")
        for port in self.rx:
            for sp in port.signals:
                comp.newpin(sp.pin, sp.type, "out")
            comp.newpin(f"{port.name}.timeout", "bit", "out")
            comp.newpin(f"{port.name}.count", "u32", "out")
        for port in self.tx:
            for sp in port.signals:
                comp.newpin(sp.pin, sp.type, "in")
            comp.newpin(f"{port.name}.count", "u32", "out")

    # -- bus -----------------------------------------------------------------
    def open(self) -> None:
        cfg = self.config
        kwargs: dict[str, Any] = {"interface": cfg.interface,
                                  "channel": cfg.channel}
        if cfg.bitrate:
            kwargs["bitrate"] = cfg.bitrate
        try:
            self.bus = can.Bus(**kwargs)
        except (can.CanError, OSError, ValueError, ImportError) as exc:
            raise DriverError(f"cannot open {cfg.interface} channel "
                              f"{cfg.channel}: {exc}") from None
        now = self.clock()
        for port in self.rx:
            port.last_seen = now
        for port in self.tx:
            port.next_due = now          # send at once, then every period
            port.last_sent = None

    def close(self) -> None:
        bus, self.bus = self.bus, None
        if self.comp is not None:        # no bus, no fresh data
            for port in self.rx:
                self.comp[f"{port.name}.timeout"] = True
        if bus is not None:
            bus.shutdown()

    # -- receive -------------------------------------------------------------
    def read(self) -> None:
        bus = self.bus
        if bus is None:
            raise DriverError("bus not open")
        for _ in range(MAX_FRAMES_PER_CYCLE):
            try:
                frame = bus.recv(timeout=0.0)
            except (can.CanError, OSError) as exc:
                raise DriverError(f"bus receive: {exc}") from None
            if frame is None:
                break
            self.handle_frame(frame)
        self.check_timeouts()

    def _bump(self, pin: str) -> None:
        comp = self._require()
        comp[pin] = (comp[pin] + 1) & 0xFFFFFFFF

    def _log_once(self, key: str, text: str) -> None:
        if key not in self._logged:
            self._logged.add(key)
            log.error("%s: %s", self.prefix, text)

    def handle_frame(self, frame: can.Message) -> None:
        """Decode one received frame into the pins of its message."""
        port = None
        if not (frame.is_error_frame or frame.is_remote_frame):
            port = self.rx_by_key.get((frame.arbitration_id,
                                       bool(frame.is_extended_id)))
        if port is None:
            self._bump("rx-unknown")
            return
        data = bytes(frame.data)
        message = port.message
        try:
            if len(data) != message.length:
                raise ValueError(f"{len(data)} data bytes, expected "
                                 f"{message.length}")
            # decode() of a non-container message, typed as a dict
            raw = message.decode_simple(data, decode_choices=False,
                                        scaling=False)
        except Exception as exc:     # never let a frame stop the loop
            self._bump("rx-errors")
            self._log_once(f"rx:{message.name}:{type(exc).__name__}",
                           f"message {message.name}: bad frame: {exc} "
                           "(further ones only counted in rx-errors)")
            return
        comp = self._require()
        for signal_name, value in raw.items():
            sp = port.by_signal.get(signal_name)
            if sp is not None:
                comp[sp.pin] = sp.from_raw(value)
        port.last_seen = self.clock()
        comp[f"{port.name}.timeout"] = False
        self._bump(f"{port.name}.count")

    def check_timeouts(self) -> None:
        now = self.clock()
        comp = self._require()
        for port in self.rx:
            if port.timeout > 0 and now - port.last_seen > port.timeout:
                comp[f"{port.name}.timeout"] = True

    # -- transmit ------------------------------------------------------------
    def write(self) -> None:
        bus = self.bus
        if bus is None:
            raise DriverError("bus not open")
        now = self.clock()
        comp = self._require()
        for port in self.tx:
            raw = {sp.signal.name: sp.to_raw(comp[sp.pin])
                   for sp in port.signals}
            due = port.period > 0 and now >= port.next_due
            first = port.last_sent is None
            changed = self.config.on_change and raw != port.last_sent
            if not (due or first or changed):
                continue
            if port.period > 0:
                # keep the rhythm; an event send or a late cycle restarts it
                port.next_due = port.next_due + port.period if due else now
                if port.next_due <= now:
                    port.next_due = now + port.period
            self.send(port, raw)

    def send(self, port: _Port, raw: dict[str, Any]) -> None:
        """Encode and send one message (encoding errors are counted)."""
        message = port.message
        try:
            data = message.encode(raw, scaling=False, padding=False,
                                  strict=False)
        except Exception as exc:
            self._bump("tx-errors")
            self._log_once(f"tx:{message.name}:{type(exc).__name__}",
                           f"message {message.name}: cannot encode: {exc} "
                           "(further ones only counted in tx-errors)")
            port.last_sent = raw
            return
        frame = can.Message(arbitration_id=message.frame_id,
                            is_extended_id=bool(message.is_extended_frame),
                            is_fd=bool(message.is_fd), data=data)
        bus = self.bus
        if bus is None:
            raise DriverError("bus not open")
        try:
            bus.send(frame)
        except (can.CanError, OSError) as exc:
            raise DriverError(f"bus send: {exc}") from None
        port.last_sent = raw
        self._bump(f"{port.name}.count")
