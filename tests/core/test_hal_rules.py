"""The rules of HAL objects: every violation is a clear exception naming
the object, and the instance stays consistent afterwards."""

from __future__ import annotations

import pytest

import halsdk
from halsdk.core import _core

TYPES = ["bit", "float", "s32", "u32", "s64", "u64"]


@pytest.fixture
def comp(hal):
    c = halsdk.component("uc")
    yield c
    c.exit()


def consistent():
    bad, report = _core.check_consistency()
    assert bad == 0, report


# ---------------------------------------------------------------- components

def test_component_is_userspace_then_ready(hal, comp):
    info = hal.component("uc")
    assert not info.realtime
    assert not info.ready
    comp.ready()
    assert hal.component("uc").ready
    comp.unready()
    assert not hal.component("uc").ready


def test_duplicate_component_name_is_refused(hal, comp):
    with pytest.raises(halsdk.ExistsError, match="'uc'"):
        halsdk.component("uc")
    consistent()


def test_loaded_component_is_realtime_and_ready(hal):
    hal.loadrt("tand2")
    c = hal.component("tand2")
    assert c.realtime and c.ready


def test_pins_only_before_ready(hal, comp):
    comp.ready()
    with pytest.raises(halsdk.InvalidError, match="already ready"):
        comp.newpin("late", "bit", "in")
    consistent()


# ---------------------------------------------------------------- pins

@pytest.mark.parametrize("type_", TYPES)
@pytest.mark.parametrize("direction", ["in", "out", "io"])
def test_every_type_and_direction(hal, comp, type_, direction):
    pin = comp.newpin("p", type_, direction)
    assert pin.type == halsdk.types.parse_type(type_)
    assert pin.direction == halsdk.types.parse_direction(direction)
    assert pin.owner == "uc"
    assert pin.value == (False if type_ == "bit" else 0)


@pytest.mark.parametrize("type_,value,back", [
    ("bit", True, True), ("bit", "FALSE", False), ("float", "2.5", 2.5),
    ("s32", -2147483648, -2147483648), ("u32", 4294967295, 4294967295),
    ("s64", -(1 << 63), -(1 << 63)), ("u64", (1 << 64) - 1, (1 << 64) - 1),
    ("s64", "0x100000000", 1 << 32), ("float", 7, 7.0),
    ("s32", "010", 8), ("s32", "-0x10", -16), ("bit", "True", True),
    ("float", "0x1.8p1", 3.0), ("float", "-1e3", -1000.0),
])
def test_values_round_trip(hal, comp, type_, value, back):
    comp.newpin("p", type_, "in")
    hal.setp("uc.p", value)
    assert hal.getp("uc.p") == back
    assert type(hal.getp("uc.p")) is type(back)


@pytest.mark.parametrize("type_,value", [
    ("s32", 1 << 31), ("s32", -(1 << 31) - 1), ("u32", -1), ("u32", 1 << 32),
    ("s64", 1 << 63), ("u64", -1), ("u64", 1 << 64), ("bit", 2),
    ("bit", "maybe"), ("float", "x1"), ("s32", 1.5), ("s32", "ten"),
    ("s32", "1_000"), ("float", "1_0.5"), ("s32", "08"),
])
def test_bad_values_are_refused(hal, comp, type_, value):
    comp.newpin("p", type_, "in")
    before = hal.getp("uc.p")
    with pytest.raises(halsdk.InvalidError, match="uc.p"):
        hal.setp("uc.p", value)
    assert hal.getp("uc.p") == before


def test_64_bit_pins_do_not_wrap(hal, comp):
    comp.newpin("big", "u64", "out")
    comp.newpin("neg", "s64", "out")
    comp["big"] = (1 << 40) + 3
    comp["neg"] = -(1 << 50)
    assert hal.getp("uc.big") == (1 << 40) + 3
    assert hal.getp("uc.neg") == -(1 << 50)


def test_bad_type_and_direction(hal, comp):
    with pytest.raises(halsdk.InvalidError, match="type"):
        comp.newpin("p", "double", "in")
    with pytest.raises(halsdk.InvalidError, match="direction"):
        comp.newpin("p", "bit", "rw")
    with pytest.raises(halsdk.InvalidError, match="direction"):
        comp.newparam("q", "bit", "in")


