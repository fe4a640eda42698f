"""Waiting for what another thread or process does."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any


def wait_for(cond: Callable[[], Any], timeout: float = 10.0,
             interval: float = 0.01) -> bool:
    """Poll ``cond()`` every ``interval`` s until it is true or ``timeout``
    s have passed; whether it was true at last (asked once more at the
    end, so a slow last poll still counts)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return True
        time.sleep(interval)
    return bool(cond())
