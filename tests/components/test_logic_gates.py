"""The shipped logic gates and2, or2, xor2 and not: load lines, pins,
functions and behaviour, checked against facts recorded from the LinuxCNC
2.9 reference (``halrun`` with ``show pin``/``show funct``/``show param``)."""

from __future__ import annotations

import importlib
import itertools
import time

import numpy as np
import pytest

import halsdk
from halsdk.components._instances import instance_names, split_names
from halsdk.core import _core

GATES = {
    "and2": lambda a, b: a and b,
    "or2": lambda a, b: a or b,
    "xor2": lambda a, b: a != b,
}
INPUTS = {"and2": ("in0", "in1"), "or2": ("in0", "in1"),
          "xor2": ("in0", "in1"), "not": ("in",)}
ALL = sorted(INPUTS)


def pin_table(hal, pattern="*"):
    return [(p.name, p.type, p.direction) for p in hal.pins(pattern)]


@pytest.mark.parametrize("comp", ALL)
def test_default_load_matches_reference(hal, comp):
    """``loadrt X`` makes one instance X.0 with the reference's pins,
    params and a non-floating-point function X.0."""
    assert hal.loadrt(comp) == [comp]
    want = [(f"{comp}.0.{pin}", _core.BIT, _core.IN) for pin in INPUTS[comp]]
    want += [(f"{comp}.0.out", _core.BIT, _core.OUT),
             (f"{comp}.0.time", _core.S32, _core.OUT)]
    assert pin_table(hal) == sorted(want)
    assert [(p.name, p.type, p.direction) for p in hal.params()] == [
        (f"{comp}.0.tmax", _core.S32, _core.RW),
        (f"{comp}.0.tmax-increased", _core.BIT, _core.RO)]
    [funct] = hal.functions()
    assert funct.name == f"{comp}.0"
    assert funct.uses_fp is False          # reference `show funct`: FP NO
    assert funct.owner == comp
    assert all(p.value is False for p in hal.pins("*.out"))


@pytest.mark.parametrize("comp", sorted(GATES))
def test_two_input_truth_tables(hal, comp):
    hal.loadrt(comp, count=4)
    hal.newthread("servo", 1_000_000, fp=False)
    for k in range(4):
        hal.addf(f"{comp}.{k}", "servo")
    cases = list(itertools.product((False, True), repeat=2))
    for k, (a, b) in enumerate(cases):
        hal.set({f"{comp}.{k}.in0": a, f"{comp}.{k}.in1": b})
    hal.step(1)
    got = [hal.getp(f"{comp}.{k}.out") for k in range(4)]
    assert got == [GATES[comp](a, b) for a, b in cases]
    # and the outputs follow changing inputs cycle by cycle
    a = np.array([0, 1, 1, 0, 1, 0, 0, 1], dtype=bool)
    b = np.array([0, 0, 1, 1, 1, 1, 0, 0], dtype=bool)
    trace = hal.run(len(a), inputs={f"{comp}.0.in0": a, f"{comp}.0.in1": b},
                    record=[f"{comp}.0.out"])
    want = [GATES[comp](bool(x), bool(y)) for x, y in zip(a, b)]
    assert trace[f"{comp}.0.out"].tolist() == want


def test_not_inverts(hal):
    hal.loadrt("not", count=2)
    hal.newthread("servo", 1_000_000, fp=False)
    hal.addf("not.0", "servo")
    hal.addf("not.1", "servo")
    assert hal.getp("not.0.out") is False      # before its first run
    hal.setp("not.1.in", True)
    hal.step(1)
    assert hal.getp("not.0.out") is True
    assert hal.getp("not.1.out") is False
    trace = hal.run(4, inputs={"not.0.in": [1, 0, 1, 1]},
                    record=["not.0.out"])
    assert trace["not.0.out"].tolist() == [False, True, False, False]


def test_not_module_is_importable_by_name():
    module = importlib.import_module("halsdk.components.not")
    assert callable(module.setup) and set(module.modparams) == {
        "count", "names"}


def test_gates_chain_through_signals(hal):
    """(a AND b) XOR (NOT c), wired with nets as a HAL file would."""
    hal.loadrt("and2")
    hal.loadrt("xor2")
    hal.loadrt("not")
    hal.newthread("servo", 1_000_000, fp=False)
    for f in ("and2.0", "not.0", "xor2.0"):
        hal.addf(f, "servo")
    hal.net("ab", "and2.0.out", "xor2.0.in0")
    hal.net("nc", "not.0.out", "xor2.0.in1")
    for a, b, c in itertools.product((False, True), repeat=3):
        hal.set({"and2.0.in0": a, "and2.0.in1": b, "not.0.in": c})
        hal.step(1)
        assert hal.getp("xor2.0.out") is ((a and b) != (not c))


def test_names_give_instance_names_in_order(hal):
    hal.loadrt("or2", names="foo,bar,x.y-z")
    assert [f.name for f in hal.functions()] == ["bar", "foo", "x.y-z"]
    assert [p.name for p in hal.pins("foo.*")] == [
        "foo.in0", "foo.in1", "foo.out", "foo.time"]
    assert hal.pin("x.y-z.out").type == _core.BIT
    hal.loadrt("not", names=["inv"])           # a list works from Python
    assert hal.pin("inv.in").direction == _core.IN
    assert [p.name for p in hal.params("inv.*")] == [
        "inv.tmax", "inv.tmax-increased"]


