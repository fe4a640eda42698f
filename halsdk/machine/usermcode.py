"""User M-codes M100-M199: programs on a search path, run by the machine.

A program block ``M101 P1.5 Q2`` runs the executable file named ``M101``
(a capital M, no extension) found first in the folders of the M-code
search path: ``[DISPLAY]PROGRAM_PREFIX`` (``nc_files`` when it is not
set), then the colon-separated ``[RS274NGC]USER_M_PATH``, each relative
to the INI file's folder. Its two arguments are the P and Q numbers
formatted with ``%f`` (``-1.000000`` for a missing word), as LinuxCNC's
task passes them.  The machine waits, with the motion at rest, until it
exits; a non-zero exit status, a signal or running longer than the
timeout (``[RS274NGC]HALSDK_USER_M_TIMEOUT``, default 60 s) aborts the
program with an error naming the M-code.  Nothing here blocks: the task
loop polls the process.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from typing import Callable, Optional

from halsdk.hal import ends_with_this_process

__all__ = ["DEFAULT_TIMEOUT", "UserMError", "UserMRun", "find_user_m",
           "search_path"]

#: seconds a user M-code may run before the machine kills it
DEFAULT_TIMEOUT = 60.0


class UserMError(Exception):
    """A user M-code that failed: its text names the M-code and why."""


def search_path(folder: str, program_prefix: Optional[str],
                user_m_path: Optional[str]) -> list[str]:
    """The folders searched for M100-M199, first to last: the program
    prefix (``nc_files`` when None), then each entry of USER_M_PATH;
    relative ones are taken from ``folder`` (the INI file's)."""
    entries = [program_prefix.strip() if program_prefix and
               program_prefix.strip() else "nc_files"]
    entries += [p.strip() for p in (user_m_path or "").split(":")
                if p.strip()]
    return [os.path.join(folder, os.path.expanduser(p)) for p in entries]


def find_user_m(number: int, folders: list[str]) -> Optional[str]:
    """The first executable regular file ``M<number>`` in ``folders``,
    or None (also for a number outside 100..199)."""
    if not 100 <= number <= 199:
        return None
    for folder in folders:
        path = os.path.join(folder, f"M{number}")
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    return None


class UserMRun:
    """One running user M-code: started at once, then polled.

    ``clock`` (default :func:`time.monotonic`) is replaced in tests.
    """

    def __init__(self, code: int, path: str, p: float, q: float,
                 timeout: float = DEFAULT_TIMEOUT,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.code = code
        self.path = path
        self.timeout = timeout
        self.clock = clock
        #: the command line, as the reference's task forms it
        self.argv = [path, f"{p:f}", f"{q:f}"]
        try:
            self.process = subprocess.Popen(
                self.argv, stdin=subprocess.DEVNULL,
                cwd=os.path.dirname(path) or None,
                start_new_session=True,     # its own group, killed whole
                # and SIGTERM when the machine's task thread ends, however
                # it ends: a dead machine leaves no M-code running
                preexec_fn=ends_with_this_process())
        except OSError as e:
            raise UserMError(f"M{code}: cannot run {path}: "
                             f"{e.strerror or e}") from None
        self.deadline = clock() + timeout

    def poll(self) -> bool:
        """True once it exited with status 0; False while it runs;
        raises :class:`UserMError` for a failure or past the timeout
        (the process group is then killed)."""
        rc = self.process.poll()
        if rc is None:
            if self.clock() < self.deadline:
                return False
            self.kill()
            raise UserMError(
                f"M{self.code}: {self.path} still running after "
                f"{self.timeout:g} s, killed (raise the limit with "
                "[RS274NGC]HALSDK_USER_M_TIMEOUT)")
        if rc == 0:
            return True
        if rc < 0:
            raise UserMError(f"M{self.code}: {self.path} was killed by "
                             f"signal {-rc}")
        raise UserMError(f"M{self.code}: {self.path} exited with status "
                         f"{rc}")

    def kill(self) -> None:
        """Kill the process and its children (abort, timeout) and reap
        it."""
        if self.process.poll() is not None:
            return
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except OSError:
            self.process.kill()
        try:
            self.process.wait(timeout=5)
        except subprocess.TimeoutExpired:      # pragma: no cover
            pass
