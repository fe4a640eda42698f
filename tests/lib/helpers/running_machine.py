"""A machine started with ``halsdk run`` in a child process, on a private
instance, for the tests of the task channels and their clients.

:func:`running_machine` starts the installed ``halsdk`` command on a copy
of the example mill (``examples/mill``) whose HAL files are taken from the
example folder; with ``quick_home`` every joint homes where it stands (no
search, home position 0), so a test homes in a few cycles.  The block gets a
:class:`RunningMachine`: its instance name, the environment for child
processes (``HALSDK_INSTANCE``, and ``PYTHONPATH`` with the compat modules
``hal`` and ``linuxcnc``) and the host process.  At the end the host gets
SIGINT and is killed if it has not stopped within 20 s.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from halsdk.testing import private_instance_name
from helpers import repo_path

MILL = repo_path("examples", "mill")


def halsdk_command() -> list[str]:
    """The installed ``halsdk`` console script (beside this Python)."""
    exe = Path(sys.executable).with_name("halsdk")
    if exe.exists():
        return [str(exe)]
    found = shutil.which("halsdk")
    if found:
        return [found]
    return [sys.executable, "-m", "halsdk.machine.cli"]


@dataclass
class RunningMachine:
    instance: str
    ini: Path
    proc: subprocess.Popen
    env: dict = field(default_factory=dict)
    output: list = field(default_factory=list)

    _drain: Optional[threading.Thread] = None

    def start_draining(self) -> None:
        """Read the host's output from now on (the pipe never fills)."""
        def drain() -> None:
            assert self.proc.stdout is not None
            for line in self.proc.stdout:
                self.output.append(line)
        self._drain = threading.Thread(target=drain, daemon=True)
        self._drain.start()

    def stop(self, timeout: float = 20.0) -> str:
        """SIGINT, wait; the host's output."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        if self._drain is not None:
            self._drain.join(timeout=5)
        elif self.proc.stdout is not None:
            self.output.append(self.proc.stdout.read())
        if self.proc.returncode is not None and self.proc.returncode < 0:
            # a host killed by a signal leaves its instance: remove it
            halrun = Path(halsdk_command()[0]).with_name("halrun")
            cmd = [str(halrun)] if halrun.exists() else \
                [sys.executable, "-c", "from halsdk.halcmd.cli import "
                 "halrun_main; raise SystemExit(halrun_main())"]
            subprocess.run(cmd + ["-U"], env=self.env, capture_output=True,
                           timeout=30)
        return "".join(self.output)


def mill_ini(folder: Path, quick_home: bool = True,
             extra: str = "") -> Path:
    """A copy of the example mill's INI file in ``folder``, its HAL files
    and tool table taken from examples/mill; ``extra`` is appended."""
    text = (MILL / "mill.ini").read_text()
    text = re.sub(r"^HALFILE = (\S+)", lambda m: "HALFILE = " +
                  str(MILL / m.group(1)), text, flags=re.M)
    shutil.copy(MILL / "tool.tbl", folder / "tool.tbl")
    if quick_home:
        text = re.sub(r"^HOME_(SEARCH|LATCH)_VEL = .*$",
                      r"HOME_\1_VEL = 0", text, flags=re.M)
        text = re.sub(r"^HOME_USE_INDEX = .*$", "HOME_USE_INDEX = NO",
                      text, flags=re.M)
        # home where it stands: no move to a home position afterwards
        text = re.sub(r"^HOME_OFFSET = .*$", "HOME_OFFSET = 0", text,
                      flags=re.M)
    path = folder / "mill.ini"
    path.write_text(text + extra)
    return path


def client_env(instance: str) -> dict:
    """The environment of a client process: the instance, and the compat
    modules (``import linuxcnc``) on PYTHONPATH."""
    from halsdk.compat import pythonpath
    env = dict(os.environ, HALSDK_INSTANCE=instance)
    env["PYTHONPATH"] = os.pathsep.join(
        p for p in (pythonpath(), os.environ.get("PYTHONPATH")) if p)
    return env


@contextlib.contextmanager
def running_machine(folder: Path, *, ini: Optional[Path] = None,
                    quick_home: bool = True, stepped: bool = False,
                    extra: str = "", timeout: float = 60.0
                    ) -> Iterator[RunningMachine]:
    """``halsdk run`` of the mill (or ``ini``) until the block ends."""
    instance = private_instance_name()
    ini = ini or mill_ini(folder, quick_home, extra)
    env = client_env(instance)
    args = halsdk_command() + ["run", str(ini)]
    if stepped:
        args.append("--stepped")
    proc = subprocess.Popen(args, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True,
                            cwd=str(folder))
    machine = RunningMachine(instance, ini, proc, env)
    try:
        deadline = time.monotonic() + timeout
        assert proc.stdout is not None
        while True:
            line = proc.stdout.readline()
            machine.output.append(line)
            if "machine running" in line:
                machine.start_draining()
                break
            if not line or time.monotonic() > deadline:
                raise AssertionError("halsdk run did not start:\n" +
                                     machine.stop())
        yield machine
    finally:
        machine.stop()
