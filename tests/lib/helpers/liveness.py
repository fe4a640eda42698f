"""A host that is SIGKILLed, as a user's machine may be: ``halrun -f
x.hal`` kept running by a last ``loadusr -w sleep``, the installed
``halcmd`` attached to it, and the measure of how soon a process ends
(tests/core/test_liveness.py, tests/drivers/test_liveness_drivers.py)."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from helpers.halcompile import child_env
from helpers.polling import wait_for

#: bound of "the program ended" after the host's SIGKILL (measured by
#: bench/liveness.py: 25-70 ms median, under 200 ms); generous for a
#: loaded machine
BOUND = 1.0


def tag(name: str) -> str:
    """The private instance name of a test's host."""
    return f"live-{os.getpid()}-{name}"


def program(name: str) -> str:
    """An installed console script of the Python under test."""
    return os.path.join(os.path.dirname(sys.executable), name)


def env_for(name: str, **extra: str) -> dict[str, str]:
    """A child's environment: the instance ``tag(name)``, this Python's
    programs first on PATH."""
    env = child_env(HALSDK_INSTANCE=tag(name), **extra)
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + \
        env.get("PATH", "")
    return env


def shm_left(name: str) -> list[str]:
    return [n for n in os.listdir("/dev/shm") if tag(name) in n]


def read_pid(path: Path, timeout: float = 20.0) -> int:
    """The pid a program wrote (atomically) into ``path``."""
    assert wait_for(path.exists, timeout), f"{path} was not written"
    return int(path.read_text())


def wait_ended(pid: int, timeout: float) -> float:
    """Seconds until process ``pid`` (not our child) ends, by a pidfd;
    AssertionError after ``timeout``."""
    t0 = time.monotonic()
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        return 0.0
    try:
        ready, _, _ = select.select([fd], [], [], timeout)
        assert ready, f"process {pid} still runs {timeout} s later"
        return time.monotonic() - t0
    finally:
        os.close(fd)


def alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie does not)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] not in "ZX"
    except FileNotFoundError:
        return False


class Host:
    """``halrun -f x.hal`` in ``cwd``, kept running by a last
    ``loadusr -w sleep 120``; its stderr goes to ``cwd/halrun.err``."""

    def __init__(self, cwd: Path, name: str, hal_text: str,
                 new_session: bool = False, **env: str):
        self.name = name
        self.env = env_for(name, **env)
        self.cwd = cwd
        (cwd / "x.hal").write_text(hal_text + "loadusr -w sleep 120\n")
        self.err = open(cwd / "halrun.err", "w+")
        self.proc = subprocess.Popen(
            [program("halrun"), "-f", "x.hal"], cwd=cwd, env=self.env,
            stdout=subprocess.DEVNULL, stderr=self.err,
            start_new_session=new_session)

    def halcmd(self, *args: str, check: bool = True
               ) -> subprocess.CompletedProcess:
        """The installed halcmd attached to the host (stdout and stderr
        together)."""
        proc = subprocess.run([program("halcmd"), *args], cwd=self.cwd,
                              env=self.env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True,
                              timeout=60)
        if check:
            assert proc.returncode == 0, proc.stdout
        return proc

    def up(self) -> None:
        """Wait until the instance answers halcmd."""
        assert wait_for(lambda: self.halcmd("show", "comp", check=False)
                        .returncode == 0, 20), self.stderr()

    def comp_pid(self, comp: str) -> int:
        rows = self.halcmd("-s", "show", "comp", comp).stdout.split()
        return int(rows[rows.index(comp) + 1])

    def kill(self) -> None:
        self.proc.kill()
        self.proc.wait()

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self.err.close()
        # a SIGKILLed host leaves its segment: remove it as a user does
        subprocess.run([program("halrun"), "-U"], cwd=self.cwd, env=self.env,
                       capture_output=True, timeout=60)

    def stderr(self) -> str:
        self.err.seek(0)
        return self.err.read()


class Hosts:
    """The body of a fixture: hosts made with :meth:`make`, pids of
    programs to kill if a failed test left them running; at the end no
    host, no program and no /dev/shm segment is left."""

    def __init__(self, cwd: Path):
        self.cwd = cwd
        self.hosts: list[Host] = []
        self.pids: list[int] = []

    def make(self, name: str, hal_text: str, new_session: bool = False,
             **env: str) -> Host:
        host = Host(self.cwd, name, hal_text, new_session, **env)
        self.hosts.append(host)
        return host

    def close(self) -> None:
        for host in self.hosts:
            host.close()
        for pid in self.pids:
            if alive(pid):
                os.kill(pid, signal.SIGKILL)
        for host in self.hosts:
            assert not shm_left(host.name), shm_left(host.name)


def hosts_fixture(cwd: Path) -> Iterator[Any]:
    hosts = Hosts(cwd)
    try:
        yield hosts
    finally:
        hosts.close()


def guards_of(pid: int) -> list[int]:
    """The ``halsdk-guard`` processes that watch process ``pid`` (a pidfd
    of theirs names it in /proc/<guard>/fdinfo)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/comm") as f:
                if f.read().strip() != "halsdk-guard":
                    continue
            for fd in os.listdir(f"/proc/{entry}/fdinfo"):
                with open(f"/proc/{entry}/fdinfo/{fd}") as f:
                    if f"Pid:\t{pid}\n" in f.read():
                        found.append(int(entry))
                        break
        except OSError:
            continue
    return found
