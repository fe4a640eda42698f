"""What the benchmark scripts share: where LinuxCNC's reference is and
whether to run it, the lock that keeps to one reference HAL on the
machine, the options the scripts have in common, and the temp folders,
child sessions and timed commands of their runs.

A script imports it as ``benchlib``: bench/ is the first entry of
``sys.path`` when a script runs as ``python bench/NAME.py``, and the
scripts that others import put it there themselves.
"""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import IO, Optional

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
#: the reference's programs, when LinuxCNC 2.9 is installed
REFERENCE_HALRUN = "/usr/bin/halrun"
REFERENCE_HALCOMPILE = "/usr/bin/halcompile"
REFERENCE_MB2HAL = "/usr/bin/mb2hal"
#: the project's tool that runs them (as another user, on a copy of the
#: current folder)
REFERENCE_TOOL = os.environ.get(
    "HALSDK_REFERENCE_TOOL",
    os.path.join(os.path.dirname(REPO), "shared", "tools", "reference"))
#: one reference HAL at a time on a machine: the lock the tests (and
#: tests/data/complib's golden.py) take too
LOCK = "/tmp/halsdk-reference.lock"


# ------------------------------------------------------------ options

def _at_least_one(text: str) -> int:
    n = int(text)
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text}: must be at least 1")
    return n


def add_repeat(p: argparse.ArgumentParser, default: int, what: str) -> None:
    """``--repeat R`` (a whole number from 1): ``what`` it does."""
    p.add_argument("--repeat", type=_at_least_one, default=default,
                   help=f"{what} (default {default})")


def add_thread_runs(p: argparse.ArgumentParser, threads: str) -> None:
    """``--seconds``, ``--warmup``, ``--repeat`` and ``--sched`` of a
    bench that runs HAL threads, ours and the reference's, alternating;
    ``threads`` names ours in the help ("our thread", "our threads")."""
    p.add_argument("--seconds", type=float, default=5.0,
                   help="length of each measurement (default 5)")
    p.add_argument("--warmup", type=float, default=1.0,
                   help="run time before the measurement (default 1)")
    add_repeat(p, 3, "runs per side, alternating; the table shows the "
                     "median")
    p.add_argument("--sched", choices=("both", "realtime", "normal"),
                   default="both",
                   help=f"{threads} with realtime scheduling (SCHED_FIFO, "
                        "when we may), normal scheduling, or both "
                        "(default both)")


def add_no_reference(p: argparse.ArgumentParser) -> None:
    """``--no-reference``: see :func:`use_reference`."""
    p.add_argument("--no-reference", action="store_true",
                   help="do not run the LinuxCNC reference")


def add_keep(p: argparse.ArgumentParser) -> None:
    """``--keep FILE``, for the scripts that generate their input."""
    p.add_argument("--keep", metavar="FILE",
                   help="also write the generated file to FILE")


def use_reference(wanted: bool, program: str) -> bool:
    """Whether to run the reference: ``wanted`` (no --no-reference), its
    ``program`` installed, and the reference tool there (when it is not,
    that is said on stderr)."""
    if not wanted or not os.path.exists(program):
        return False
    if not os.access(REFERENCE_TOOL, os.X_OK):
        print(f"reference tool {REFERENCE_TOOL} not found; skipping the "
              "reference", file=sys.stderr)
        return False
    return True


# ------------------------------------------------------------ runs

@contextlib.contextmanager
def reference_lock() -> Iterator[None]:
    """Hold :data:`LOCK` while the block runs (waiting for it first)."""
    with open(LOCK, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


@contextlib.contextmanager
def run_folder(prefix: str, files: Mapping[str, str]) -> Iterator[str]:
    """A new temp folder holding ``files`` (name: text), readable by all
    (the reference tool copies it as another user); removed when the
    block ends."""
    folder = tempfile.mkdtemp(prefix=prefix)
    try:
        os.chmod(folder, 0o755)
        for name, text in files.items():
            path = os.path.join(folder, name)
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
            os.chmod(path, 0o644)
        yield folder
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def session(cmd: Sequence[str], **popen: object) -> Iterator[subprocess.Popen]:
    """``cmd`` started in a session of its own (stdin /dev/null); when
    the block ends with it still running, its whole process group
    (halrun and what it started) gets SIGTERM and is waited for."""
    proc = subprocess.Popen(list(cmd), stdin=subprocess.DEVNULL,
                            start_new_session=True, **popen)
    try:
        yield proc
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait(timeout=10)


def sleeping_child(pid: int, hold: str) -> bool:
    """Our halrun has started its threads once it runs ``sleep hold``."""
    r = subprocess.run(["pgrep", "-P", str(pid), "-f", f"^sleep {hold}$"],
                       capture_output=True, text=True)
    return bool(r.stdout.strip())


def wait_host(proc: subprocess.Popen, log: IO[str], hold: str,
              reference_host: Optional[Callable[[str], Optional[int]]],
              what: str, timeout: float = 120) -> int:
    """The pid of the process that runs the HAL threads of ``proc``, once
    they run: the reference's rtapi_app (``reference_host(hold)`` finds
    it) or our halrun (which then runs ``sleep hold``). RuntimeError with
    the end of ``log`` if ``proc`` ends first or ``timeout`` passes."""
    deadline = time.monotonic() + timeout
    while True:
        if reference_host is not None:
            host = reference_host(hold)
        else:
            host = proc.pid if sleeping_child(proc.pid, hold) else None
        if host:
            return host
        if proc.poll() is not None or time.monotonic() > deadline:
            log.seek(0)
            raise RuntimeError(f"{what}: run failed:\n" + log.read()[-3000:])
        time.sleep(0.02)


class RunError(RuntimeError):
    """A timed command failed; the message ends with its output."""


def timed(cmd: Sequence[str], cwd: str,
          env: Optional[Mapping[str, str]] = None) -> tuple[float, str]:
    """Run ``cmd`` in ``cwd``: (wall time in s, its stdout); RunError
    when it fails."""
    t0 = time.perf_counter()
    proc = subprocess.run(list(cmd), cwd=cwd, env=env,
                          stdin=subprocess.DEVNULL, capture_output=True,
                          text=True, timeout=600)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RunError(f"{' '.join(cmd)} exited with {proc.returncode} in "
                       f"{cwd}:\n" + (proc.stdout + proc.stderr)[-2000:])
    return wall, proc.stdout
