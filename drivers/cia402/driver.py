"""The bus: one HAL component (``cia402`` by default) for all drives, the
CAN connection, SYNC, and the count of unknown and malformed frames."""

from __future__ import annotations

import logging
import threading
import time
from typing import Optional

import can
import canopen

from halsdk.driverkit import Driver, DriverError

from .config import BusConfig
from .drive import DriveLink
from .sim import SimBus, SimDrive

log = logging.getLogger("halsdk.drivers.cia402")

#: function codes (COB-ID & 0x780) without a node id
_BROADCAST = {0x000, 0x080, 0x100}


class _FrameWatch(can.Listener):
    """Counts frames of unknown nodes and malformed frames."""

    def __init__(self, driver: Cia402Driver):
        self.driver = driver

    def on_message_received(self, msg: can.Message) -> None:
        d = self.driver
        if msg.is_error_frame or msg.is_remote_frame:
            d.count_malformed(msg.arbitration_id, "error or remote frame")
            return
        cob = msg.arbitration_id
        if msg.is_extended_id:
            d.count_unknown(cob, "extended (29-bit) identifier")
            return
        if cob in _BROADCAST or cob in d.own_ids:
            if cob == 0 and len(msg.data) != 2:
                d.count_malformed(cob, f"NMT of {len(msg.data)} bytes")
            return
        if cob not in d.known_ids:
            d.count_unknown(cob, f"node {cob & 0x7F}" if cob & 0x7F
                            else "no node")

    def stop(self) -> None:
        """Nothing to release."""


class Cia402Driver(Driver):
    """All drives of one CAN bus, as component ``name``."""

    name = "cia402"

    def __init__(self, config: BusConfig, comp_name: str = "cia402",
                 simulate: bool = False, instance: Optional[str] = None):
        super().__init__(0, instance, comp_name=comp_name)
        self.prefix = comp_name       # pins <comp_name>.<pin>
        self.config = config
        self.simulate = simulate or config.simulate
        self.drives: list[DriveLink] = []
        self.network: Optional[canopen.Network] = None
        self.sim: Optional[SimBus] = None
        self.known_ids: set[int] = set()
        self.own_ids: set[int] = set()
        self._count_lock = threading.Lock()
        self._unknown = 0
        self._malformed = 0
        self._logged_frames: set[tuple[str, int]] = set()

    # -- pins ---------------------------------------------------------------
    def setup(self) -> None:
        comp = self._require()
        comp.newpin("unknown-frames", "u32", "out")
        comp.newpin("malformed-frames", "u32", "out")
        for cfg in self.config.drives:
            link = DriveLink(cfg, comp, self.prefix, self.count_malformed,
                             self.config.sdo_timeout)
            self.drives.append(link)
            self.known_ids |= link.known_cob_ids()
            nid = cfg.node_id
            self.own_ids |= {0x600 + nid, *(cfg.rpdo_cob(n) for n in
                                            cfg.rpdo)}

    # -- frame statistics (notifier thread) -------------------------------
    def count_unknown(self, cob: int, what: str) -> None:
        with self._count_lock:
            self._unknown += 1
            first = ("unknown", cob & 0x7F) not in self._logged_frames
            self._logged_frames.add(("unknown", cob & 0x7F))
        if first:
            log.warning("%s: ignoring frames of unknown origin: COB-ID "
                        "0x%03X (%s)", self.prefix, cob, what)

    def count_malformed(self, cob: int, what: str) -> None:
        with self._count_lock:
            self._malformed += 1
            first = ("malformed", cob) not in self._logged_frames
            self._logged_frames.add(("malformed", cob))
        if first:
            log.warning("%s: ignoring malformed frame: COB-ID 0x%03X (%s)",
                        self.prefix, cob, what)

    # -- device -------------------------------------------------------------
    def open(self) -> None:
        cfg = self.config
        interface = "virtual" if self.simulate else cfg.interface
        if self.simulate and self.sim is None:
            self.sim = SimBus(cfg.channel, [
                SimDrive(d.node_id, d.eds, cfg.period)
                for d in cfg.drives]).start()
        network = canopen.Network()
        network.NOTIFIER_CYCLE = 0.1        # quick stop
        kwargs = {} if interface == "virtual" else {"bitrate": cfg.bitrate}
        try:
            network.connect(interface=interface, channel=cfg.channel,
                            **kwargs)
        except Exception as exc:  # python-can raises many kinds
            reason = exc.strerror if isinstance(exc, OSError) and \
                exc.strerror else str(exc) or type(exc).__name__
            raise ConnectionError(f"{interface} channel {cfg.channel}: "
                                  f"{reason}") from None
        if network.notifier is None:      # connect() always starts one
            network.disconnect()
            raise ConnectionError(f"{interface} channel {cfg.channel}: "
                                  "no CAN notifier")
        network.notifier.add_listener(_FrameWatch(self))
        self.network = network
        for link in self.drives:
            link.attach(network)

    def safe_state(self) -> None:
        """Drives disabled: every drive's power stage off, applied by a
        SYNC (close() does it again before NMT stop)."""
        network = self.network
        if network is None:
            return
        for link in self.drives:
            link.switch_off()
        network.send_message(0x80, b"")

    def close(self) -> None:
        network, self.network = self.network, None
        if network is not None:
            # power stages off before NMT stop: a stopped node would react
            # as its 0x6007 setting says, which may leave the motor live
            try:
                for link in self.drives:
                    link.switch_off()
                network.send_message(0x80, b"")      # SYNC applies them
                time.sleep(2 * self.config.period)
            except Exception as exc:   # the bus may be gone already
                log.debug("%s: switching the drives off: %s",
                          self.prefix, exc)
        for link in self.drives:
            link.detach(stop=network is not None)
        if network is not None:
            network.disconnect()

    def shutdown(self) -> None:
        super().shutdown()
        if self.sim is not None:
            self.sim.stop()
            self.sim = None

    def _network(self) -> canopen.Network:
        if self.network is None:
            raise DriverError("bus not open")
        return self.network

    def read(self) -> None:
        self._network().check()
        for link in self.drives:
            link.read()
        comp = self._require()
        with self._count_lock:
            comp["unknown-frames"] = self._unknown & 0xFFFFFFFF
            comp["malformed-frames"] = self._malformed & 0xFFFFFFFF

    def write(self) -> None:
        for link in self.drives:
            link.write()
        self._network().send_message(0x80, b"")          # SYNC
