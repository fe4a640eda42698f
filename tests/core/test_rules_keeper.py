"""The core is the one keeper of the HAL rules: structured errors, the
atomic net, the setp/sets checks, and who may import the core."""

from __future__ import annotations

import pytest

import halsdk
from halsdk.core import _core
from halsdk.errors import Rule
from halsdk.halcmd.messages import MESSAGES
from halsdk.values import coerce, parse_word


@pytest.fixture
def comp(hal):
    c = hal.new_component("rk")
    for name, t, d in (("o1", "bit", "out"), ("o2", "bit", "out"),
                       ("io", "bit", "io"), ("i", "bit", "in"),
                       ("f", "float", "in")):
        c.newpin(name, t, d)
    c.newparam("ro", "s32", "ro")
    c.ready()
    yield c
    c.exit()


def test_rule_enum_mirrors_the_c_enum():
    assert set(_core.RULES.values()) | {"BAD_VALUE"} == {r.value for r in Rule}


def test_halcmd_table_uses_known_rules():
    assert all(isinstance(rule, Rule) for _, rule, _ in MESSAGES)


@pytest.mark.parametrize("call, cls, rule, kind, names", [
    (lambda h: h.linkps("nope", "s"), halsdk.NotFoundError, Rule.NOT_FOUND,
     "pin", ("nope",)),
    (lambda h: h.linkps("rk.f", "s"), halsdk.HalTypeError,
     Rule.TYPE_MISMATCH, "signal", ("s", "rk.f")),
    (lambda h: h.linkps("rk.o2", "s"), halsdk.ConflictError,
     Rule.SECOND_WRITER, "signal", ("s", "rk.o2", "rk.o1")),
    (lambda h: h.linkps("rk.io", "s"), halsdk.ConflictError,
     Rule.WRITER_AND_IO, "signal", ("s", "rk.io", "rk.o1")),
    (lambda h: h.setp("rk.i", 1), halsdk.ConflictError,
     Rule.PIN_CONNECTED, "pin", ("rk.i", "s")),
    (lambda h: h.setp("rk.o1", 1), halsdk.NotPermittedError,
     Rule.WRITE_OUTPUT, "pin", ("rk.o1",)),
    (lambda h: h.setp("rk.ro", 1), halsdk.NotPermittedError,
     Rule.RO_PARAM, "param", ("rk.ro",)),
    (lambda h: h.sets("s", 1), halsdk.ConflictError, Rule.SIG_HAS_WRITER,
     "signal", ("s",)),
    (lambda h: h.net("rk.i", "rk.f"), halsdk.InvalidError,
     Rule.NAME_IS_PIN, "signal", ("rk.i",)),
    (lambda h: h.newsig("s", "bit"), halsdk.ExistsError, Rule.EXISTS,
     "signal", ("s",)),
    (lambda h: h.newsig("a b", "bit"), halsdk.InvalidError, Rule.BAD_NAME,
     None, ("a b",)),
    (lambda h: h.setp("rk.f", "x"), halsdk.InvalidError, Rule.BAD_VALUE,
     "pin", ("rk.f",)),
])
def test_errors_carry_rule_kind_and_names(hal, comp, call, cls, rule, kind,
                                          names):
    hal.net("s", "rk.o1", "rk.i")
    with pytest.raises(cls) as info:
        call(hal)
    assert (info.value.rule, info.value.kind, info.value.names) == \
        (rule, kind, names)


def test_net_checks_all_pins_before_linking(hal, comp):
    with pytest.raises(halsdk.ConflictError) as info:
        hal.net("n", "rk.i", "rk.o1", "rk.io")
    assert info.value.rule == Rule.WRITER_AND_IO
    assert info.value.names == ("n", "rk.io", "rk.o1")
    assert hal.find("signal", "n") is None
    assert not hal.pin("rk.i").linked and not hal.pin("rk.o1").linked
    hal.net("n", "rk.o1", "rk.i")
    hal.net("n", "rk.i")                # pins already there stay
    assert hal.signal("n").readers == 1


def test_params_lock_and_ignore_lock(hal, comp):
    hal.lock_level = hal.LOCK_PARAMS
    try:
        with pytest.raises(halsdk.NotPermittedError) as info:
            hal.setp("rk.i", True)
        assert info.value.rule == Rule.LOCKED
        hal.setp("rk.i", True, ignore_lock=True)
        assert hal.getp("rk.i") is True
    finally:
        hal.lock_level = 0


def test_one_value_parser():
    assert parse_word(halsdk.S32, "0x7fffffff") == 2**31 - 1
    assert parse_word(halsdk.S32, "4294967295") == -1          # C wraps
    with pytest.raises(ValueError):
        parse_word(halsdk.S32, "4294967295", wrap=False)
    assert parse_word(halsdk.U32, "010") == 8
    assert parse_word(halsdk.BIT, "TRUE") is True
    assert coerce(halsdk.FLOAT, " 0x1p4 ", "pin 'x'") == 16.0
    with pytest.raises(halsdk.InvalidError, match="out of range for u32"):
        coerce(halsdk.U32, -1, "pin 'x'")


def test_hal_current_is_a_view(hal):
    view = halsdk.Hal.current()
    assert view is not None and view.instance == hal.instance
    view.close()                        # does not close the instance
    assert hal.find("signal", "nothing") is None
