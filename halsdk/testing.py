"""pytest plugin: a private HAL instance per test, stepped deterministically.

Installed with halsdk (entry point ``pytest11``), so any project can use::

    import numpy as np
    import pytest

    def test_scale_doubles(hal):
        hal.loadrt("scale")                 # a component shipped with halsdk
        hal.newthread("servo", 1_000_000)
        hal.addf("scale.0", "servo")
        hal.setp("scale.0.gain", 2.0)
        trace = hal.run(100, inputs={"scale.0.in": np.linspace(0, 1, 100)},
                        record=["scale.0.out"])
        assert trace["scale.0.out"][-1] == pytest.approx(2.0)

The ``hal`` fixture creates an instance of its own (``HALSDK_INSTANCE`` is
set for the test, so child processes and :func:`halsdk.component` find it),
and removes it afterwards.  At the end of the session the plugin fails the
run if an instance it created is still in ``/dev/shm``.

SIGTERM (and SIGHUP) stop the whole run as Ctrl-C does: the running test
is interrupted, no further test starts, the fixtures are torn down (so
every instance is removed) and pytest exits with 128 + the signal number.
"""

from __future__ import annotations

import itertools
import os
import signal
import threading
from collections.abc import Iterable, Mapping, Sequence
from types import FrameType
from typing import Any, Callable, Optional, Union

import numpy as np
import pytest

import halsdk
from halsdk.types import HalType

_counter = itertools.count()
_created: list[str] = []
TEST_INSTANCE_SIZE = 32 * 1024 * 1024


class Trace(dict):
    """Recorded values: ``trace[name]`` is a NumPy array with one value per
    cycle; ``trace.time`` holds the simulated time (ns) of each sample."""

    time: np.ndarray


_DTYPES = {HalType.BIT: np.bool_, HalType.FLOAT: np.float64, HalType.S32: np.int32,
           HalType.U32: np.uint32, HalType.S64: np.int64, HalType.U64: np.uint64}


class TestHal(halsdk.Hal):
    """:class:`halsdk.Hal` with helpers for stepping tests."""

    __test__ = False        # not a test class for pytest

    def set(self, values: Mapping[str, Any]) -> None:
        """Set inputs: unlinked in-pins and params (setp), or signals
        without a writer (sets)."""
        for name, value in values.items():
            item = self._lookup(name)
            if isinstance(item, halsdk.Signal):
                item.sets(value)
            else:
                item.setp(value)

    def _lookup(self, name: str):
        """The pin or param of that name, else the signal."""
        item = (self.find("pin", name) or self.find("param", name)
                or self.find("signal", name))
        if item is None:
            raise halsdk.NotFoundError(f"no pin, param or signal '{name}'")
        return item

    def run(self, cycles: int, inputs: Optional[Mapping[str, Any]] = None,
            record: Iterable[str] = (), thread: Optional[str] = None
            ) -> Trace:
        """Step ``cycles`` times, one cycle of the fastest thread (or of
        ``thread``) each; before each cycle apply ``inputs`` (a scalar, or
        a sequence giving one value per cycle), after each cycle sample
        the ``record`` names (pins, signals or params)."""
        inputs = dict(inputs or {})
        sources = [(n, self._lookup(n)) for n in record]
        plan = []
        for name, value in inputs.items():
            target = self._lookup(name)
            if isinstance(value, (str, bytes)) or not isinstance(
                    value, (Sequence, np.ndarray)):
                self.set({name: value})
                continue
            if len(value) != cycles:
                raise halsdk.InvalidError(
                    f"input '{name}' has {len(value)} values for {cycles} "
                    "cycles")
            setter = target.sets if isinstance(target, halsdk.Signal) \
                else target.setp
            plan.append((setter, value))
        out: dict[str, np.ndarray] = {
            n: np.empty(cycles, dtype=_DTYPES[src.type])
            for n, src in sources}
        times = np.empty(cycles, dtype=np.int64)
        for k in range(cycles):
            for setter, value in plan:
                v = value[k]
                setter(v.item() if isinstance(v, np.generic) else v)
            self.step(1, thread)
            times[k] = self.time
            for n, src in sources:
                out[n][k] = src.value
        trace = Trace(out)
        trace.time = times
        return trace


def private_instance_name() -> str:
    return f"pytest-{os.getpid()}-{next(_counter)}"


_Handler = Union[Callable[[int, Optional[FrameType]], Any], int, None]
_STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)
_previous_handlers: dict[int, _Handler] = {}
_stopping = False


def _stop_run(signum: int, frame: Optional[FrameType]) -> None:
    """Stop the session cleanly: pytest's Exit is not a test failure, ends
    the run, and still tears the fixtures down.  A second signal while
    that teardown runs is ignored, so it cannot cut the teardown short."""
    global _stopping
    if _stopping:
        return
    _stopping = True
    name = signal.Signals(signum).name
    pytest.exit(f"halsdk: stopped by {name}; removing the test instances",
                returncode=128 + signum)


def _install_stop_handlers() -> None:
    """Only where nobody else handles the signal: a project's own handler
    (or pytest-timeout's) is left alone."""
    if threading.current_thread() is not threading.main_thread():
        return
    for signum in _STOP_SIGNALS:
        if signal.getsignal(signum) is signal.SIG_DFL:
            _previous_handlers[signum] = signal.signal(signum, _stop_run)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "hal_size(nbytes): size of the test's private HAL "
        "instance (the hal fixture), when the default is too small")
    _install_stop_handlers()


def pytest_unconfigure(config: pytest.Config) -> None:
    global _stopping
    while _previous_handlers:
        signum, handler = _previous_handlers.popitem()
        if signal.getsignal(signum) is _stop_run:
            signal.signal(signum, handler)
    _stopping = False


@pytest.fixture
def hal(monkeypatch: pytest.MonkeyPatch, request: pytest.FixtureRequest):
    """A private HAL instance hosted by the test process (its size:
    ``@pytest.mark.hal_size(nbytes)``, default TEST_INSTANCE_SIZE)."""
    name = private_instance_name()
    monkeypatch.setenv("HALSDK_INSTANCE", name)
    marker = request.node.get_closest_marker("hal_size")
    size = marker.args[0] if marker else TEST_INSTANCE_SIZE
    h = TestHal(name, create=True, size=size)
    _created.append(halsdk.core.instance.shm_name(name))
    try:
        yield h
    finally:
        try:
            h.stop()
        except halsdk.HalError:
            pass
        conn = halsdk.core.instance.current()
        h.close()
        # components the test left open must not keep the instance alive
        if conn is not None and halsdk.core.instance.current() is conn:
            halsdk.core.instance._teardown(conn)


def leftover_instances(shm_names: Iterable[str]) -> list[str]:
    return [n for n in shm_names
            if os.path.exists("/dev/shm/" + n.lstrip("/"))]


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """After pytest's own teardown of the fixtures (trylast), so that a
    run stopped half-way is checked once its instances are gone."""
    left = leftover_instances(_created)
    if left:
        print(f"\nhalsdk: HAL instances left in /dev/shm: {', '.join(left)}")
        if not session.exitstatus:
            session.exitstatus = 1
