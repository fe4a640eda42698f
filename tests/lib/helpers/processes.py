"""Child processes of a test (drivers started with Popen)."""

from __future__ import annotations

import contextlib
import signal
import subprocess
from collections.abc import Iterator


@contextlib.contextmanager
def ended_at_exit(proc: subprocess.Popen) -> Iterator[subprocess.Popen]:
    """Kill ``proc`` when the block ends with it still running (a failed
    assertion must not leave a driver process behind)."""
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def sigterm(proc: subprocess.Popen, timeout: float = 10) -> tuple:
    """Send SIGTERM and wait for the end: (stdout, stderr)."""
    proc.send_signal(signal.SIGTERM)
    return proc.communicate(timeout=timeout)
