"""The machine that ``halsdk web machine.ini`` starts: ``halsdk run
machine.ini`` in a child process, which the workbench then attaches to.

Why a child rather than the launcher in the server's process: the task
controller and the web server do not share an interpreter lock (a busy
page never delays a task cycle), ``halsdk run``'s own start, signal
handling and shutdown (motion disabled, ``[HAL]SHUTDOWN``, the instance
removed) are used unchanged, and each side sees the other end:

- the child is in a session of its own, so Ctrl-C in the terminal reaches
  the server only, which ends its pages (and its connections to the
  instance) first and then stops the machine with SIGINT, as Ctrl-C stops
  ``halsdk run``;
- the child gets SIGTERM from the kernel when the server dies however it
  dies (``PR_SET_PDEATHSIG``), so a killed server never leaves a machine
  running;
- the server attaches with ``end_with_host``, so a machine that ends by
  itself (or is killed) ends the server.

The child's output (warnings, errors) goes to the server's stderr, its
``halsdk run:`` prefix replaced by the server's.
"""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
from typing import Any, Optional

from halsdk.hal import ends_with_this_process

#: seconds the machine may take to start
START_TIMEOUT = 120.0
#: seconds it may take to stop after SIGINT, before SIGKILL
STOP_TIMEOUT = 30.0
_RUN_PREFIX = "halsdk run: "
_STARTED = ("machine running", "HAL running")


class StartError(Exception):
    """The machine did not start (the message says why)."""


class MachineHost:
    """``halsdk run ini`` as a child process, on ``instance`` (default:
    ``$HALSDK_INSTANCE``, else the user's instance)."""

    def __init__(self, ini: str, instance: Optional[str] = None, *,
                 prog: str = "halsdk web") -> None:
        self.ini = ini
        self.instance = instance
        self.prog = prog
        self.proc: Optional[subprocess.Popen[str]] = None
        self._lines: queue.Queue[str] = queue.Queue()
        self._stopping = False
        self._forward = False
        self._reader: Optional[threading.Thread] = None
        self.said: list[str] = []

    def _say(self, line: str) -> str:
        line = line.rstrip("\n")
        if line.startswith(_RUN_PREFIX):
            line = line[len(_RUN_PREFIX):]
        return f"{self.prog}: {line}" if line else ""

    def _read(self) -> None:
        assert self.proc is not None and self.proc.stdout is not None
        for line in self.proc.stdout:
            if self._forward:
                text = self._say(line)
                if text:
                    print(text, file=sys.stderr, flush=True)
            else:
                self._lines.put(line)
        self._lines.put("")

    def start(self) -> None:
        """Start the machine and wait until it runs; StartError (with
        what ``halsdk run`` said) when it does not."""
        env = dict(os.environ)
        if self.instance is not None:
            env["HALSDK_INSTANCE"] = self.instance
        args = [sys.executable, "-m", "halsdk.machine.cli", "run", self.ini]
        old = _interruptible()
        try:
            try:
                self.proc = subprocess.Popen(
                    args, env=env, stdin=subprocess.DEVNULL,
                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                    text=True, start_new_session=True,
                    preexec_fn=ends_with_this_process())
            except OSError as exc:
                raise StartError(f"cannot start the machine: "
                                 f"{exc.strerror or exc}") from None
            self._reader = threading.Thread(target=self._read, daemon=True,
                                             name="halsdk-web-machine")
            self._reader.start()
            self._wait_started()
        except KeyboardInterrupt:
            self.stop()
            raise StartError("interrupted while the machine started "
                             "(it was stopped)") from None
        except StartError:
            self.stop()
            raise
        finally:
            for sig, handler in old.items():
                signal.signal(sig, handler)

    def _wait_started(self) -> None:
        while True:
            try:
                line = self._lines.get(timeout=START_TIMEOUT)
            except queue.Empty:
                raise StartError(f"{self.ini}: the machine did not start "
                                 f"within {START_TIMEOUT:g} s") from None
            if not line:                    # it ended
                assert self.proc is not None
                status = self.proc.wait()
                if self.said:
                    raise StartError("\n".join(self.said))
                raise StartError(f"{self.ini}: the machine did not start "
                                 f"(halsdk run ended with status {status})")
            text = self._say(line)
            if any(word in line for word in _STARTED):
                if text:
                    print(text, file=sys.stderr, flush=True)
                # from now on what it says goes straight to stderr
                while not self._lines.empty():
                    rest = self._say(self._lines.get())
                    if rest:
                        print(rest, file=sys.stderr, flush=True)
                self._forward = True
                return
            if text:
                # said before the start ended: a warning, or the error
                self.said.append(text[len(self.prog) + 2:])
                if "warning" in line:
                    print(text, file=sys.stderr, flush=True)
                    self.said.pop()

    @property
    def running(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    def stop(self) -> Optional[str]:
        """Stop the machine (SIGINT, as Ctrl-C stops ``halsdk run``; SIGKILL
        after STOP_TIMEOUT).  Returns None when it stopped as asked, else
        what happened to it (it had ended by itself, or it had to be
        killed).  Safe to call more than once."""
        proc = self.proc
        if proc is None or self._stopping:
            return None
        self._stopping = True
        ended = proc.poll()
        if ended is None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(timeout=STOP_TIMEOUT)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
                return (f"the machine did not stop within {STOP_TIMEOUT:g} "
                        "s and was killed")
            if self._reader is not None:
                self._reader.join(timeout=5)
            if proc.returncode != 0:
                return f"the machine stopped with status {proc.returncode}"
            return None
        if self._reader is not None:
            self._reader.join(timeout=5)
        if ended < 0:
            return (f"the machine ended by signal {-ended} "
                    f"({_signal_name(-ended)})")
        return f"the machine ended by itself (status {ended})"


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return "?"


def _interruptible() -> dict[int, Any]:
    """SIGINT and SIGTERM raise KeyboardInterrupt (while the machine
    starts); the old handlers."""
    if threading.current_thread() is not threading.main_thread():
        return {}

    def interrupt(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt
    return {sig: signal.signal(sig, interrupt)
            for sig in (signal.SIGINT, signal.SIGTERM)}
