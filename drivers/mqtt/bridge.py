"""The bridge: a HAL component that scans items, publishes them through a
:class:`~halsdk.drivers.mqtt.client.Link` and applies received values."""

from __future__ import annotations

import logging
import math
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable, Optional

from halsdk import Hal
from halsdk.component import Component, component
from halsdk.driverkit.signals import StopSignals
from halsdk.errors import HalError
from halsdk.types import type_word

from . import payload
from .client import Link
from .config import BridgeConfig, ConfigError, Subscription, check

log = logging.getLogger("halsdk.driverkit.mqtt")

#: values of the fault-code pin
FAULT_NONE, FAULT_CONNECT, FAULT_REFUSED, FAULT_LOST = 0, 1, 2, 3
COUNTERS = ("published", "received", "bad-payloads", "dropped",
            "reconnects")
STATUS_PINS = ("connected", "fault", "fault-code", "lastpublish", *COUNTERS)
U32 = 0xFFFFFFFF


@dataclass
class Item:
    """A published pin, param or signal."""

    name: str
    obj: Any
    type: str
    last: Any = None
    sent: bool = False


def _same(a: Any, b: Any) -> bool:
    return a == b or (isinstance(a, float) and isinstance(b, float)
                      and math.isnan(a) and math.isnan(b))


