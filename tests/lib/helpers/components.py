"""Loading a component into a test's HAL, and the pins and params it
made."""

from __future__ import annotations

PERIOD = 1_000_000


def setup(hal, comp, *funct, args=()):
    """Load ``comp`` (load-line ``args``), make thread ``t`` of 1 ms and
    add the functions ``funct`` to it."""
    hal.loadrt(comp, *args)
    hal.newthread("t", PERIOD)
    for f in funct:
        hal.addf(f, "t")


def names(handles) -> list[str]:
    """The names of pin, param, ... handles."""
    return [h.name for h in handles]


def own_pins(hal, pattern: str) -> list[str]:
    """Pins of a component, without the timing pins of its functions."""
    return [n for n in names(hal.pins(pattern)) if not n.endswith(".time")]


def own_params(hal, pattern: str) -> list[str]:
    """Params of a component, without the timing params of its functions."""
    return [n for n in names(hal.params(pattern))
            if not n.endswith((".tmax", ".tmax-increased"))]
