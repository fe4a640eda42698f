"""Loading a shipped component into a test's HAL."""

from __future__ import annotations

PERIOD = 1_000_000


def setup(hal, comp, *funct, args=()):
    """Load ``comp`` (load-line ``args``), make thread ``t`` of 1 ms and
    add the functions ``funct`` to it."""
    hal.loadrt(comp, *args)
    hal.newthread("t", PERIOD)
    for f in funct:
        hal.addf(f, "t")