class Bridge:
    """One ``mqtt-bridge`` (or ``mqtt-publisher``) component.

    :meth:`start` creates the component and its pins, finds the items and
    starts connecting; :meth:`cycle` does one scan (tests call it
    directly); :meth:`run` cycles every ``cfg.poll`` seconds until stopped.
    """

    def __init__(self, cfg: BridgeConfig, instance: Optional[str] = None,
                 out: Callable[[str], None] = print):
        self.cfg = cfg
        self._instance = instance
        self._out = out
        self.comp: Optional[Component] = None
        self.link: Optional[Link] = None
        self.items: list[Item] = []
        self.subs: dict[str, Subscription] = {}
        self.batch_topic = f"{cfg.topic_prefix}/set"
        self.ever_up = False
        self.fault_text = ""
        self._bad_logged: set[str] = set()
        self._dropped_seen = 0
        self._dropping = False
        self._next_batch = 0.0
        self._stop = threading.Event()

    # -- setup -------------------------------------------------------------
    def start(self) -> Component:
        """Create the component, resolve items, start the MQTT link."""
        cfg = self.cfg
        check(cfg, cfg.name)
        comp = component(cfg.name, cfg.name, self._instance)
        self.comp = comp
        try:
            self._pins(comp)
            self.items = [self._resolve(kind, name)
                          for kind, name in cfg.publish]
            if not cfg.dryrun:
                topics = [*self.subs]
                if self.subs:
                    topics.append(self.batch_topic)
                self.link = Link(cfg, topics, "" if cfg.publisher
                                 else f"{cfg.topic_prefix}/status")
            comp.ready()
        except BaseException:
            comp.exit()
            self.comp = None
            raise
        if self.link is not None:
            self.link.start()
        self._next_batch = time.monotonic()
        return comp

    def _pins(self, comp: Component) -> None:
        cfg = self.cfg
        comp.newpin("enable", "bit", "in")
        comp["enable"] = True
        if cfg.publisher:
            comp.newpin("period", "u32", "in")
            comp["period"] = int(cfg.period)
        else:
            comp.newpin("period", "float", "in")
            comp["period"] = cfg.period
        for pin in STATUS_PINS:
            comp.newpin(pin, "bit" if pin in ("connected", "fault")
                        else "u32", "out")
        for sub in cfg.subscribe:
            if sub.pin in comp:
                raise ConfigError(f"{sub.where}: pin name {sub.pin!r} is "
                                  "taken by the bridge's own pins")
            comp.newpin(sub.pin, sub.type, "out")
            self.subs[cfg.sub_topic(sub)] = sub

    def _resolve(self, kind: str, name: str) -> Item:
        kinds = [kind] if kind else ["pin", "param", "signal"]
        hal = Hal.current()
        for k in kinds:
            obj = hal.find(k, name) if hal is not None else None
            if obj is not None:
                return Item(name, obj, type_word(obj.type))
        what = kind or "pin, param or signal"
        raise ConfigError(f"{self.cfg.name}: key {name!r}: no {what} of "
                          "that name")

    # -- one scan ----------------------------------------------------------
    def cycle(self) -> None:
        """Apply what the network thread reported, then publish."""
        comp = self.comp
        if comp is None:
            raise RuntimeError("call start() before cycle()")
        if self.link is not None:
            events = self.link.events
            while events:
                self._event(events.popleft())
            self._note_dropped(self.link.dropped)
        if not comp["enable"]:
            for item in self.items:
                item.sent = False
            return
        values = self._read()
        now = time.time()
        if self.cfg.on_change:
            for item, value in values:
                if not item.sent or not _same(value, item.last):
                    msg = payload.single(item.name, item.type, value, now)
                    if self._send(f"{self.cfg.topic_prefix}/{item.name}",
                                  msg):
                        item.last, item.sent = value, True
        period = float(comp["period"])
        mono = time.monotonic()
        if period > 0 and mono >= self._next_batch:
            batch = {item.name: value for item, value in values}
            if self._send(self.cfg.topic_prefix,
                          payload.batch(batch, now, self.cfg.flat)):
                self._next_batch = max(self._next_batch + period, mono)
                comp["lastpublish"] = int(now) & U32
        elif period <= 0:
            self._next_batch = mono

    def _read(self) -> list[tuple[Item, Any]]:
        values = []
        for item in list(self.items):
            try:
                values.append((item, item.obj.value))
            except HalError:
                log.warning("%s: %s %r is gone; no longer published",
                            self.cfg.name, type(item.obj).__name__.lower(),
                            item.name)
                self.items.remove(item)
        return values

    def _component(self) -> Component:
        """The component made by :meth:`start` (RuntimeError before)."""
        if self.comp is None:
            raise RuntimeError(f"{self.cfg.name}: call start() first")
        return self.comp

    def _send(self, topic: str, text: str) -> bool:
        if self.cfg.dryrun:
            self._out(f"{topic} {text}")
        else:
            if self.link is None:
                raise RuntimeError(f"{self.cfg.name}: no MQTT link (call "
                                   "start() first)")
            if not self.link.publish(topic, text):
                return False
        self._count("published")
        return True

    def _note_dropped(self, dropped: int) -> None:
        """Publish the count of messages dropped for arriving faster than
        the scans apply them; say so once per burst."""
        if dropped == self._dropped_seen:
            self._dropping = False          # a scan without new drops
            return
        if not self._dropping:
            log.warning("%s: messages arrive faster than they are applied; "
                        "dropping some (see %s.dropped)", self.cfg.name,
                        self.cfg.name)
            self._dropping = True
        self._dropped_seen = dropped
        self._component()["dropped"] = dropped & U32

    def _count(self, pin: str) -> None:
        comp = self._component()
        comp[pin] = (comp[pin] + 1) & U32

    # -- events from the network thread -------------------------------------
    def _event(self, event: tuple) -> None:
        comp = self._component()
        kind = event[0]
        where = f"{self.cfg.broker}:{self.cfg.broker_port}"
        if kind == "msg":
            self._message(event[1], event[2])
        elif kind == "up":
            comp["connected"] = True
            if self.ever_up:
                self._count("reconnects")
            self.ever_up = True
            for item in self.items:       # resend everything
                item.sent = False
            self._next_batch = time.monotonic()
            self._clear_fault(where)
        elif kind == "refused":
            comp["connected"] = False
            self._fault(FAULT_REFUSED, f"broker {where} refused the "
                        f"connection: {event[1]}")
        elif kind == "fail":
            comp["connected"] = False
            self._fault(FAULT_CONNECT, f"cannot connect to {where}: "
                        f"{event[1]}")
        elif kind == "lost":
            comp["connected"] = False
            self._fault(FAULT_LOST, f"connection to {where} lost: "
                        f"{event[1]}")

    def _fault(self, code: int, text: str) -> None:
        comp = self._component()
        comp["fault"] = True
        comp["fault-code"] = code
        if text != self.fault_text:
            log.error("%s: %s (retrying)", self.cfg.name, text)
            self.fault_text = text

    def _clear_fault(self, where: str) -> None:
        if self.fault_text:
            log.warning("%s: connected to %s again", self.cfg.name, where)
        else:
            log.info("%s: connected to %s", self.cfg.name, where)
        self.fault_text = ""
        comp = self._component()
        comp["fault"] = False
        comp["fault-code"] = FAULT_NONE

    def _message(self, topic: str, raw: bytes) -> None:
        self._count("received")
        try:
            updates = self._decode(topic, raw)
        except payload.PayloadError as exc:
            self._count("bad-payloads")
            if topic not in self._bad_logged:
                self._bad_logged.add(topic)
                log.warning("%s: bad payload on %r: %s (pin unchanged; "
                            "further bad payloads on this topic are only "
                            "counted)", self.cfg.name, topic, exc)
            return
        comp = self._component()
        for pin, value in updates:
            comp[pin] = value

    def _decode(self, topic: str, raw: bytes) -> list[tuple[str, Any]]:
        obj = payload.parse(raw)
        sub = self.subs.get(topic)
        if sub is not None:
            return [(sub.pin, payload.convert(payload.unwrap(obj, sub.type),
                                              sub.type))]
        if topic != self.batch_topic:
            raise payload.PayloadError("not a subscribed topic")
        if not isinstance(obj, dict):
            raise payload.PayloadError("expected an object "
                                       '{"pin": value, ...}')
        by_pin = {s.pin: s for s in self.subs.values()}
        updates = []
        for key, value in obj.items():
            sub = by_pin.get(key)
            if sub is None:
                raise payload.PayloadError(f"unknown key {key!r}")
            try:
                updates.append((key, payload.convert(value, sub.type)))
            except payload.PayloadError as exc:
                raise payload.PayloadError(f"{key}: {exc}") from None
        return updates

    # -- running -----------------------------------------------------------
    def run(self, handle_signals: bool = True) -> None:
        """Cycle until SIGTERM/SIGINT, :meth:`stop` or ``unloadusr``."""
        signals = StopSignals(handle_signals).__enter__()
        try:
            if self.comp is None:
                self.start()
            while not self._stop.is_set() and not signals.caught:
                comp = self._component()
                if not comp.exists:
                    log.info("%s: component removed, stopping",
                             self.cfg.name)
                    break
                if comp.host_gone:      # said on stderr by the core
                    break
                try:
                    self.cycle()
                except HalError:
                    if comp.exists:
                        raise
                    continue
                self._stop.wait(self.cfg.poll)
        finally:
            self.shutdown()
            signals.__exit__(None, None, None)

    def stop(self) -> None:
        self._stop.set()

    def shutdown(self) -> None:
        """Disconnect (bounded wait) and remove the component."""
        if self.link is not None:
            self.link.stop()
            self.link = None
        if self.comp is not None:
            self.comp.exit()
            self.comp = None