def test_duplicate_pin_and_param_share_a_namespace(hal, comp):
    comp.newpin("p", "bit", "in")
    other = halsdk.component("uc2", prefix="uc")
    try:
        with pytest.raises(halsdk.ExistsError, match="uc.p"):
            other.newparam("p", "bit", "rw")
    finally:
        other.exit()
    consistent()


def test_setp_rules_for_pins(hal, comp):
    comp.newpin("o", "float", "out")
    comp.newpin("i", "float", "in")
    comp.newpin("b", "float", "io")
    with pytest.raises(halsdk.NotPermittedError,
                       match="pin 'uc.o' is not writable"):
        hal.setp("uc.o", 1)
    hal.setp("uc.b", 3)
    assert hal.getp("uc.b") == 3.0
    hal.net("s", "uc.i")
    with pytest.raises(halsdk.ConflictError,
                       match="pin 'uc.i' is connected to a signal"):
        hal.setp("uc.i", 1)


def test_params_ro_and_rw(hal, comp):
    comp.newparam("ro", "s32", "ro")
    comp.newparam("rw", "s32", "rw")
    hal.setp("uc.rw", 5)
    assert hal.getp("uc.rw") == 5
    with pytest.raises(halsdk.NotPermittedError,
                       match="param 'uc.ro' is not writable"):
        hal.setp("uc.ro", 5)
    comp["ro"] = 9             # the owner may write it
    assert hal.getp("uc.ro") == 9
    assert hal.param("uc.ro").direction == halsdk.RO


# ---------------------------------------------------------------- signals

def test_one_writer_any_readers(hal, comp):
    for n in ("o1", "o2"):
        comp.newpin(n, "float", "out")
    for n in ("i1", "i2", "i3"):
        comp.newpin(n, "float", "in")
    hal.net("s", "uc.o1", "uc.i1", "uc.i2", "uc.i3")
    sig = hal.signal("s")
    assert (sig.writers, sig.readers) == (1, 3)
    with pytest.raises(halsdk.ConflictError, match="'s'"):
        hal.linkps("uc.o2", "s")
    with pytest.raises(halsdk.ConflictError):
        hal.net("s", "uc.o2")
    assert sig.writers == 1 and not hal.pin("uc.o2").linked
    comp["o1"] = 4.5
    assert [hal.getp(f"uc.i{k}") for k in (1, 2, 3)] == [4.5] * 3
    consistent()


def test_io_pins_share_but_not_with_an_out_pin(hal, comp):
    comp.newpin("a", "bit", "io")
    comp.newpin("b", "bit", "io")
    comp.newpin("o", "bit", "out")
    hal.net("s", "uc.a", "uc.b")
    assert hal.signal("s").bidirs == 2
    with pytest.raises(halsdk.ConflictError, match="I/O"):
        hal.linkps("uc.o", "s")
    hal.net("t", "uc.o")
    comp2 = halsdk.component("uc2")
    try:
        comp2.newpin("c", "bit", "io")
        with pytest.raises(halsdk.ConflictError, match="output pin"):
            hal.linkps("uc2.c", "t")
    finally:
        comp2.exit()
    comp["a"] = True
    assert hal.getp("uc.b") is True
    consistent()


def test_net_checks_everything_before_changing_anything(hal, comp):
    comp.newpin("o1", "bit", "out")
    comp.newpin("o2", "bit", "out")
    comp.newpin("i", "bit", "in")
    with pytest.raises(halsdk.ConflictError):
        hal.net("s", "uc.i", "uc.o1", "uc.o2")
    assert hal.signals() == []
    assert not hal.pin("uc.i").linked and not hal.pin("uc.o1").linked


def test_net_refuses_a_pin_name_as_signal_name(hal, comp):
    comp.newpin("o", "bit", "out")
    comp.newpin("i", "bit", "in")
    with pytest.raises(halsdk.InvalidError, match="omit the signal name"):
        hal.net("uc.o", "uc.i")
    assert hal.signals() == [] and not hal.pin("uc.i").linked


