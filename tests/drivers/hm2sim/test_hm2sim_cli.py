"""The hm2-sim console script."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from halsdk.drivers.hm2sim import Hm2Sim

COMMAND = [sys.executable, "-m", "halsdk.drivers.hm2sim"]


def _run(args: list[str], tmp_path: Path, **kw) -> subprocess.CompletedProcess:
    return subprocess.run(COMMAND + args, cwd=tmp_path, capture_output=True,
                          text=True, timeout=30, **kw)


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_help(tmp_path: Path) -> None:
    proc = _run(["--help"], tmp_path)
    assert proc.returncode == 0
    for word in ("--board", "{7i92,7i96s}", "--port", "27181", "--drop",
                 "--control", "away | back"):
        assert word in proc.stdout


SCRIPT = shutil.which("hm2-sim", path=str(Path(sys.executable).parent)) \
    or shutil.which("hm2-sim")


@pytest.mark.skipif(SCRIPT is None, reason="the console script is not "
                    "installed (pip install -e . makes it)")
def test_console_script_help(tmp_path: Path) -> None:
    assert SCRIPT is not None
    proc = subprocess.run([SCRIPT, "--help"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=30)
    assert proc.returncode == 0 and "--board" in proc.stdout


def test_port_in_use(tmp_path: Path) -> None:
    with Hm2Sim(port=0) as sim:
        proc = _run(["--port", str(sim.port)], tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.strip() == (
        f"hm2-sim: error: UDP 127.0.0.1:{sim.port} is in use (another "
        "hm2-sim or card simulator?); choose another --port or --address")
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize("args, message", [
    (["--board", "7i99"], "invalid choice: '7i99'"),
    (["--drop", "2"], "'2': expected 0..1"),
    (["--port", "70000"], "'70000': expected 0..65535"),
    (["--delay", "100"], "--delay: expected 0..60 seconds"),
    (["--switch", "1:2:=5"], "expected PIN:STEPGEN:>=STEPS"),
    (["--switch", "1:9:>=5"], "stepgen 9: the 7i96s has 5"),
    (["--couple", "0"], "expected ENCODER:STEPGEN"),
])
def test_bad_command_line(args: list[str], message: str,
                          tmp_path: Path) -> None:
    proc = _run(args, tmp_path)
    assert proc.returncode == 2
    assert message in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_control_commands(tmp_path: Path) -> None:
    port = _free_port()
    script = "\n".join([
        "away", "back", "input 3 0", "encoder 0 42", "index 0", "drop 1",
        "delay 0.01 p0.5", "clear", "bogus", "status", "quit"]) + "\n"
    proc = _run(["--board", "7I92", "--port", str(port), "--control",
                 "--switch", "20:0:<=-1:low"],
                tmp_path, input=script)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert f"hm2-sim: Mesa 7I92 with a 7I76 on P2 on UDP 127.0.0.1:{port}" \
        in out
    assert "hm2-sim: bogus: unknown command" in out
    assert "encoder 0 {'position': 42, 'count': 42" in out
    assert "'index_events': 1" in out
    assert "stepgen 4 position 0.0000 steps" in out
    # the status line of the pins: pin 3 low, the rest pulled up; the
    # encoder's A, B (position 42: phase 2) high
    pins = next(line for line in out.splitlines() if line.startswith("pins"))
    assert pins.split()[1][3] == "0" and len(pins.split()[1]) == 34
    # the switch on pin 20 is off (the axis is at 0): it reads high
    assert pins.split()[1][20] == "1"


def test_sigterm_stops_it(tmp_path: Path) -> None:
    port = _free_port()
    proc = subprocess.Popen(COMMAND + ["--port", str(port)], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=dict(os.environ))
    try:
        assert proc.stdout is not None
        assert "on UDP" in proc.stdout.readline()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.settimeout(5)
            s.sendto(bytes.fromhex("81420001"), ("127.0.0.1", port))
            assert s.recv(100) == bytes.fromhex("fecaaa55")
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=10) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_unwritable_log(tmp_path: Path) -> None:
    proc = _run(["--port", "0", "--log", str(tmp_path / "no" / "log.txt")],
                tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.strip() == (
        f"hm2-sim: error: cannot write the packet log {tmp_path}/no/log.txt: "
        "No such file or directory")


def test_couple_and_switch_arguments() -> None:
    from halsdk.drivers.hm2sim.__main__ import parse_args
    args = parse_args(["--couple", "0:1", "--couple", "0:2:4.5",
                       "--switch", "3:0:>=10", "--switch", "4:1:<=-2.5:low"])
    assert args.couple == [(0, 1, 1.0), (0, 2, 4.5)]
    assert args.switch == [(3, 0, 10.0, True, True),
                           (4, 1, -2.5, False, False)]
