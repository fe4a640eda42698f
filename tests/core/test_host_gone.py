"""A request in flight when the host dies (issue 19).

The host is a Python process; ``loadrt slowsetup`` asks it to load a
module whose ``setup`` sleeps, and the test SIGKILLs the host meanwhile.
The client, a Python program or the installed ``halcmd``, must report a
:class:`halsdk.HostGoneError` (an ``InstanceError``) naming the instance:
one line from halcmd, exit status 1, no traceback, never a bare
``ConnectionResetError``.  A host that is not there at all (no socket,
a refused connection) gives the same error.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

import halsdk
from halsdk.core import channel
from halsdk.core.instance import shm_name

BOUND = 30.0

SLOW_MODULE = """\
import time
from pathlib import Path

def setup(**params):
    Path(__file__).with_name("setup-started").touch()
    time.sleep(60)
"""

HOST = """\
import time
import halsdk
hal = halsdk.Hal(create=True)
print("hosting", flush=True)
time.sleep(120)
"""

CLIENT = """\
import sys
import halsdk
hal = halsdk.Hal(create=False)
try:
    hal.loadrt("slowsetup")
except halsdk.HostGoneError as exc:
    assert isinstance(exc, halsdk.InstanceError)
    print("HostGoneError:", exc, flush=True)
    sys.exit(3)
"""


def _program(name: str) -> list[str]:
    path = os.path.join(os.path.dirname(sys.executable), name)
    if os.path.exists(path):
        return [path]
    return [sys.executable, "-m", "halsdk.halcmd.cli", name]


@pytest.fixture
def host(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
         ) -> Iterator[tuple[subprocess.Popen, str, Path]]:
    """A host process of a private instance, with the slow module on its
    HALSDK_PATH; the instance's leftovers are removed at the end."""
    name = f"hostgone-{os.getpid()}-{time.monotonic_ns() % 10**9}"
    monkeypatch.setenv("HALSDK_INSTANCE", name)
    (tmp_path / "slowsetup.py").write_text(SLOW_MODULE)
    monkeypatch.setenv("HALSDK_PATH", str(tmp_path))
    proc = subprocess.Popen([sys.executable, "-c", HOST], cwd=tmp_path,
                            stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline().strip() == "hosting"
        yield proc, name, tmp_path
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait(BOUND)
        if proc.stdout is not None:
            proc.stdout.close()
        shm = shm_name(name)
        try:
            os.unlink("/dev/shm/" + shm.lstrip("/"))
        except FileNotFoundError:
            pass
        channel.remove_socket(shm)


def _kill_when_setup_runs(proc: subprocess.Popen, folder: Path) -> None:
    deadline = time.monotonic() + BOUND
    while not (folder / "setup-started").exists():
        assert time.monotonic() < deadline, "setup never started"
        time.sleep(0.01)
    os.kill(proc.pid, signal.SIGKILL)


def test_python_client_gets_host_gone(host):
    proc, name, folder = host
    client = subprocess.Popen([sys.executable, "-c", CLIENT], cwd=folder,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    try:
        _kill_when_setup_runs(proc, folder)
        out, err = client.communicate(timeout=BOUND)
    finally:
        if client.poll() is None:
            client.kill()
            client.wait()
    assert client.returncode == 3, err
    assert out.startswith("HostGoneError: ")
    assert f"HAL instance '{name}'" in out
    assert "ConnectionResetError" not in out + err


def test_halcmd_prints_one_line(host):
    proc, name, folder = host
    client = subprocess.Popen(_program("halcmd") + ["loadrt", "slowsetup"],
                              cwd=folder, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    try:
        _kill_when_setup_runs(proc, folder)
        out, err = client.communicate(timeout=BOUND)
    finally:
        if client.poll() is None:
            client.kill()
            client.wait()
    assert client.returncode == 1
    assert "Traceback" not in out + err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert f"HAL instance '{name}'" in lines[0]
    assert "host" in lines[0]


def test_no_host_listening(hal):
    """The socket is gone (a host that died earlier): refused."""
    shm = shm_name(hal.instance)
    with pytest.raises(halsdk.HostGoneError,
                       match=f"HAL instance '{hal.instance}-nobody': "
                             "cannot reach its host"):
        channel.request(shm + "-nobody", "ping")