def test_linking_across_types_is_refused(hal, comp):
    comp.newpin("f", "float", "in")
    comp.newpin("b", "bit", "in")
    hal.newsig("s", "float")
    hal.linkps("uc.f", "s")
    with pytest.raises(halsdk.HalTypeError,
                       match="Signal 's' of type 'float' cannot add pin "
                             "'uc.b' of type 'bit'"):
        hal.linkps("uc.b", "s")
    consistent()


def test_pin_linked_elsewhere_is_refused(hal, comp):
    comp.newpin("i", "s32", "in")
    hal.net("a", "uc.i")
    hal.newsig("b", "s32")
    with pytest.raises(halsdk.ConflictError,
                       match="Pin 'uc.i' was already linked to signal 'a'"):
        hal.linkps("uc.i", "b")
    hal.linkps("uc.i", "a")          # linking again to the same is a no-op
    assert hal.signal("a").readers == 1


def test_setting_a_driven_signal_is_refused(hal, comp):
    comp.newpin("o", "u32", "out")
    comp.newpin("i", "u32", "in")
    hal.net("s", "uc.o", "uc.i")
    with pytest.raises(halsdk.ConflictError,
                       match="signal 's' already has writer"):
        hal.sets("s", 3)
    hal.newsig("free", "u32")
    hal.sets("free", 7)
    assert hal.gets("free") == 7


def test_first_pin_gives_the_signal_its_value(hal, comp):
    comp.newpin("i", "float", "in")
    comp.newpin("j", "float", "in")
    hal.setp("uc.i", 1.25)
    hal.setp("uc.j", 9.0)
    hal.net("s", "uc.i", "uc.j")
    assert hal.gets("s") == 1.25
    assert hal.getp("uc.j") == 1.25


def test_unlinked_pin_keeps_its_own_and_last_value(hal, comp):
    comp.newpin("i", "s32", "in")
    hal.setp("uc.i", 3)
    assert hal.getp("uc.i") == 3
    hal.net("s", "uc.i")
    hal.sets("s", 42)
    assert hal.getp("uc.i") == 42
    hal.unlinkp("uc.i")
    assert hal.getp("uc.i") == 42      # keeps what it last saw
    hal.sets("s", 0)
    assert hal.getp("uc.i") == 42
    hal.setp("uc.i", 5)
    assert hal.getp("uc.i") == 5


def test_delsig_unlinks_its_pins(hal, comp):
    comp.newpin("o", "bit", "out")
    comp.newpin("i", "bit", "in")
    hal.net("s", "uc.o", "uc.i")
    comp["o"] = True
    hal.delsig("s")
    assert not hal.pin("uc.o").linked and not hal.pin("uc.i").linked
    assert hal.getp("uc.i") is True
    comp["o"] = False
    assert hal.getp("uc.i") is True
    with pytest.raises(halsdk.NotFoundError, match="signal 's' not found"):
        hal.signal("s")
    consistent()


def test_unknown_names(hal):
    with pytest.raises(halsdk.NotFoundError, match="nope"):
        hal.getp("nope")
    with pytest.raises(halsdk.NotFoundError, match="signal 'nosig'"):
        hal.gets("nosig")
    with pytest.raises(halsdk.NotFoundError):
        hal.net("s", "no.such.pin")
    with pytest.raises(LookupError):       # NotFoundError is a LookupError
        hal.pin("zzz")
    assert hal.signals() == []


# ---------------------------------------------------------------- names

def test_names_up_to_127_characters(hal, comp):
    long_name = "a" * (127 - len("uc."))
    pin = comp.newpin(long_name, "bit", "in")
    assert len(pin.name) == 127
    with pytest.raises(halsdk.InvalidError, match="longer than 127"):
        comp.newpin(long_name + "b", "bit", "in")
    with pytest.raises(halsdk.InvalidError, match="longer than 127"):
        hal.newsig("s" * 128, "bit")
    consistent()


@pytest.mark.parametrize("bad", ["", "has space", "tab\tname", "quo'te",
                                 'dq"x', "hash#x", ".lead", "trail.",
                                 "dou..ble", "dollar$", "br[0]", "é"])
