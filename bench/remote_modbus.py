"""Transactions per second of the mb2hal engine against a local pymodbus
TCP server on loopback (read holding registers, write registers, write
coils; no rate limit).

    python bench/remote_modbus.py [seconds]
"""

from __future__ import annotations

import importlib.util
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

INI = """[MB2HAL_INIT]
INIT_DEBUG=0
VERSION=1.1
HAL_MODULE_NAME=mbbench
TOTAL_TRANSACTIONS=3
[TRANSACTION_00]
LINK_TYPE=tcp
TCP_IP=127.0.0.1
TCP_PORT={port}
MB_SLAVE_ID=1
MB_TX_CODE=fnct_03_read_holding_registers
FIRST_ELEMENT=0
NELEMENTS=10
DEBUG=0
[TRANSACTION_01]
MB_TX_CODE=fnct_16_write_multiple_registers
FIRST_ELEMENT=20
NELEMENTS=10
[TRANSACTION_02]
MB_TX_CODE=fnct_15_write_multiple_coils
FIRST_ELEMENT=0
NELEMENTS=16
"""


def _simulator():
    path = ROOT / "examples" / "modbus" / "simulator.py"
    spec = importlib.util.spec_from_file_location("mb2hal_simulator", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def bench(seconds: float = 3.0) -> dict:
    """Run the engine for ``seconds``; return transactions per second."""
    from halsdk.drivers.mb2hal import Mb2hal, load_config

    import halsdk
    sim = _simulator()
    server = sim.ServerThread().start()
    hal = None
    if not os.environ.get("HALSDK_INSTANCE"):
        os.environ["HALSDK_INSTANCE"] = f"mbbench-{os.getpid()}"
    try:
        hal = halsdk.Hal()
        with tempfile.TemporaryDirectory() as tmp:
            ini = Path(tmp) / "bench.ini"
            ini.write_text(INI.format(port=server.port))
            engine = Mb2hal(load_config(str(ini)))
            engine.start()
            try:
                time.sleep(0.2)                  # connected, warm
                n0, t0 = engine.transactions_done, time.monotonic()
                time.sleep(seconds)
                n1, t1 = engine.transactions_done, time.monotonic()
                errors = sum(hal.getp(f"mbbench.{i:02d}.num_errors")
                             for i in range(3))
            finally:
                engine.stop()
    finally:
        if hal is not None:
            hal.close()
        server.stop()
    result = {"name": "mb2hal_tcp_loopback",
              "transactions": n1 - n0, "seconds": round(t1 - t0, 3),
              "tx_per_s": round((n1 - n0) / (t1 - t0), 1),
              "errors": errors}
    print(f"mb2hal TCP loopback: {result['tx_per_s']} transactions/s "
          f"({result['transactions']} in {result['seconds']} s, "
          f"{errors} errors)")
    return result


if __name__ == "__main__":
    bench(float(sys.argv[1]) if len(sys.argv) > 1 else 3.0)
