"""The master side of one CiA 402 drive: configuration over SDO, NMT,
heartbeat consumer, EMCY, PDO exchange and the HAL pins ``<comp>.<num>.*``.
"""

from __future__ import annotations

import logging
import struct
import threading
import time
from collections import deque
from typing import Callable, Optional

import canopen
from canopen.objectdictionary import ODVariable
from canopen.sdo import SdoAbortedError, SdoClient, SdoCommunicationError

from halsdk.component import Component
from halsdk.driverkit.backoff import Backoff

from . import statemachine as sm
from .codes import abort_text, emcy_text
from .config import DriveConfig, PdoEntry

log = logging.getLogger("halsdk.drivers.cia402")

#: ``fault-code`` values the driver sets itself (CiA 301 error codes)
CODE_HEARTBEAT = 0x8130     # heartbeat lost
CODE_NO_REPLY = 0x8100      # no SDO reply during configuration
CODE_CONFIG = 0x6320        # SDO abort during configuration

#: link states
CONFIGURE, RUNNING, LOST = "configure", "running", "lost"

PINS = (
    ("enable", "bit", "in"), ("enabled", "bit", "out"),
    ("fault-reset", "bit", "in"), ("quick-stop", "bit", "in"),
    ("position-cmd", "float", "in"), ("position-fb", "float", "out"),
    ("velocity-cmd", "float", "in"), ("velocity-fb", "float", "out"),
    ("statusword", "u32", "out"), ("controlword", "u32", "out"),
    ("state", "s32", "out"), ("target-reached", "bit", "out"),
    ("fault", "bit", "out"), ("fault-code", "u32", "out"),
    ("error-register", "u32", "out"), ("abort-code", "u32", "out"),
    ("connected", "bit", "out"), ("operational", "bit", "out"),
    ("heartbeat-lost", "bit", "out"),
)


class SdoConfigError(Exception):
    def __init__(self, text: str, code: int, abort: int = 0):
        super().__init__(text)
        self.code = code
        self.abort = abort


