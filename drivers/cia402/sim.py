"""A simulated CiA 402 drive: a canopen LocalNode with the driver's object
dictionary, the drive state machine, a motor model, heartbeat, TPDOs on
SYNC and EMCY on injected faults.

python-can's ``virtual`` interface connects the buses of one process only,
so the simulated drives run in the process of the driver (``--simulate``)
or of a test.
"""

from __future__ import annotations

import logging
import math
import struct
import threading
import time
from collections.abc import Iterable
from typing import Optional

import can
import canopen
from canopen.objectdictionary import ODVariable

from . import DEFAULT_EDS
from . import statemachine as sm

log = logging.getLogger("halsdk.drivers.cia402.sim")

#: NMT states as sent in the heartbeat
BOOTUP, STOPPED, OPERATIONAL, PRE_OPERATIONAL = 0, 4, 5, 127
_STATUS_BITS = {
    sm.NOT_READY: 0x00, sm.SWITCH_ON_DISABLED: 0x40,
    sm.READY_TO_SWITCH_ON: 0x31, sm.SWITCHED_ON: 0x33,
    sm.OPERATION_ENABLED: 0x37, sm.QUICK_STOP_ACTIVE: 0x17,
    sm.FAULT_REACTION_ACTIVE: 0x0F, sm.FAULT: 0x08,
}
#: manufacturer objects of the shipped EDS
OBJ_INJECT_FAULT = 0x2000      # write an EMCY code: the drive faults
OBJ_FOLLOWING_CHECK = 0x2001   # 0 turns the following error check off


def error_register(code: int) -> int:
    """Error register (0x1001) bits for an error code."""
    reg = 0x01
    reg |= {0x2: 0x02, 0x3: 0x04, 0x4: 0x08, 0x8: 0x10}.get(code >> 12, 0x80)
    return reg


