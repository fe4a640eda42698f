"""threads: creates realtime threads at load time (``loadrt threads``).

``loadrt threads name1=servo period1=1000000 [fp1=1] [name2=... ...]``
creates up to three threads, fastest first.  The component has no pins,
params or functions of its own; the threads stay when it is unloaded, so
it can be loaded again to make more.

The defaults are LinuxCNC's: ``name1=thread1 period1=1000000`` (so a
bare ``loadrt threads`` makes ``thread1`` at 1 ms), ``fp1..3=1``, and
no second or third thread.  A thread is made when both its name and a
period greater than 0 are given; otherwise it is left out silently, as
the reference does (``loadrt threads period1=0`` makes no thread).
"""

from __future__ import annotations

from typing import Any

from halsdk import Component, Hal
from halsdk.errors import InvalidError

modparams: dict[str, tuple[type, Any, str]] = {}
for _n in (1, 2, 3):
    modparams[f"name{_n}"] = (str, "thread1" if _n == 1 else "",
                              f"name of thread {_n}")
    modparams[f"period{_n}"] = (int, 1000000 if _n == 1 else 0,
                                f"period of thread {_n} in ns")
    modparams[f"fp{_n}"] = (int, 1, f"thread {_n} runs floating-point code")

_comp: Component | None = None


def setup(**params: Any) -> None:
    global _comp
    wanted: list[tuple[str, int, bool]] = []
    for n in (1, 2, 3):
        name = params.get(f"name{n}", modparams[f"name{n}"][1])
        period = params.get(f"period{n}", modparams[f"period{n}"][1])
        if not name or period <= 0:
            continue            # not asked for (the reference's rule)
        if wanted and period < wanted[-1][1]:
            raise InvalidError(
                f"threads: thread '{name}' ({period} ns) is faster than "
                f"'{wanted[-1][0]}' ({wanted[-1][1]} ns); create threads "
                "from fastest to slowest")
        wanted.append((name, period, bool(params.get(f"fp{n}", 1))))
    hal = Hal.current()
    if hal is None:
        raise InvalidError("threads: no HAL instance in this process")
    comp = hal.new_component("threads", realtime=True)
    made = []
    try:
        for name, period, fp in wanted:
            hal.newthread(name, period, fp, 16)
            made.append(name)
    except Exception:
        for name in made:       # nothing half-made
            hal.delthread(name)
        comp.exit()
        raise
    comp.ready()
    _comp = comp


def cleanup() -> None:
    """Remove the component; its threads stay."""
    global _comp
    if _comp is not None:
        _comp.exit()
    _comp = None