def test_badly_formed_names(hal, bad):
    with pytest.raises(halsdk.InvalidError, match="name"):
        hal.newsig(bad, "bit")
    assert hal.signals() == []


def test_names_must_be_strings(hal):
    with pytest.raises(halsdk.InvalidError, match="strings"):
        hal.newsig(5, "bit")


# ---------------------------------------------------------------- aliases

def test_alias_and_unalias(hal, comp):
    comp.newpin("orig", "float", "in")
    comp.newparam("par", "float", "rw")
    hal.alias("pin", "uc.orig", "nice-name")
    assert hal.pin("nice-name").alias_of == "uc.orig"
    # the original name still finds it, as in the reference
    assert hal.pin("uc.orig") == hal.pin("nice-name")
    assert [p.name for p in hal.pins("uc.*")] == []
    hal.setp("nice-name", 2)
    with pytest.raises(halsdk.ExistsError):
        hal.alias("param", "uc.par", "nice-name")
    hal.alias("param", "uc.par", "p-alias")
    hal.unalias("pin", "nice-name")
    assert hal.getp("uc.orig") == 2.0
    assert hal.pin("uc.orig").alias_of is None
    hal.unalias("param", "p-alias")
    assert hal.param("uc.par").name == "uc.par"
    consistent()


# ---------------------------------------------------------------- locks

def test_lock_levels(hal, comp):
    comp.newpin("i", "bit", "in")
    hal.lock(2)                         # config
    with pytest.raises(halsdk.NotPermittedError, match="locked"):
        hal.newsig("s", "bit")
    with pytest.raises(halsdk.NotPermittedError, match="locked"):
        hal.linkps("uc.i", "x")
    hal.setp("uc.i", 1)                 # params are not locked
    hal.lock(4)
    with pytest.raises(halsdk.NotPermittedError, match="locked"):
        hal.setp("uc.i", 0)
    hal.lock(1)
    with pytest.raises(halsdk.HalError, match="locked"):
        hal.loadrt("tand2")
    hal.unlock()
    hal.loadrt("tand2")
    hal.newsig("s", "bit")
    assert hal.getp("uc.i") is True


# ---------------------------------------------------------------- handles

def test_stale_handles_raise(hal):
    comp = halsdk.component("gone")
    pin = comp.newpin("x", "bit", "in")
    comp.exit()
    assert not pin.exists
    with pytest.raises(halsdk.StaleError, match="pin 'gone.x'"):
        _ = pin.value
    # a new object in the same place is not mistaken for the old one
    comp2 = halsdk.component("gone")
    comp2.newpin("x", "bit", "in")
    assert not pin.exists
    comp2.exit()


# ---------------------------------------------------------------- capacity

def test_full_segment_is_a_clear_error_and_recoverable(monkeypatch):
    name = halsdk.testing.private_instance_name()
    monkeypatch.setenv("HALSDK_INSTANCE", name)
    with halsdk.Hal(name, create=True, size=1 << 20) as h:
        comp = halsdk.component("filler")
        made = 0
        with pytest.raises(halsdk.CapacityError, match="full"):
            for made in range(100_000):
                comp.newpin(f"p{made}", "float", "in")
        assert 1000 < made < 100_000
        bad, report = _core.check_consistency()
        assert bad == 0, report
        comp.exit()
        assert h.info()["counts"]["pin"] == 0
        # the memory came back: the same number fits again
        comp = halsdk.component("filler")
        for k in range(made):
            comp.newpin(f"q{k}", "float", "in")
        comp.exit()


def test_100000_pins_in_one_instance(monkeypatch):
    name = halsdk.testing.private_instance_name()
    monkeypatch.setenv("HALSDK_INSTANCE", name)
    with halsdk.Hal(name, create=True) as h:
        comp = halsdk.component("many")
        for k in range(100_000):
            comp.newpin(f"p{k}", "s32", "in")
        comp.ready()
        assert h.info()["counts"]["pin"] == 100_000
        h.setp("many.p99999", 7)
        assert h.pin("many.p99999").value == 7
        assert len(h.pins("many.p9999*")) == 11
        comp.exit()