def test_count_forms_as_the_reference(hal):
    hal.loadrt("and2 count=0x3")               # C-style integer
    assert [f.name for f in hal.functions()] == ["and2.0", "and2.1",
                                                 "and2.2"]
    hal.unloadrt("and2")
    hal.loadrt("and2", count=0)                # 0: the default (1)
    assert [f.name for f in hal.functions()] == ["and2.0"]
    hal.unloadrt("and2")
    hal.loadrt("and2", "count=2 names=")       # empty names: not given
    assert len(hal.functions()) == 2
    hal.unloadrt("and2")
    hal.loadrt("and2", "count=0 names=a")      # count=0: not given
    assert [f.name for f in hal.functions()] == ["a"]
    hal.unloadrt("and2")
    hal.loadrt("and2", count=-1)               # loads, with no instance
    assert hal.components("and2")[0].ready and hal.functions() == []
    hal.unloadrt("and2")
    hal.loadrt("and2", count=100)              # the reference has no limit
    assert len(hal.functions()) == 100 and len(hal.pins()) == 400


@pytest.mark.parametrize("line, error, match", [
    ("count=2 names=a", halsdk.InvalidError,
     "count= and names= are mutually exclusive"),
    ("names=a,,b", halsdk.InvalidError, r"names\[1\] is invalid"),
    ("names=a,b,", halsdk.InvalidError, r"names\[2\] is invalid"),
    ("names=a,a", halsdk.ExistsError, "duplicate .*'a.in0'"),
    ("names=a$b", halsdk.InvalidError, "contains the character '\\$'"),
    ("names=" + "x" * 200, halsdk.InvalidError, 'names: "x+" too long'),
    ("count=1.5", halsdk.InvalidError, "not an integer"),
    ("cnt=1", halsdk.InvalidError, "Unknown parameter `cnt=1'"),
])
def test_load_errors_leave_nothing(hal, line, error, match):
    hal.loadrt("or2")
    before = hal.info()["counts"]
    with pytest.raises(error, match=match):
        hal.loadrt("and2", line)
    assert hal.components("and2") == []
    assert hal.info()["counts"] == before
    hal.check()
    hal.loadrt("and2", names="ok")             # loads cleanly afterwards
    assert hal.pin("ok.out").owner == "and2"


@pytest.mark.parametrize("comp", ALL)
def test_unload_removes_everything(hal, comp):
    hal.newthread("servo", 1_000_000, fp=False)
    hal.loadrt(comp, count=3)
    hal.addf(f"{comp}.1", "servo")
    hal.net("s", f"{comp}.1.out")
    hal.unloadrt(comp)
    assert hal.components(comp) == []
    pattern = f"{comp}.*"
    assert hal.pins(pattern) == [] and hal.params(pattern) == []
    assert hal.functions() == []
    assert hal.thread("servo").functions == []
    assert hal.signal("s").writers == 0
    hal.loadrt(comp, names="again")
    assert [f.name for f in hal.functions()] == ["again"]
    hal.check()


def test_gates_run_in_a_realtime_thread(hal):
    hal.loadrt("and2")
    hal.loadrt("or2")
    hal.loadrt("xor2")
    hal.loadrt("not")
    hal.newthread("fast", 200_000, fp=False)
    for f in ("and2.0", "or2.0", "xor2.0", "not.0"):
        hal.addf(f, "fast")
    hal.set({"and2.0.in0": 1, "and2.0.in1": 1, "or2.0.in1": 1,
             "xor2.0.in0": 1})
    hal.start()
    try:
        deadline = time.monotonic() + 5
        while hal.thread("fast").cycles < 20 and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        hal.stop()
    assert hal.thread("fast").cycles >= 20
    assert [hal.getp(f"{c}.0.out") for c in ("and2", "or2", "xor2", "not")] \
        == [True, True, True, True]
    assert hal.function("and2.0").users == 1


def test_instance_names_helper():
    assert instance_names("g") == ["g.0"]
    assert instance_names("g", 3) == ["g.0", "g.1", "g.2"]
    assert instance_names("g", 0, default_count=2) == ["g.0", "g.1"]
    assert instance_names("g", -4) == []
    assert instance_names("g", 0, "a,b") == ["a", "b"]
    assert instance_names("g", 2, "") == ["g.0", "g.1"]
    assert instance_names("g", 2, [""]) == ["g.0", "g.1"]
    assert instance_names("g", 0, ("p", "q")) == ["p", "q"]
    assert instance_names("g", 5, max_count=5)[-1] == "g.4"
    with pytest.raises(halsdk.InvalidError, match="at most|more than"):
        instance_names("g", 6, max_count=5)
    with pytest.raises(halsdk.InvalidError, match="mutually exclusive"):
        instance_names("g", 1, "a")
    with pytest.raises(halsdk.InvalidError, match="blank"):
        instance_names("g", 0, "a b")
    assert split_names(None) == [] and split_names(",") == ["", ""]
