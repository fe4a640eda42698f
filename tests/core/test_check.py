"""``Hal.check()``: it finds each kind of inconsistency, and it is
O(n log n) (issue 19: it was quadratic, 67 s at 125,000 pins, holding
the instance lock throughout).  Its time is measured by
``bench/check.py``; here a large instance must pass it and every broken
invariant, made on purpose with a test hook, must be reported and gone
again once repaired.
"""

from __future__ import annotations

import pytest

import halsdk
from halsdk.core import _core


@pytest.fixture
def wired(hal):
    """A small instance with a component, a linked signal, a thread."""
    comp = halsdk.component("wc")
    comp.newpin("out", "float", "out")
    comp.newpin("in", "float", "in")
    comp.newparam("par", "s32", "rw")
    comp.ready()
    hal.net("wsig", "wc.out", "wc.in")
    hal.loadrt("tand2")
    hal.newthread("wt", 1_000_000)
    hal.addf("tand2.0", "wt")
    hal.check()
    yield hal
    comp.exit()


def _broken(hal, kind: str, name: str, field: str, value, match: str):
    """Break one field, check that check() says so, repair it."""
    off = _core._test_offset(kind, name) if kind != "header" else 0
    if callable(value):
        value = value(off)
    old = _core._test_poke(off, field, value)
    try:
        bad, report = _core.check_consistency()
        assert bad >= 1
        assert match in report, report
        with pytest.raises(halsdk.InstanceError, match="inconsistent"):
            hal.check()
    finally:
        _core._test_poke(off, field, old)
    hal.check()


def test_signal_link_counts(wired):
    _broken(wired, "signal", "wsig", "sig.readers", 7,
            "signal 'wsig' link counts are wrong")


def test_pin_without_owner(wired):
    _broken(wired, "pin", "wc.in", "item.comp",
            _core._test_offset("signal", "wsig"), "pin 'wc.in' has no owner")


def test_pin_linked_to_a_deleted_signal(wired):
    _broken(wired, "pin", "wc.in", "pin.signal",
            _core._test_offset("component", "wc"),
            "pin 'wc.in' is linked to a deleted signal")


def test_function_users(wired):
    _broken(wired, "function", "tand2.0", "funct.users", 3,
            "function 'tand2.0' has 3 users, 1 counted")


def test_count(wired):
    count = wired.counts()["pin"]
    _broken(wired, "header", "", "count.pin", count + 1,
            f"pin count {count + 1} but {count} listed")


def test_list_links(wired):
    _broken(wired, "pin", "wc.in", "obj.prev", 8,
            "pin list broken at offset")


def test_name_index(wired):
    _broken(wired, "param", "wc.par", "obj.name0", ord("Q"),
            "param 'Qc.par' is not in the name index")


@pytest.mark.hal_size(64 * 1024 * 1024)
def test_large_instance_passes(hal):
    """20,000 pins, 5,000 signals with 2 pins each: consistent."""
    comp = halsdk.component("big")
    for k in range(20_000):
        comp.newpin(f"p{k}", "float", "out" if k % 2 == 0 else "in")
    comp.ready()
    for k in range(0, 10_000, 2):
        hal.net(f"bs{k}", f"big.p{k}", f"big.p{k + 1}")
    hal.check()
    assert _core.check_consistency() == (0, "")
    info = hal.info()["counts"]
    assert info["pin"] >= 20_000 and info["signal"] >= 5_000
    comp.exit()
