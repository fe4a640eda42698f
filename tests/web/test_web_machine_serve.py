"""``halsdk web machine.ini``: the machine and the workbench started
together (halsdk.web.machinehost), ended together; and the Machine page
of a workbench whose instance runs no task controller.
"""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

import pytest
from helpers.polling import wait_for
from helpers.running_machine import halsdk_command, mill_ini
from starlette.testclient import TestClient

from halsdk.testing import private_instance_name
from halsdk.web.app import create_app

TOKEN = "serve-token-0123456789"
BASE = "http://127.0.0.1:8125"


def segments(instance: str) -> list[str]:
    """The /dev/shm segments of ``instance``."""
    return [n for n in os.listdir("/dev/shm")
            if n.startswith(f"halsdk-{os.getuid()}-") and
            n.endswith(f"-{instance}")]


def web(folder: Path, *args: str, instance: str) -> subprocess.Popen:
    return subprocess.Popen(
        halsdk_command() + ["web", "--token", TOKEN, "--instance", instance,
                            *args],
        cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)


def started(proc: subprocess.Popen) -> str:
    """The URL line once the workbench serves (AssertionError else)."""
    assert proc.stdout is not None
    for line in proc.stdout:
        if "http://" in line:
            return line.strip()
    proc.wait(timeout=60)
    raise AssertionError(f"halsdk web did not start: "
                         f"{proc.stderr.read() if proc.stderr else ''}")


def children(pid: int) -> list[int]:
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return []
    return [int(p) for p in text.split()]


def gone(pid: int) -> bool:
    """Whether process ``pid`` ended (a zombie counts)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] == "Z"
    except OSError:
        return True


@pytest.mark.slow
def test_sigterm_stops_the_server_and_the_machine(tmp_path):
    instance = private_instance_name()
    proc = web(tmp_path, str(mill_ini(tmp_path)), instance=instance)
    try:
        url = started(proc)
        assert f":{TOKEN}" not in url and f"token={TOKEN}" in url
        assert segments(instance)
        (host,) = children(proc.pid)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert "Traceback" not in err
    assert "machine running" in err and "stopped" in err
    assert segments(instance) == []
    assert gone(host)


@pytest.mark.slow
def test_the_server_ends_when_the_machine_ends(tmp_path):
    instance = private_instance_name()
    proc = web(tmp_path, str(mill_ini(tmp_path)), instance=instance)
    try:
        started(proc)
        (host,) = children(proc.pid)
        os.kill(host, signal.SIGTERM)           # halsdk run stops cleanly
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 1
    assert "the machine ended by itself" in err
    assert "Traceback" not in err
    assert segments(instance) == []


@pytest.mark.slow
def test_a_killed_server_takes_the_machine_with_it(tmp_path):
    instance = private_instance_name()
    proc = web(tmp_path, str(mill_ini(tmp_path)), instance=instance)
    try:
        started(proc)
        (host,) = children(proc.pid)
        proc.kill()
        proc.communicate(timeout=30)
        # the kernel's SIGTERM: halsdk run shuts the machine down
        assert wait_for(lambda: gone(host), 60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert wait_for(lambda: segments(instance) == [], 30)


@pytest.mark.parametrize("text", [None, "[EMC]\nMACHINE = nothing\n"])
def test_a_bad_ini_gives_one_line_and_status_1(tmp_path, text):
    ini = tmp_path / "bad.ini"
    if text is not None:
        ini.write_text(text)
    instance = private_instance_name()
    proc = web(tmp_path, str(ini), instance=instance)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("halsdk web: ") and str(ini) in lines[0]
    assert ("cannot read" if text is None else "HALFILE") in lines[0]
    assert "http://" not in out
    assert segments(instance) == []


def test_help_names_the_ini_file():
    out = subprocess.run(halsdk_command() + ["web", "--help"],
                         capture_output=True, text=True, timeout=60).stdout
    assert "machine.ini" in out and "halsdk run" in out


def test_no_task_controller(hal):
    """HAL runs, but no task: the page says so and keeps looking."""
    app = create_app(hal, token=TOKEN)
    with TestClient(app, base_url=BASE) as c:
        c.get("/?token=" + TOKEN)

        def why() -> str:
            return c.get("/api/machine/status").json().get("why", "")
        assert wait_for(lambda: "no task" in why(), 10)
        assert c.get("/api/machine/status").json()["connected"] is False
        r = c.post("/api/machine/on", json={}, headers={"origin": BASE})
        assert r.status_code == 503 and "no task" in r.json()["error"]
        page = app.state.workbench.pages["machine"]
        tries = page._next_try
        # it keeps looking, once a second
        assert wait_for(lambda: (c.get("/api/machine/status"),
                                 page._next_try > tries)[1], 10)
