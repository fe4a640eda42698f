"""Exponential back-off between attempts to reach a device."""

from __future__ import annotations

import math

#: the longest wait between two attempts, in seconds
MAX_DELAY = 3600.0


class Backoff:
    """When to try again after failures: the first retry waits ``first``
    seconds, each further failure doubles the wait up to ``maximum``, and
    a success starts again from ``first``.

    Times are in the caller's clock (``time.monotonic()`` or a fake one).
    """

    def __init__(self, first: float = 0.1, maximum: float = 5.0):
        if not (math.isfinite(first) and math.isfinite(maximum)
                and 0 < first <= maximum <= MAX_DELAY):
            raise ValueError("back-off needs 0 < first <= maximum <= "
                             f"{MAX_DELAY:g} s, not {first!r}, {maximum!r}")
        self.first = first
        self.maximum = maximum
        self.delay = first          # wait after the next failure
        self.next_attempt = 0.0     # clock time of the next attempt

    def ready(self, now: float) -> bool:
        """True when an attempt may be made at ``now``."""
        return now >= self.next_attempt

    def failed(self, now: float) -> float:
        """Record a failure at ``now``; returns the wait before the next
        attempt."""
        wait = self.delay
        self.next_attempt = now + wait
        self.delay = min(self.delay * 2, self.maximum)
        return wait

    def succeeded(self) -> None:
        """Record a success: the next failure waits ``first`` again."""
        self.delay = self.first
        self.next_attempt = 0.0