class SimDrive:
    """One simulated drive with node id ``node_id``; ``period`` is the
    time the motor model advances per SYNC."""

    def __init__(self, node_id: int, eds: str = DEFAULT_EDS,
                 period: float = 0.01):
        self.node_id = node_id
        self.period = period
        self.od = canopen.import_od(eds, node_id)
        self.node = canopen.LocalNode(node_id, self.od)
        self.nmt_state = PRE_OPERATIONAL
        self.state = sm.SWITCH_ON_DISABLED
        self.position = 0.0          # counts
        self.velocity = 0.0          # counts/s
        self.heartbeat = True        # producing heartbeats
        self.online = True           # answering at all
        self.sync_count = 0
        self._lock = threading.RLock()
        self._last_cw = 0
        self._pp_target: Optional[float] = None
        self._pp_ack = False
        self._rpdo_cobs: dict[int, int] = {}
        self._next_heartbeat = 0.0
        self.network: Optional[canopen.Network] = None

    # -- object dictionary access -------------------------------------
    def _var(self, index: int, sub: int = 0) -> ODVariable:
        obj = self.od[index]
        return obj if isinstance(obj, ODVariable) else obj[sub]

    def get(self, index: int, sub: int = 0) -> int | float:
        """The value of an object."""
        value = self._var(index, sub).decode_raw(
            self.node.get_data(index, sub))
        if not isinstance(value, (int, float)):
            raise TypeError(f"sim node {self.node_id}: object "
                            f"0x{index:04X}:{sub:02X} is not a number")
        return value

    def set(self, index: int, value: int | float, sub: int = 0) -> None:
        self.node.data_store.setdefault(index, {})[sub] = \
            self._var(index, sub).encode_raw(value)

    # -- network --------------------------------------------------------
    def attach(self, network: canopen.Network) -> None:
        """Join ``network`` (SDO server, NMT, SYNC, RPDOs)."""
        self.network = network
        network.add_node(self.node)
        network.unsubscribe(0, self.node.nmt.on_command)
        network.unsubscribe(self.node.sdo.rx_cobid, self.node.sdo.on_request)
        network.subscribe(self.node.sdo.rx_cobid, self._on_sdo)
        self.node._write_callbacks.remove(self.node.nmt.on_write)
        self.node.add_write_callback(self._on_write)
        network.subscribe(0, self._on_nmt)
        network.subscribe(0x80, self._on_sync)
        for n in range(4):
            self._route_rpdo(n, int(self.get(0x1400 + n, 1)))
        self._update_status()

    def _send(self, can_id: int, data: bytes) -> None:
        if self.online and self.network is not None:
            try:
                self.network.send_message(can_id, data)
            except can.CanError as exc:
                log.debug("sim node %d: send failed: %s", self.node_id, exc)

    def _route_rpdo(self, n: int, cob: int) -> None:
        network = self.network
        if network is None:
            raise RuntimeError(f"sim node {self.node_id}: not attached")
        old = self._rpdo_cobs.pop(n, None)
        if old is not None:
            network.unsubscribe(old, self._on_rpdo)
        if not cob & 0x80000000:
            self._rpdo_cobs[n] = cob & 0x7FF
            network.subscribe(cob & 0x7FF, self._on_rpdo)

    def _on_sdo(self, can_id: int, data: bytes | bytearray,
                timestamp: float) -> None:
        if self.online:
            with self._lock:
                self.node.sdo.on_request(can_id, data, timestamp)

    def _on_write(self, index: int, subindex: int, od, data: bytes) -> None:
        if 0x1400 <= index <= 0x1403 and subindex == 1:
            self._route_rpdo(index - 0x1400, od.decode_raw(data))
        elif index == OBJ_INJECT_FAULT:
            code = od.decode_raw(data)
            if code:
                self.inject_fault(code)

    def tick(self, now: float) -> None:
        """Produce the heartbeat when due (called by :class:`SimBus`)."""
        period = self.get(0x1017) / 1000.0
        if period <= 0 or not self.heartbeat or now < self._next_heartbeat:
            return
        self._next_heartbeat = now + period
        self._send(0x700 + self.node_id, bytes([self.nmt_state]))

    def _on_nmt(self, can_id: int, data: bytes | bytearray,
                timestamp: float) -> None:
        if len(data) != 2 or data[1] not in (0, self.node_id) \
                or not self.online:
            return
        with self._lock:
            new = {1: OPERATIONAL, 2: STOPPED, 0x80: PRE_OPERATIONAL,
                   0x81: PRE_OPERATIONAL, 0x82: PRE_OPERATIONAL}.get(data[0])
            if new is None:
                return
            if new != OPERATIONAL and self.state in (
                    sm.OPERATION_ENABLED, sm.QUICK_STOP_ACTIVE):
                self.state = sm.SWITCH_ON_DISABLED   # communication gone
                self.velocity = 0.0
            self.nmt_state = new
            if data[0] in (0x81, 0x82):
                self._send(0x700 + self.node_id, b"\x00")   # boot-up
            self._update_status()

    # -- faults, heartbeat ----------------------------------------------
    def inject_fault(self, code: int = 0x2310) -> None:
        """Enter the fault state with error ``code`` and send an EMCY."""
        with self._lock:
            self._fault(code)

    def _fault(self, code: int) -> None:
        reg = error_register(code)
        self.state = sm.FAULT
        self.velocity = 0.0
        self.set(0x603F, code)
        self.set(0x1001, reg)
        self._update_status()
        self._send(0x80 + self.node_id, struct.pack("<HB5x", code, reg))

    def stop_heartbeat(self) -> None:
        """Stop producing heartbeats (the master sees a lost node)."""
        self.heartbeat = False

    def resume_heartbeat(self) -> None:
        self.heartbeat = True
        self._next_heartbeat = 0.0

    def go_offline(self) -> None:
        """Fall silent: no heartbeat, no PDO, no SDO reply."""
        self.online = False

    def go_online(self) -> None:
        """Come back as after a restart: boot-up message, pre-operational,
        switch on disabled."""
        with self._lock:
            self.online = True
            self.nmt_state = PRE_OPERATIONAL
            if self.state != sm.FAULT:
                self.state = sm.SWITCH_ON_DISABLED
            self.velocity = 0.0
            self._update_status()
            self._send(0x700 + self.node_id, b"\x00")
            self._next_heartbeat = 0.0

    # -- PDOs -----------------------------------------------------------
    def _mapping(self, base: int, n: int) -> list[tuple[int, int, int]]:
        count = int(self.get(base + n, 0))
        out = []
        for k in range(1, count + 1):
            entry = int(self.get(base + n, k))
            out.append((entry >> 16, (entry >> 8) & 0xFF, entry & 0xFF))
        return out

    def _on_rpdo(self, can_id: int, data: bytes | bytearray,
                 timestamp: float) -> None:
        if not self.online or self.nmt_state != OPERATIONAL:
            return
        n = next((k for k, c in self._rpdo_cobs.items() if c == can_id),
                 None)
        if n is None:
            return
        mapping = self._mapping(0x1600, n)
        if sum(bits for _, _, bits in mapping) != 8 * len(data):
            return                          # PDO length error: ignored
        with self._lock:
            pos = 0
            for index, sub, bits in mapping:
                size = bits // 8
                self.node.data_store.setdefault(index, {})[sub] = \
                    bytes(data[pos:pos + size])
                pos += size
            if any(index == 0x6040 for index, _, _ in mapping):
                self._controlword(int(self.get(0x6040)))

    def _on_sync(self, can_id: int, data: bytes | bytearray,
                 timestamp: float) -> None:
        if not self.online or self.nmt_state != OPERATIONAL:
            return
        with self._lock:
            self.sync_count += 1
            self._step(self.period)
            frames = []
            for n in range(4):
                cob = int(self.get(0x1800 + n, 1))
                if cob & 0x80000000:
                    continue
                payload = b"".join(self.node.get_data(i, s)
                                   for i, s, _ in self._mapping(0x1A00, n))
                frames.append((cob & 0x7FF, payload))
        for cob, payload in frames:
            self._send(cob, payload)

    # -- the CiA 402 state machine ------------------------------------
    def _controlword(self, cw: int) -> None:
        last, self._last_cw = self._last_cw, cw
        s = self.state
        if s == sm.FAULT:
            if cw & 0x80 and not last & 0x80:
                self.state = sm.SWITCH_ON_DISABLED
                self.set(0x603F, 0)
                self.set(0x1001, 0)
                self._send(0x80 + self.node_id, bytes(8))   # error reset
        elif not cw & 0x02:                                  # disable voltage
            self.state = sm.SWITCH_ON_DISABLED
        elif cw & 0x06 == 0x02:                              # quick stop
            self.state = sm.QUICK_STOP_ACTIVE \
                if s in (sm.OPERATION_ENABLED, sm.QUICK_STOP_ACTIVE) \
                else sm.SWITCH_ON_DISABLED
        elif cw & 0x07 == 0x06:                              # shutdown
            if s in (sm.SWITCH_ON_DISABLED, sm.SWITCHED_ON,
                     sm.OPERATION_ENABLED):
                self.state = sm.READY_TO_SWITCH_ON
        elif cw & 0x0F == 0x07:                              # switch on
            if s in (sm.READY_TO_SWITCH_ON, sm.OPERATION_ENABLED):
                self.state = sm.SWITCHED_ON
        elif cw & 0x0F == 0x0F:                              # enable op
            if s in (sm.READY_TO_SWITCH_ON, sm.SWITCHED_ON):
                self.state = sm.OPERATION_ENABLED
                self._pp_target = None
        if self.state != sm.OPERATION_ENABLED:
            self._pp_ack = False
        elif self.get(0x6060) == sm.MODE_PP:
            if cw & sm.CW_NEW_SETPOINT and not self._pp_ack:
                target = float(self.get(0x607A))
                if cw & sm.CW_RELATIVE:
                    target += (self._pp_target if self._pp_target
                               is not None else self.position)
                self._pp_target = target
                self._pp_ack = True
            elif not cw & sm.CW_NEW_SETPOINT:
                self._pp_ack = False
        self._update_status()

    def _update_status(self) -> None:
        sw = _STATUS_BITS[self.state] | 0x0200              # remote
        mode = self.get(0x6060)
        if self.state == sm.OPERATION_ENABLED:
            if mode == sm.MODE_PP:
                if self._pp_ack:
                    sw |= sm.SW_SETPOINT_ACK
                if self._pp_target is None or (
                        abs(self._pp_target - self.position) < 0.5
                        and self.velocity == 0):
                    sw |= sm.SW_TARGET_REACHED
            else:
                sw |= sm.SW_SETPOINT_ACK     # CSP/CSV: drive follows target
                if mode == sm.MODE_CSP and abs(
                        self.get(0x607A) - self.position) < 0.5:
                    sw |= sm.SW_TARGET_REACHED
        self.set(0x6041, sw)
        self.set(0x6061, mode)
        self.set(0x6064, int(round(self.position)))
        self.set(0x606C, int(round(self.velocity)))

    # -- the motor --------------------------------------------------------
    def _approach(self, target: float, vmax: float, amax: float,
                  dt: float) -> None:
        """Move towards ``target``: at most ``vmax``, accelerating and
        braking at most ``amax``, arriving without overshoot."""
        err = target - self.position
        step = amax * dt
        brake = step * (math.sqrt(0.25 + 2 * abs(err) / (step * dt)) - 0.5)
        want = math.copysign(min(vmax, brake, abs(err) / dt), err)
        self.velocity += max(-step, min(step, want - self.velocity))
        self.position += self.velocity * dt
        if abs(target - self.position) < 0.5:
            self.position = target

    def _step(self, dt: float) -> None:
        vmax = float(self.get(0x607F))
        amax = float(self.get(0x60C5))
        mode = self.get(0x6060)
        if self.state == sm.QUICK_STOP_ACTIVE:
            dv = min(abs(self.velocity), amax * dt)
            self.velocity -= math.copysign(dv, self.velocity)
            self.position += self.velocity * dt
        elif self.state != sm.OPERATION_ENABLED:
            self.velocity = 0.0
        elif mode == sm.MODE_CSP:
            target = float(self.get(0x607A))
            self._approach(target, vmax, amax, dt)
            window = self.get(0x6065)
            self.set(0x60F4, int(round(target - self.position)))
            if self.get(OBJ_FOLLOWING_CHECK) and \
                    abs(target - self.position) > window:
                self._fault(0x8611)
        elif mode == sm.MODE_CSV:
            want = max(-vmax, min(vmax, float(self.get(0x60FF))))
            dv = max(-amax * dt, min(amax * dt, want - self.velocity))
            self.velocity += dv
            self.position += self.velocity * dt
        elif mode == sm.MODE_PP and self._pp_target is not None:
            self._approach(self._pp_target,
                           min(vmax, float(self.get(0x6081))),
                           min(amax, float(self.get(0x6083))), dt)
        self._update_status()


class SimBus:
    """Simulated drives on their own canopen network on a virtual bus
    ``channel`` (connected to the other buses of the same process)."""

    def __init__(self, channel: str, drives: Iterable[SimDrive],
                 interface: str = "virtual"):
        self.channel = channel
        self.interface = interface
        self.drives = {d.node_id: d for d in drives}
        self.network: Optional[canopen.Network] = None
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None

    def start(self) -> SimBus:
        self.network = canopen.Network()
        self.network.NOTIFIER_CYCLE = 0.1   # quick stop
        self.network.connect(interface=self.interface, channel=self.channel)
        for drive in self.drives.values():
            drive.attach(self.network)
        for drive in self.drives.values():
            drive._send(0x700 + drive.node_id, b"\x00")      # boot-up
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name="cia402-sim")
        self._thread.start()
        return self

    def _run(self) -> None:
        while not self._stop.wait(0.005):
            now = time.monotonic()
            for drive in self.drives.values():
                drive.tick(now)

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5)
        if self.network is not None:
            self.network.disconnect()
            self.network = None

    def __getitem__(self, node_id: int) -> SimDrive:
        return self.drives[node_id]
