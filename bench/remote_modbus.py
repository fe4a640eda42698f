"""Transactions per second of mb2hal against a local pymodbus TCP server
on loopback (read holding registers, write registers, write coils; no
rate limit).

``bench()`` runs our engine in this process. ``compare()`` runs the same
INI file as a program under halrun (``loadusr -W mb2hal config=...``),
ours and -- when LinuxCNC is installed -- the reference's, one after the
other, and counts the requests at the server, so both are measured the
same way in one run.

    python bench/remote_modbus.py [seconds] [--no-reference]
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchlib import (
    LOCK,
    REFERENCE_MB2HAL,
    REFERENCE_TOOL,
    run_folder,
    session,
    use_reference,
)

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
    import halsdk
    from halsdk.drivers.mb2hal import Mb2hal, load_config
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


def _program_rate(reference: bool, seconds: float) -> float:
    """Requests per second that halrun + mb2hal make, counted at the
    server."""
    sim = _simulator()
    count = [0]

    def on_request() -> None:
        count[0] += 1

    server = sim.ServerThread(on_request=on_request).start()
    hal = ("loadusr -Wn mbbench mb2hal config=bench.ini\n"
           f"loadusr -w sleep {seconds + 3:.1f}\n")
    env = dict(os.environ)
    if reference:
        env["PATH"] = "/usr/sbin:/usr/bin:/sbin:/bin"
        cmd = ["flock", LOCK, "timeout", "120", REFERENCE_TOOL,
               "halrun", "-f", "bench.hal"]
    else:
        bindir = os.path.dirname(sys.executable)
        env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
        env["HALSDK_INSTANCE"] = f"mbbench-{os.getpid()}"
        cmd = [os.path.join(bindir, "halrun"), "-f", "bench.hal"]
    try:
        with run_folder("halsdk-bench-mb-",
                        {"bench.ini": INI.format(port=server.port),
                         "bench.hal": hal}) as folder, \
                session(cmd, cwd=folder, env=env, stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL) as proc:
            deadline = time.monotonic() + 60
            while count[0] == 0:
                if proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError("mb2hal sent no request")
                time.sleep(0.01)
            time.sleep(0.5)                      # connected, warm
            n0, t0 = count[0], time.monotonic()
            time.sleep(seconds)
            n1, t1 = count[0], time.monotonic()
            proc.wait(timeout=seconds + 60)
    finally:
        server.stop()
    return (n1 - n0) / (t1 - t0)


def compare(seconds: float = 3.0, reference: bool = True) -> dict:
    """Ours and the reference's mb2hal program, side by side."""
    ours = _program_rate(False, seconds)
    ref = None
    if use_reference(reference, REFERENCE_MB2HAL):
        ref = _program_rate(True, seconds)
    print(f"mb2hal program under halrun, requests/s at the server: "
          f"ours {ours:.0f}, reference "
          + (f"{ref:.0f}, ratio ours/reference {ours / ref:.2f}"
             if ref else "not installed"))
    return {"ours_tx_per_s": round(ours, 1),
            "reference_tx_per_s": None if ref is None else round(ref, 1)}


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    secs = float(args[0]) if args else 3.0
    bench(secs)
    compare(secs, reference="--no-reference" not in sys.argv)
