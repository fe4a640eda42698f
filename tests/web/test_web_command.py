"""``halsdk web`` as a user runs it: the installed console script against
an instance that ``halrun`` hosts in another process."""

from __future__ import annotations

import json
import os
import queue
import re
import shlex
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from http.cookiejar import CookieJar
from pathlib import Path
from urllib.parse import urlsplit

import pytest
from helpers import repo_path
from helpers.docblocks import code_blocks
from helpers.polling import wait_for
from helpers.running_machine import halsdk_command

HAL_FILE = """\
loadrt threads name1=servo period1=1000000
loadrt and2 count=2
addf and2.0 servo
net x-in and2.0.in0
start
"""


def _env(tag: str) -> dict:
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = f"web-{os.getpid()}-{tag}"
    env.pop("HALSDK_WEB_TOKEN", None)
    return env


def _segments(env: dict) -> list[str]:
    return [n for n in os.listdir("/dev/shm")
            if n.endswith(env["HALSDK_INSTANCE"])]


def _end(proc: subprocess.Popen, timeout: float = 20) -> None:
    if proc.poll() is None:
        proc.kill()
        proc.wait(timeout=timeout)


@pytest.fixture
def halrun(tmp_path: Path) -> Iterator[dict]:
    """A halrun host of the HAL file above (its own instance); its
    environment, for the programs that attach."""
    env = _env(tmp_path.name[-20:])
    (tmp_path / "bench.hal").write_text(HAL_FILE)
    host = subprocess.Popen(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-I", "-f",
         "bench.hal"], cwd=tmp_path, env=env, stdin=subprocess.PIPE,
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        probe = [sys.executable, "-m", "halsdk.halcmd.cli", "halcmd",
                 "getp", "and2.0.in0"]
        assert wait_for(lambda: subprocess.run(
            probe, cwd=tmp_path, env=env, capture_output=True,
            timeout=60).returncode == 0, timeout=60), "halrun did not start"
        env["_HOST_PID"] = str(host.pid)
        yield env
    finally:
        if host.stdin:
            host.stdin.close()          # halrun -I ends at end of input
        try:
            host.wait(timeout=30)
        finally:
            _end(host)
            if host.stderr:
                host.stderr.close()
    assert _segments(env) == []


