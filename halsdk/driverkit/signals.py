"""SIGTERM and SIGINT as a flag that a driver's loop polls.

A Python signal handler runs in the main thread between two bytecodes,
possibly while that thread is inside ``threading.Event.wait()`` holding
the event's lock: a handler that calls ``Event.set()`` then waits for that
lock for ever (the driver never ends, its device never goes to its safe
state).  Two SIGTERMs close together (the kernel's when the host dies and
the core's host watch) made it happen.  So the handler only stores the
signal number, and the loop looks at :attr:`StopSignals.caught` between
its waits.
"""

from __future__ import annotations

import signal
import threading
from types import FrameType, TracebackType
from typing import Any, Optional


class StopSignals:
    """``with StopSignals() as stop:`` then ``while not stop.caught``.

    Handles SIGTERM and SIGINT while the block runs (on the main thread
    only; elsewhere it does nothing) and restores the handlers after it.
    """

    SIGNALS = (signal.SIGTERM, signal.SIGINT)

    def __init__(self, enabled: bool = True) -> None:
        self.enabled = enabled
        self.caught = 0             #: the signal number, 0 until one came
        self._old: dict[int, Any] = {}

    def _handler(self, signum: int, frame: Optional[FrameType]) -> None:
        self.caught = signum        # nothing that takes a lock

    def __enter__(self) -> StopSignals:
        if self.enabled and \
                threading.current_thread() is threading.main_thread():
            for sig in self.SIGNALS:
                self._old[sig] = signal.signal(sig, self._handler)
        return self

    def __exit__(self, kind: Optional[type[BaseException]],
                 exc: Optional[BaseException],
                 tb: Optional[TracebackType]) -> None:
        while self._old:
            sig, handler = self._old.popitem()
            signal.signal(sig, handler)
