"""A small Modbus TCP (or RTU) server on loopback for trying mb2hal.

    python simulator.py [--port 5020]           # TCP on 127.0.0.1
    python simulator.py --serial /dev/pts/N     # RTU on a serial port

Every table (coils, discrete inputs, holding and input registers) holds
addresses 0..199 (input registers 0..2 hold 100, 200, 300).
:class:`ServerThread` runs the same server in a background thread (used
by the tests and the benchmark; ``on_request`` is called for every
request the server receives; with ``record`` each request is kept in
:attr:`ServerThread.requests` as ``(function code, address, count or
values)``). ``--log FILE`` writes one such line per request.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import os
import signal
import sys
import threading
import time
from typing import Any, Callable, Optional

SIZE = 200


def make_context(size: int = SIZE, inputs: Optional[list[int]] = None,
                 discrete: Optional[list[bool]] = None) -> Any:
    """A single-device server context with ``size`` elements per table,
    protocol addresses 0..size-1."""
    from pymodbus.datastore import (
        ModbusDeviceContext,
        ModbusSequentialDataBlock,
        ModbusServerContext,
    )
    logging.getLogger("pymodbus").setLevel(logging.CRITICAL)
    ir = (inputs or []) + [0] * (size - len(inputs or []))
    di = (discrete or []) + [False] * (size - len(discrete or []))
    device = ModbusDeviceContext(
        co=ModbusSequentialDataBlock(1, [False] * size),
        di=ModbusSequentialDataBlock(1, di),
        hr=ModbusSequentialDataBlock(1, [0] * size),
        ir=ModbusSequentialDataBlock(1, ir))
    return ModbusServerContext(devices=device, single=True)


class ServerThread:
    """A pymodbus server served from its own event loop thread."""

    def __init__(self, port: int = 0, serial: str = "",
                 context: Any = None, baudrate: int = 115200,
                 on_request: Optional[Callable[[], None]] = None,
                 record: bool = False, log: Optional[str] = None):
        self.port = port
        self.on_request = on_request
        self.record = record or bool(log)
        self.log = open(log, "a", buffering=1) if log else None
        #: (function code, address, count or written values) per request
        self.requests: list[tuple[int, int, Any]] = []
        self.serial = serial
        self.baudrate = baudrate
        self.context = context if context is not None else make_context()
        self.loop = asyncio.new_event_loop()
        self.server: Any = None
        self.thread = threading.Thread(target=self.loop.run_forever,
                                       daemon=True, name="modbus-server")

    def _trace(self, sending: bool, pdu: Any) -> Any:
        if not sending and self.on_request is not None:
            self.on_request()
        if not sending and self.record:
            code = pdu.function_code
            if code in (5, 6, 15, 16):
                data: Any = [int(v) for v in (pdu.bits if code in (5, 15)
                                              else pdu.registers)]
                if code in (5, 15):
                    data = data[:pdu.count or 1]
            else:
                data = pdu.count
            entry = (code, pdu.address, data)
            self.requests.append(entry)
            if self.log is not None:
                self.log.write(f"fc={code} address={entry[1]} {data}\n")
        return pdu

    async def _create(self) -> None:
        from pymodbus.server import ModbusSerialServer, ModbusTcpServer
        trace = ({"trace_pdu": self._trace}
                 if self.on_request or self.record else {})
        if self.serial:
            self.server = ModbusSerialServer(
                self.context, port=self.serial, baudrate=self.baudrate,
                stopbits=1, bytesize=8, parity="N", timeout=1, **trace)
        else:
            self.server = ModbusTcpServer(
                self.context, address=("127.0.0.1", self.port), **trace)
        await self.server.serve_forever(background=True)
        if not self.serial and not self.port:
            sock = self.server.transport.sockets[0]
            self.port = sock.getsockname()[1]

    def start(self, timeout: float = 5.0) -> ServerThread:
        self.thread.start()
        fut = asyncio.run_coroutine_threadsafe(self._create(), self.loop)
        fut.result(timeout)
        return self

    def stop(self, timeout: float = 5.0) -> None:
        if self.server is not None:
            fut = asyncio.run_coroutine_threadsafe(self.server.shutdown(),
                                                   self.loop)
            try:
                fut.result(timeout)
            except Exception:       # already closed
                pass
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout)
        if not self.thread.is_alive():
            self.loop.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--port", type=int, default=5020)
    parser.add_argument("--serial", default="")
    parser.add_argument("--log", default=None,
                        help="write each request received to this file")
    parser.add_argument("--port-file", default=None,
                        help="write the port to this file once serving "
                        "(with --port 0: a free port)")
    args = parser.parse_args()
    context = make_context(inputs=[100, 200, 300], discrete=[True])
    server = ServerThread(args.port, args.serial, context,
                          log=args.log).start()
    where = args.serial or f"127.0.0.1:{server.port}"
    if args.port_file:
        with open(args.port_file + ".tmp", "w") as f:
            f.write(f"{server.port}\n")
        os.replace(args.port_file + ".tmp", args.port_file)
    print(f"modbus simulator on {where}; Ctrl-C stops it", flush=True)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    try:
        while True:
            time.sleep(1)
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()


if __name__ == "__main__":
    main()