def _start(env: dict, cwd: Path, *args: str) -> subprocess.Popen:
    return subprocess.Popen(halsdk_command() + ["web", *args], cwd=cwd,
                            env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _url(proc: subprocess.Popen, timeout: float = 60) -> str:
    """The URL the program prints (it has started serving then)."""
    return _greeting(proc, timeout)[-1]


def _greeting(proc: subprocess.Popen, timeout: float = 60) -> list[str]:
    """The lines the program prints up to its URL."""
    lines: queue.Queue = queue.Queue()

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.put(line)
            if "http://" in line:
                return
        lines.put("")

    threading.Thread(target=read, daemon=True).start()
    seen: list[str] = []
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            break
        seen.append(line.rstrip("\n"))
        if "http://" in line:
            seen[-1] = seen[-1].strip()
            return seen
        if not line:
            break
    _end(proc)
    raise AssertionError(f"no URL: {seen!r} {proc.stderr.read()!r}")


def _opener() -> urllib.request.OpenerDirector:
    return urllib.request.build_opener(
        urllib.request.HTTPCookieProcessor(CookieJar()))


def test_help(tmp_path):
    proc = subprocess.run(halsdk_command() + ["web", "--help"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    for option in ("--instance", "--host", "--port", "--read-only",
                   "--token"):
        assert option in proc.stdout
    top = subprocess.run(halsdk_command() + ["--help"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=60)
    assert "web" in top.stdout


def test_no_instance_is_one_line_and_exit_1(tmp_path):
    env = _env("none")
    proc = subprocess.run(halsdk_command() + ["web"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1
    assert proc.stdout == ""
    assert proc.stderr == (f"halsdk web: no HAL instance "
                           f"'{env['HALSDK_INSTANCE']}' is running (start "
                           "one with halrun or halsdk.Hal())\n")
    assert _segments(env) == []                 # it created none


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_it_serves_on_loopback_and_a_signal_ends_it(halrun, tmp_path,
                                                    signum):
    proc = _start(halrun, tmp_path)
    try:
        url = _url(proc)
        parts = urlsplit(url)
        assert parts.hostname == "127.0.0.1" and parts.port
        token = parts.query.partition("token=")[2]
        assert len(token) >= 32                 # token_urlsafe(24)
        base = f"http://127.0.0.1:{parts.port}"
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(base + "/api/tree", timeout=30)
        assert refused.value.code == 403
        opener = _opener()
        page = opener.open(url, timeout=30)     # 303 to /, with the cookie
        assert page.status == 200 and page.url == base + "/"
        assert b"<title>HAL workbench</title>" in page.read()
        tree = json.load(opener.open(base + "/api/tree", timeout=30))
        assert tree["instance"] == halrun["HALSDK_INSTANCE"]
        assert "and2.0.in0" in {p["name"] for p in tree["pins"]}
        os.kill(proc.pid, signum)
        out, err = proc.communicate(timeout=30)
    finally:
        _end(proc)
    assert proc.returncode == 0, err
    assert "Traceback" not in err and err.strip() == "", err


def test_read_only_and_a_given_token(halrun, tmp_path):
    proc = _start(halrun, tmp_path, "--read-only", "--token", "s3cret-1")
    try:
        url = _url(proc)
        assert url.endswith("/?token=s3cret-1")
        base = url.partition("/?")[0]
        opener = _opener()
        opener.open(url, timeout=30)
        request = urllib.request.Request(
            base + "/api/setp", method="POST",
            data=json.dumps({"name": "and2.0.in1", "value": "1"}).encode(),
            headers={"Content-Type": "application/json"})
        with pytest.raises(urllib.error.HTTPError) as refused:
            opener.open(request, timeout=30)
        assert refused.value.code == 403
        assert "read-only" in json.load(refused.value)["error"]
        os.kill(proc.pid, signal.SIGTERM)
        proc.communicate(timeout=30)
    finally:
        _end(proc)
    assert proc.returncode == 0
    getp = subprocess.run([sys.executable, "-m", "halsdk.halcmd.cli",
                           "halcmd", "getp", "and2.0.in1"], cwd=tmp_path,
                          env=halrun, capture_output=True, text=True,
                          timeout=60)
    assert getp.stdout == "FALSE\n"


def test_it_ends_with_its_host(halrun, tmp_path):
    proc = _start(halrun, tmp_path)
    try:
        _url(proc)
        os.kill(int(halrun["_HOST_PID"]), signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
    finally:
        _end(proc)
    assert proc.returncode == 0, err
    assert "Traceback" not in err


def _normal(lines: list[str], command: str) -> list[str]:
    """The greeting without what differs from run to run: the instance,
    and the port and token unless the command gives them."""
    out = []
    for line in lines:
        line = re.sub(r"instance '[^']*'", "instance 'NAME'", line.strip())
        if "--port" not in command:
            line = re.sub(r":\d+/", ":PORT/", line)
        if "--token" not in command:
            line = re.sub(r"token=[\w-]{32}$", "token=TOKEN", line)
        out.append(line)
    return out


def test_the_examples_of_the_docs_run(halrun, tmp_path):
    """The console blocks of docs/web.rst, run as the page types them;
    they print what the page shows and serve the page."""
    blocks = code_blocks(repo_path("docs", "web.rst"), "console")
    assert len(blocks) == 2
    for block in blocks:
        command, *shown = block.splitlines()
        assert command.startswith("$ halsdk web")
        proc = _start(halrun, tmp_path, *shlex.split(command)[3:])
        try:
            printed = _greeting(proc)
            assert _normal(printed, command) == _normal(shown, command)
            page = _opener().open(printed[-1], timeout=30)
            assert page.status == 200
            os.kill(proc.pid, signal.SIGTERM)
            proc.communicate(timeout=30)
        finally:
            _end(proc)
        assert proc.returncode == 0


def test_sigterm_ends_it_with_a_page_connected(halrun, tmp_path):
    """An open websocket (a page watching values) does not hold the
    server: SIGTERM still ends it, with 0."""
    from websockets.sync.client import connect
    proc = _start(halrun, tmp_path)
    try:
        parts = urlsplit(_url(proc))
        base = f"http://127.0.0.1:{parts.port}"
        with connect(f"ws://127.0.0.1:{parts.port}/ws?{parts.query}",
                     origin=base, open_timeout=30) as ws:
            ws.send(json.dumps({"watch": ["pin:and2.0.in0"]}))
            assert json.loads(ws.recv(timeout=30)) == {
                "values": {"pin:and2.0.in0": "FALSE"}}
            os.kill(proc.pid, signal.SIGTERM)
            out, err = proc.communicate(timeout=30)
    finally:
        _end(proc)
    assert proc.returncode == 0, err
    assert "Traceback" not in err


def test_a_port_in_use_is_one_line_and_exit_1(halrun, tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        proc = subprocess.run(halsdk_command() + ["web", "--port", str(port)],
                              cwd=tmp_path, env=halrun, capture_output=True,
                              text=True, timeout=60)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.startswith(f"halsdk web: cannot listen on "
                                  f"127.0.0.1:{port}: ")
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
