"""threads: creates realtime threads at load time (``loadrt threads``).

``loadrt threads name1=servo period1=1000000 [fp1=1] [name2=... ...]``
creates up to three threads, fastest first.  The component has no pins,
params or functions of its own; the threads stay when it is unloaded, so
it can be loaded again to make more.
"""

from __future__ import annotations

from halsdk.core import _core
from halsdk.errors import InvalidError

modparams = {}
for _n in (1, 2, 3):
    modparams[f"name{_n}"] = (str, "", f"name of thread {_n}")
    modparams[f"period{_n}"] = (int, 0, f"period of thread {_n} in ns")
    modparams[f"fp{_n}"] = (int, 1, f"thread {_n} runs floating-point code")

_comp_id = -1


def setup(**params: object) -> None:
    global _comp_id
    wanted = []
    for n in (1, 2, 3):
        name = params.get(f"name{n}", "")
        period = params.get(f"period{n}", 0)
        if not name:
            if period:
                raise InvalidError(f"threads: period{n} given without name{n}")
            continue
        if period <= 0:
            raise InvalidError(f"threads: thread '{name}' needs period{n}")
        if wanted and period < wanted[-1][1]:
            raise InvalidError(
                f"threads: thread '{name}' ({period} ns) is faster than "
                f"'{wanted[-1][0]}' ({wanted[-1][1]} ns); create threads "
                "from fastest to slowest")
        wanted.append((name, period, bool(params.get(f"fp{n}", 1))))
    if not wanted:
        raise InvalidError("threads: no thread given (name1=... period1=...)")
    _comp_id = _core.comp_new("threads", _core.COMP_RT)
    made = []
    try:
        for name, period, fp in wanted:
            _core.thread_new(name, period, fp, 16)
            made.append(name)
    except Exception:
        for name in made:       # nothing half-made
            _core.thread_delete(name)
        raise
    _core.comp_ready(_comp_id)


def cleanup() -> None:
    """Remove the component; its threads stay."""
    global _comp_id
    if _comp_id >= 0 and _core.comp_by_id(_comp_id) is not None:
        _core.comp_exit(_comp_id)
    _comp_id = -1
