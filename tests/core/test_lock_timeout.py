"""A process stopped while it holds the instance lock blocks nobody for
ever (issue 19).

A holder is an attached Python process that takes the lock with the test
hook ``_core.hold_lock_for_test`` and is then stopped with SIGSTOP.  Every
other process waits at most the lock timeout (``HALSDK_LOCK_TIMEOUT``,
small here) and fails with "instance lock held by pid N (stopped)":
``halcmd show pin`` and ``halcmd setp`` (the installed program, one line,
exit status 1, no traceback), a Python listing in another process and in
the host, ``Hal.check()``.  The realtime threads never take the lock and
keep running meanwhile.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers.polling import wait_for

import halsdk
from halsdk.core import _core

TIMEOUT = 0.5           # the lock timeout the tests set
BOUND = 10.0            # generous: "it does not hang"

HOLD = """\
import sys
import halsdk
from halsdk.core import _core
hal = halsdk.Hal(create=False)
print("holding", flush=True)
_core.hold_lock_for_test(120)
"""


def _program(name: str) -> list[str]:
    """The installed console script, else the module."""
    path = os.path.join(os.path.dirname(sys.executable), name)
    if os.path.exists(path):
        return [path]
    return [sys.executable, "-m", "halsdk.halcmd.cli", name]


def _state(pid: int) -> str:
    with open(f"/proc/{pid}/stat") as f:
        return f.read().rsplit(")", 1)[1].split()[0]


@contextlib.contextmanager
def holding_and_stopped(hal, cwd: Path) -> Iterator[int]:
    """An attached process stopped while it holds the lock: its pid.
    Killed at the end; then the lock is taken again (the robust mutex
    recovers from the dead holder)."""
    proc = subprocess.Popen([sys.executable, "-c", HOLD], cwd=cwd,
                            stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline().strip() == "holding"
        assert wait_for(lambda: _core.lock_holder() == proc.pid, BOUND), \
            "the child did not take the instance lock"
        os.kill(proc.pid, signal.SIGSTOP)
        assert wait_for(lambda: _state(proc.pid) in ("T", "t"), BOUND), \
            "the child did not stop"
        yield proc.pid
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        os.kill(proc.pid, signal.SIGCONT)
        proc.wait(BOUND)
        if proc.stdout is not None:
            proc.stdout.close()
    hal.lock_timeout = 5.0
    hal.newsig(f"after-holder-{proc.pid}", "bit")
    hal.check()


@pytest.fixture
def stopped_holder(hal, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                   ) -> Iterator[int]:
    monkeypatch.setenv("HALSDK_LOCK_TIMEOUT", str(TIMEOUT))
    with holding_and_stopped(hal, tmp_path) as pid:
        yield pid


def _timed(args: list[str], cwd: Path) -> tuple[subprocess.CompletedProcess,
                                                float]:
    start = time.monotonic()
    done = subprocess.run(args, cwd=cwd, env=dict(os.environ),
                          capture_output=True, text=True, timeout=60)
    return done, time.monotonic() - start


@pytest.fixture
def lt_comp(hal) -> Iterator[halsdk.Component]:
    comp = halsdk.component("lt")
    comp.newpin("in", "float", "in")
    comp.ready()
    yield comp
    comp.exit()


@pytest.mark.parametrize("words", [["show", "pin"], ["setp", "lt.in", "1"],
                                   ["list", "sig"]])
def test_halcmd_fails_with_the_holder_named(hal, lt_comp, stopped_holder,
                                            tmp_path, words):
    done, took = _timed(_program("halcmd") + words, tmp_path)
    assert took < BOUND
    assert "Traceback" not in done.stderr + done.stdout, done.stderr
    assert done.returncode != 0
    assert f"instance lock held by pid {stopped_holder} (stopped)" \
        in done.stderr
    assert f"HAL instance '{hal.instance}'" in done.stderr
    assert "Traceback" not in done.stderr + done.stdout


def test_python_listing_in_another_process_raises(hal, stopped_holder,
                                                  tmp_path):
    script = (
        "import halsdk\n"
        "hal = halsdk.Hal(create=False)\n"
        "for call in (hal.pins, lambda: hal.snapshot('signal'),\n"
        "             lambda: hal.newsig('x', 'bit')):\n"
        "    try:\n"
        "        call()\n"
        "    except halsdk.LockTimeoutError as exc:\n"
        "        assert isinstance(exc, halsdk.InstanceError)\n"
        "        print('timeout:', exc)\n"
    )
    done, took = _timed([sys.executable, "-c", script], tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 3
    assert all(f"lock held by pid {stopped_holder} (stopped)" in line
               for line in lines)
    assert took < 3 * BOUND


def test_host_waits_at_most_the_timeout(hal, stopped_holder):
    hal.lock_timeout = TIMEOUT
    for call in (hal.pins, lambda: hal.snapshot("pin"), hal.check,
                 lambda: hal.newsig("late", "float")):
        start = time.monotonic()
        with pytest.raises(halsdk.LockTimeoutError,
                           match=rf"lock held by pid {stopped_holder} "
                                 r"\(stopped\)") as info:
            call()
        assert time.monotonic() - start < BOUND
        assert isinstance(info.value, TimeoutError)
        assert hal.instance in str(info.value)


def test_realtime_threads_run_while_the_lock_is_held(hal, tmp_path,
                                                     monkeypatch):
    monkeypatch.setenv("HALSDK_LOCK_TIMEOUT", str(TIMEOUT))
    hal.newthread("rt-run", 1_000_000)
    thread = hal.thread("rt-run")
    hal.start(False)
    with holding_and_stopped(hal, tmp_path):
        cycles = thread.cycles
        assert wait_for(lambda: thread.cycles > cycles + 20, BOUND), \
            "the thread stopped while a stopped process holds the lock"


def test_lock_timeout_setting(hal, monkeypatch, tmp_path):
    assert hal.lock_timeout > 0
    hal.lock_timeout = 2.5
    assert hal.lock_timeout == 2.5
    with pytest.raises(halsdk.InvalidError, match="lock timeout"):
        hal.lock_timeout = 0
    with pytest.raises(halsdk.InvalidError, match="lock timeout"):
        hal.lock_timeout = float("nan")
    hal.lock_timeout = 5.0
    # a bad $HALSDK_LOCK_TIMEOUT is an error that names it, in halcmd too
    monkeypatch.setenv("HALSDK_LOCK_TIMEOUT", "soon")
    done, _ = _timed(_program("halcmd") + ["show", "pin"], tmp_path)
    assert done.returncode != 0
    assert "HALSDK_LOCK_TIMEOUT='soon'" in done.stderr
    assert "Traceback" not in done.stderr
    monkeypatch.setenv("HALSDK_LOCK_TIMEOUT", "0.75")
    done, _ = _timed([sys.executable, "-c", "import halsdk; "
                      "print(halsdk.Hal(create=False).lock_timeout)"],
                     tmp_path)
    assert done.stdout.strip() == "0.75", done.stderr


def test_the_holder_is_recorded_and_cleared(hal):
    # the host's own watch of userspace components takes the lock now and
    # then: one of a few looks finds it free
    for _ in range(100):
        if _core.lock_holder() == 0 and hal.info()["lock_holder"] == 0:
            break
        time.sleep(0.01)
    else:
        pytest.fail(f"the lock stays held by pid {_core.lock_holder()}")
    assert hal.info()["abi"] >= 4
