"""One Modbus connection (TCP or RTU) driven through pymodbus with a
bounded time for every request."""

from __future__ import annotations

import logging
import re
from collections.abc import Sequence
from typing import Any, Optional

from .config import PARITIES, Link, Transaction

# pymodbus reports every refused connect at ERROR level; mb2hal reports
# link problems itself, once per outage.
logging.getLogger("pymodbus").setLevel(logging.CRITICAL)


class LinkDown(Exception):
    """The link is not usable (connect failed, timeout, bad frame): the
    connection is closed and opened again later."""


class Refused(Exception):
    """The device answered with a Modbus exception response."""

    NAMES = {1: "illegal function", 2: "illegal data address",
             3: "illegal data value", 4: "server device failure",
             5: "acknowledge", 6: "server device busy",
             8: "memory parity error", 10: "gateway path unavailable",
             11: "gateway target failed to respond"}

    def __init__(self, code: int):
        self.code = code
        super().__init__(f"exception 0x{code:02X} "
                         f"({self.NAMES.get(code, 'unknown')})")


class ModbusLink:
    """A pymodbus sync client for one :class:`Link`, opened on demand."""

    def __init__(self, link: Link):
        self.link = link
        self.client: Any = None

    @property
    def is_open(self) -> bool:
        return self.client is not None

    def open(self, timeout: float) -> None:
        from pymodbus.client import ModbusSerialClient, ModbusTcpClient
        from pymodbus.framer import FramerType
        link = self.link
        client: ModbusTcpClient | ModbusSerialClient
        if link.kind == "tcp" and not 1 <= link.port <= 65535:
            raise LinkDown(f"{link.describe()}: cannot connect: the port "
                           "is out of range")
        if link.kind == "tcp":
            client = ModbusTcpClient(link.ip, port=link.port, timeout=timeout,
                                     retries=0)
        else:
            client = ModbusSerialClient(
                link.device, framer=FramerType.RTU, baudrate=link.baud,
                bytesize=link.bits, parity=PARITIES[link.parity],
                stopbits=link.stop, timeout=timeout, retries=0)
        try:
            ok = client.connect()
        except Exception as exc:    # pyserial raises its own errors
            client.close()
            raise LinkDown(f"{link.describe()}: cannot connect: "
                           f"{exc}") from None
        if not ok:
            client.close()
            raise LinkDown(f"{link.describe()}: cannot connect")
        self.client = client

    def close(self) -> None:
        client, self.client = self.client, None
        if client is not None:
            try:
                client.close()
            except Exception:        # already gone
                pass

    def _timeouts(self, tx: Transaction) -> None:
        response = tx.response_timeout_ms / 1000.0
        self.client.comm_params.timeout_connect = response
        port = getattr(self.client, "socket", None)
        if self.link.kind == "serial" and port is not None:
            port.timeout = response
            port.inter_byte_timeout = tx.byte_timeout_ms / 1000.0 or None

    def execute(self, tx: Transaction,
                values: Optional[Sequence[int]] = None) -> list[int]:
        """Run one transaction; return the values read (reads) or [].
        A write needs ``values`` (one per element)."""
        from pymodbus.exceptions import ModbusException
        if values is None:
            if tx.is_write:
                raise TypeError(f"transaction {tx.name}: a write needs "
                                "values")
            values = ()
        if self.client is None:
            raise LinkDown(f"{self.link.describe()}: not connected")
        self._timeouts(tx)
        c = self.client
        kw = {"device_id": tx.slave_id}
        addr, n = tx.first_element, tx.count
        fn = tx.function
        try:
            if fn == 1:
                resp = c.read_coils(addr, count=n, **kw)
            elif fn == 2:
                resp = c.read_discrete_inputs(addr, count=n, **kw)
            elif fn == 3:
                resp = c.read_holding_registers(addr, count=n, **kw)
            elif fn == 4:
                resp = c.read_input_registers(addr, count=n, **kw)
            elif fn == 5:
                resp = c.write_coil(addr, bool(values[0]), **kw)
            elif fn == 6:
                resp = c.write_register(addr, int(values[0]), **kw)
            elif fn == 15:
                resp = c.write_coils(addr, [bool(v) for v in values], **kw)
            else:
                resp = c.write_registers(addr, [int(v) for v in values],
                                         **kw)
        except ModbusException as exc:
            raise LinkDown(f"{self.link.describe()}: {_short(exc)}") from None
        except OSError as exc:
            text = (exc.strerror or str(exc) or type(exc).__name__).lower()
            raise LinkDown(f"{self.link.describe()}: {text}") from None
        except ValueError as exc:
            raise LinkDown(f"{self.link.describe()}: bad response: "
                           f"{_short(exc)}") from None
        if resp is None:
            raise LinkDown(f"{self.link.describe()}: no response")
        if resp.isError():
            raise Refused(int(getattr(resp, "exception_code", 0)))
        if fn in (1, 2):
            bits = list(resp.bits)
            if len(bits) < n:
                raise LinkDown(f"{self.link.describe()}: short response")
            return [int(b) for b in bits[:n]]
        if fn in (3, 4):
            regs = list(resp.registers)
            if len(regs) != n:
                raise LinkDown(f"{self.link.describe()}: {len(regs)} "
                               f"registers in the response, {n} asked")
            return regs
        return []


def _short(exc: Exception) -> str:
    """A short, stable text for a pymodbus error (no addresses, byte
    counts or timings, so that one problem always reads the same)."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    low = text.lower()
    if ("no response received" in low or "timeouterror" in low
            or "timed out" in low):
        return "timeout, no response"
    if "unexpectedly closed" in low or "connection closed" in low:
        return "connection closed by the device"
    text = re.sub(r"^Modbus Error:\s*", "", text)
    text = re.sub(r"^\[[^\]]*\]\s*", "", text)
    text = re.sub(r"^Modbus\w*Client\s+\S+\s*", "", text)
    return text[:100] or type(exc).__name__