class DriveLink:
    """Drive ``cfg.num`` on ``network``; pins on ``comp``."""

    def __init__(self, cfg: DriveConfig, comp: Component, prefix: str,
                 count_malformed: Callable[[int, str], None],
                 sdo_timeout: float = 0.3,
                 clock: Callable[[], float] = time.monotonic):
        self.cfg = cfg
        self.comp = comp
        self.name = f"{prefix}.{cfg.num}"
        self.pin = f"{cfg.num}."
        self.count_malformed = count_malformed
        self.sdo_timeout = sdo_timeout
        self.clock = clock
        for pin, type_, direction in PINS:
            comp.newpin(self.pin + pin, type_, direction)
        comp[self.pin + "state"] = sm.NO_DATA
        self.network: Optional[canopen.Network] = None
        self.sdo: Optional[SdoClient] = None
        self.link = CONFIGURE
        self.retry = Backoff(0.25, 5.0)
        self.comm_fault = 0          # CODE_* while a link problem lasts
        self.comm_text = ""
        self.fault_text = ""         #: the text of the current fault
        self._logged = ""
        self._lock = threading.Lock()
        self._values: dict[tuple[int, int], int | float] = {}
        self._emcy: deque[tuple[int, int]] = deque(maxlen=32)
        self._last_heartbeat: Optional[float] = None
        self._heartbeat_state = -1
        self._bootup = False
        self._lost_at = 0.0
        self.emcy_code = 0
        self.drive_state = sm.NO_DATA
        self._pp_target: Optional[int] = None
        self._pp_new = False
        self._tpdo_by_cob = {cfg.tpdo_cob(n): entries
                             for n, entries in cfg.tpdo.items()}

    # -- network ----------------------------------------------------------
    def attach(self, network: canopen.Network) -> None:
        self.network = network
        nid = self.cfg.node_id
        self.sdo = SdoClient(0x600 + nid, 0x580 + nid, self.cfg.od)
        self.sdo.RESPONSE_TIMEOUT = self.sdo_timeout
        self.sdo.network = network
        network.subscribe(0x580 + nid, self.sdo.on_response)
        network.subscribe(0x700 + nid, self._on_heartbeat)
        network.subscribe(0x80 + nid, self._on_emcy)
        for cob in self._tpdo_by_cob:
            network.subscribe(cob, self._on_tpdo)
        self.link = CONFIGURE
        self.retry.succeeded()          # configure at once

    def detach(self, stop: bool) -> None:
        """Leave the network (NMT stop first when ``stop``)."""
        if self.network is None:
            return
        if stop and self.link == RUNNING:
            try:
                self.network.send_message(0, bytes([0x02, self.cfg.node_id]))
            except Exception as exc:   # the bus may be gone already
                log.debug("%s: NMT stop: %s", self.name, exc)
        self.network = None
        self.sdo = None
        self.link = CONFIGURE

    def _attached(self) -> tuple[canopen.Network, SdoClient]:
        """The network and SDO client of :meth:`attach`."""
        if self.network is None or self.sdo is None:
            raise RuntimeError(f"{self.name}: not attached to a network")
        return self.network, self.sdo

    def known_cob_ids(self) -> set[int]:
        nid = self.cfg.node_id
        return {0x580 + nid, 0x700 + nid, 0x80 + nid, *self._tpdo_by_cob}

    # notifier thread callbacks (canopen passes a bytearray): store only
    def _on_heartbeat(self, can_id: int, data: bytes | bytearray,
                      ts: float) -> None:
        if len(data) != 1:
            self.count_malformed(can_id, f"heartbeat of {len(data)} bytes")
            return
        with self._lock:
            self._last_heartbeat = self.clock()
            self._heartbeat_state = data[0] & 0x7F
            if data[0] == 0:
                self._bootup = True

    def _on_emcy(self, can_id: int, data: bytes | bytearray,
                 ts: float) -> None:
        if len(data) != 8:
            self.count_malformed(can_id, f"EMCY of {len(data)} bytes")
            return
        code, reg = struct.unpack_from("<HB", data)
        with self._lock:
            self._emcy.append((code, reg))

    def _on_tpdo(self, can_id: int, data: bytes | bytearray,
                 ts: float) -> None:
        entries = self._tpdo_by_cob[can_id]
        if 8 * len(data) != sum(e.bits for e in entries):
            self.count_malformed(can_id, f"TPDO of {len(data)} bytes")
            return
        values: dict[tuple[int, int], int | float] = {}
        pos = 0
        for e in entries:
            size = e.bits // 8
            value = e.var.decode_raw(bytes(data[pos:pos + size]))
            if isinstance(value, (int, float)):   # read() uses numbers only
                values[(e.index, e.subindex)] = value
            pos += size
        with self._lock:
            self._values.update(values)

    # -- configuration ----------------------------------------------------
    def _write(self, index: int, sub: int, data: bytes, what: str) -> None:
        sdo = self._attached()[1]
        try:
            sdo.download(index, sub, data)
        except SdoAbortedError as exc:
            raise SdoConfigError(
                f"SDO abort writing 0x{index:04X}:{sub:02X} ({what}): "
                f"0x{exc.code:08X} {abort_text(exc.code)}", CODE_CONFIG,
                exc.code) from None
        except SdoCommunicationError as exc:
            raise SdoConfigError(
                f"no SDO reply writing 0x{index:04X}:{sub:02X} ({what}): "
                f"{exc}", CODE_NO_REPLY) from None

    def _value(self, index: int, value: int | float, what: str) -> None:
        var = self.cfg.od[index]
        if not isinstance(var, ODVariable):
            raise SdoConfigError(
                f"0x{index:04X} ({what}) is not a single object in the EDS "
                f"{self.cfg.eds}", CODE_CONFIG)
        self._write(index, 0, var.encode_raw(value), what)

    def _map(self, comm: int, mapping: int, cob: int,
             entries: Optional[list[PdoEntry]], kind: str) -> None:
        u32 = struct.Struct("<I").pack
        self._write(comm, 1, u32(cob | 0x80000000), f"disable {kind}")
        if not entries:
            return
        self._write(comm, 2, b"\x01", f"{kind} transmission type")
        self._write(mapping, 0, b"\x00", f"{kind} mapping count")
        for k, e in enumerate(entries, 1):
            self._write(mapping, k, u32(e.mapping),
                        f"{kind} maps 0x{e.index:04X}:{e.subindex:02X}")
        self._write(mapping, 0, bytes([len(entries)]), f"{kind} mapping count")
        self._write(comm, 1, u32(cob), f"enable {kind}")

    def configure(self) -> None:
        """Pre-operational, SDO configuration, PDO mapping, start."""
        cfg = self.cfg
        nid = cfg.node_id
        network = self._attached()[0]
        network.send_message(0, bytes([0x80, nid]))
        if cfg.heartbeat_period > 0:
            self._value(0x1017, int(round(cfg.heartbeat_period * 1000)),
                        "producer heartbeat time")
        self._value(0x6060, sm.MODES[cfg.mode], "modes of operation")
        if cfg.mode == "pp":
            for index, value, what in (
                    (0x6081, cfg.profile_velocity, "profile velocity"),
                    (0x6083, cfg.profile_acceleration,
                     "profile acceleration"),
                    (0x6084, cfg.profile_deceleration,
                     "profile deceleration")):
                if value > 0:
                    counts = int(round(abs(value * cfg.position_scale)))
                    self._value(index, counts, what)
        for w in cfg.sdo_writes:
            self._write(w.index, w.subindex, w.data, f"SDO line {w.where}")
        for n in range(1, 5):
            self._map(0x1400 + n - 1, 0x1600 + n - 1, cfg.rpdo_cob(n),
                      cfg.rpdo.get(n), f"RPDO{n}")
            self._map(0x1800 + n - 1, 0x1A00 + n - 1, cfg.tpdo_cob(n),
                      cfg.tpdo.get(n), f"TPDO{n}")
        with self._lock:
            self._values.clear()
            self._bootup = False
            self._last_heartbeat = self.clock()   # grace period
        network.send_message(0, bytes([0x01, nid]))

    # -- faults -------------------------------------------------------------
    def _note(self, text: str, level: int = logging.ERROR) -> None:
        """Log ``text`` once (until a different text comes)."""
        if text != self._logged:
            self._logged = text
            log.log(level, "%s", text)

    def _comm_fault(self, code: int, text: str, abort: int = 0) -> None:
        self.comm_fault = code
        self.comm_text = f"{self.name} (node {self.cfg.node_id}): {text}"
        self.comp[self.pin + "abort-code"] = abort
        self._note(self.comm_text)

    # -- cycle --------------------------------------------------------------
    def read(self) -> None:
        now = self.clock()
        with self._lock:
            emcys = list(self._emcy)
            self._emcy.clear()
            values = dict(self._values)
            last_hb = self._last_heartbeat
            bootup, self._bootup = self._bootup, False
        p = self.pin
        comp = self.comp
        for code, reg in emcys:
            comp[p + "error-register"] = reg
            if code:
                self.emcy_code = code
                self._note(f"{self.name} (node {self.cfg.node_id}): EMCY "
                           f"0x{code:04X} {emcy_text(code)}, error register "
                           f"0x{reg:02X}")
            else:
                self.emcy_code = 0
        timeout = self.cfg.heartbeat_timeout
        if self.link == RUNNING:
            if bootup:
                self._note(f"{self.name} (node {self.cfg.node_id}): "
                           "restarted, configuring again", logging.WARNING)
                self.link = CONFIGURE
            elif timeout > 0 and last_hb is not None and \
                    now - last_hb > timeout:
                self.link = LOST
                self._lost_at = now
                self._comm_fault(CODE_HEARTBEAT, f"heartbeat lost (none for "
                                 f"{timeout:g} s)")
        elif self.link == LOST:
            if last_hb is not None and last_hb > self._lost_at:
                self._note(f"{self.name} (node {self.cfg.node_id}): "
                           "heartbeat back, configuring again",
                           logging.WARNING)
                self.link = CONFIGURE
                self.retry.succeeded()
        if self.link == CONFIGURE and self.retry.ready(now):
            try:
                self.configure()
            except SdoConfigError as exc:
                self._comm_fault(exc.code, str(exc), exc.abort)
                self.retry.failed(now)
            else:
                self.link = RUNNING
                self.retry.succeeded()
                self.drive_state = sm.NO_DATA
                if self.comm_fault:
                    log.warning("%s: configured, running again", self.name)
                self.comm_fault = 0
                self.comm_text = ""
                comp[p + "abort-code"] = 0
        running = self.link == RUNNING
        comp[p + "connected"] = self.link != LOST and self.comm_fault not in (
            CODE_NO_REPLY, CODE_HEARTBEAT)
        comp[p + "operational"] = running
        comp[p + "heartbeat-lost"] = self.link == LOST
        sw_value = values.get((0x6041, 0))
        if running and sw_value is not None:
            sw = int(sw_value)
            state = sm.decode(sw)
            comp[p + "statusword"] = sw
            comp[p + "target-reached"] = bool(sw & sm.SW_TARGET_REACHED)
        else:
            state = sm.NO_DATA
            comp[p + "target-reached"] = False
        pos = values.get((0x6064, 0))
        if pos is not None:
            comp[p + "position-fb"] = pos / self.cfg.position_scale
        vel = values.get((0x606C, 0))
        if vel is not None:
            comp[p + "velocity-fb"] = vel / self.cfg.velocity_scale
        if (0x603F, 0) in values and values[(0x603F, 0)]:
            self.emcy_code = self.emcy_code or int(values[(0x603F, 0)])
        self._update_state(state)

    def _update_state(self, state: int) -> None:
        p = self.pin
        comp = self.comp
        old, self.drive_state = self.drive_state, state
        comp[p + "state"] = state
        comp[p + "enabled"] = state == sm.OPERATION_ENABLED
        in_fault = state in (sm.FAULT, sm.FAULT_REACTION_ACTIVE)
        if in_fault and old not in (sm.FAULT, sm.FAULT_REACTION_ACTIVE) \
                and not self.emcy_code:
            self.emcy_code = self._read_error_code()
        if in_fault:
            code = self.emcy_code
            text = (f"{self.name} (node {self.cfg.node_id}): drive fault "
                    f"0x{code:04X} {emcy_text(code)}")
            emcy = f"{self.name} (node {self.cfg.node_id}): EMCY 0x{code:04X}"
            if not self._logged.startswith(emcy):
                self._note(text)
        elif old in (sm.FAULT, sm.FAULT_REACTION_ACTIVE):
            self.emcy_code = 0
            self._note(f"{self.name}: drive fault cleared", logging.WARNING)
        if self.comm_fault:
            comp[p + "fault"] = True
            comp[p + "fault-code"] = self.comm_fault
            self.fault_text = self.comm_text
        elif in_fault:
            comp[p + "fault"] = True
            comp[p + "fault-code"] = self.emcy_code
            self.fault_text = (f"{self.name} (node {self.cfg.node_id}): "
                               f"0x{self.emcy_code:04X} "
                               f"{emcy_text(self.emcy_code)}")
        else:
            comp[p + "fault"] = False
            comp[p + "fault-code"] = 0
            self.fault_text = ""

    def _read_error_code(self) -> int:
        try:
            raw = self._attached()[1].upload(0x603F, 0)
            return struct.unpack_from("<H", raw)[0]
        except Exception as exc:   # no 0x603F, no reply: code unknown
            log.debug("%s: reading 0x603F: %s", self.name, exc)
            return 0

    def write(self) -> None:
        p = self.pin
        comp = self.comp
        if self.link != RUNNING:
            self._pp_target = None
            return
        state = self.drive_state
        cw = sm.command(state, comp[p + "enable"], comp[p + "quick-stop"])
        if comp[p + "fault-reset"] and state in (sm.FAULT,
                                                 sm.FAULT_REACTION_ACTIVE):
            cw |= sm.CW_FAULT_RESET
        cfg = self.cfg
        target = int(round(comp[p + "position-cmd"] * cfg.position_scale))
        if cfg.mode == "pp":
            cw = self._pp(cw, state, target)
            target = self._pp_target if self._pp_target is not None \
                else target
        comp[p + "controlword"] = cw
        self._send_rpdos(cw, target)

    def switch_off(self) -> None:
        """Send controlword "shutdown" (power stage off) with the last
        targets: the drive leaves operation enabled at the next SYNC."""
        if self.link != RUNNING or self.network is None:
            return
        p = self.pin
        target = int(round(self.comp[p + "position-cmd"]
                           * self.cfg.position_scale))
        if self._pp_target is not None:
            target = self._pp_target
        self.comp[p + "controlword"] = sm.CW_SHUTDOWN
        self._send_rpdos(sm.CW_SHUTDOWN, target)

    def _send_rpdos(self, cw: int, target: int) -> None:
        comp, p, cfg = self.comp, self.pin, self.cfg
        values = {0x6040: cw, 0x607A: target,
                  0x60FF: int(round(comp[p + "velocity-cmd"]
                                    * cfg.velocity_scale)),
                  0x6060: sm.MODES[cfg.mode],
                  0x6081: int(round(abs(cfg.profile_velocity
                                        * cfg.position_scale)))}
        for n, entries in cfg.rpdo.items():
            data = b"".join(e.var.encode_raw(self._clamp(e, values[e.index]))
                            for e in entries)
            self._attached()[0].send_message(cfg.rpdo_cob(n), data)

    @staticmethod
    def _clamp(e: PdoEntry, value: int) -> int:
        if e.var.data_type in (0x2, 0x3, 0x4):
            lim = 1 << (e.bits - 1)
            return max(-lim, min(lim - 1, value))
        return max(0, min((1 << e.bits) - 1, value))

    def _pp(self, cw: int, state: int, target: int) -> int:
        """Profile position: the set-point handshake (bits 4/12)."""
        if state != sm.OPERATION_ENABLED:
            self._pp_target = None
            self._pp_new = False
            return cw
        sw = self.comp[self.pin + "statusword"]
        if self._pp_new:
            if sw & sm.SW_SETPOINT_ACK:
                self._pp_new = False       # acknowledged: release bit 4
        elif target != self._pp_target and not sw & sm.SW_SETPOINT_ACK:
            self._pp_target = target
            self._pp_new = True
        if self._pp_new:
            cw |= sm.CW_NEW_SETPOINT
        return cw | sm.CW_CHANGE_IMMEDIATELY
