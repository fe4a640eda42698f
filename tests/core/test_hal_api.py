"""The Python API: instances, handles, listing, userspace components."""

from __future__ import annotations

import os

import pytest

import halsdk
from halsdk.core import _core


def test_second_hal_in_a_process_shares_the_instance(hal):
    with halsdk.Hal() as again:
        assert again.instance == hal.instance
        assert again.is_host
        again.newsig("shared", "float")
    assert hal.signal("shared").type == halsdk.FLOAT


def test_one_instance_per_process(hal):
    with pytest.raises(halsdk.InstanceError, match="one instance"):
        halsdk.Hal("another-instance")


def test_create_true_in_the_host_itself_is_fine(hal):
    with halsdk.Hal(create=True) as again:
        assert again.is_host


def test_instance_is_private_and_removed_at_close(monkeypatch):
    name = halsdk.testing.private_instance_name()
    monkeypatch.setenv("HALSDK_INSTANCE", name)
    path = f"/dev/shm/halsdk-{os.getuid()}-{name}"
    with halsdk.Hal(name, size=1 << 22) as h:
        assert h.is_host and h.instance == name
        assert os.stat(path).st_mode & 0o777 == 0o600
        assert h.info()["size"] == 1 << 22
        assert h.info()["host_pid"] == os.getpid()
    assert not os.path.exists(path)


def test_bad_instance_names():
    with pytest.raises(halsdk.InvalidError, match="instance name"):
        halsdk.Hal("../escape")
    with pytest.raises(halsdk.InvalidError, match="out of range"):
        halsdk.Hal("tiny-one", size=1000)
    assert not any(n.endswith("tiny-one") for n in os.listdir("/dev/shm"))


def test_handles_and_listing(hal):
    comp = halsdk.component("lst")
    comp.newpin("b", "bit", "out")
    comp.newpin("a", "float", "in")
    comp.newparam("k", "u32", "rw")
    comp.ready()
    pin = hal.pin("lst.a")
    assert (pin.name, pin.type, pin.direction, pin.owner) == (
        "lst.a", halsdk.FLOAT, halsdk.IN, "lst")
    assert pin.owner_id == comp.id
    assert [p.name for p in hal.pins("lst.*")] == ["lst.a", "lst.b"]
    assert [p.name for p in hal.pins(["lst.b", "nothing*"])] == ["lst.b"]
    assert [p.name for p in hal.params("lst.*")] == ["lst.k"]
    assert hal.ptype("lst.k") == "u32"
    hal.net("sig-a", "lst.a")
    assert hal.pin("lst.a").signal == hal.signal("sig-a")
    assert hal.stype("sig-a") == "float"
    with pytest.raises(halsdk.ConflictError, match="connected"):
        pin.value = 0
    comp.exit()


def test_component_items(hal):
    with halsdk.component("uc", prefix="pre") as comp:
        comp.newpin("in", halsdk.FLOAT, halsdk.IN)
        comp.newpin("out", "float", "out")
        comp.newparam("gain", "float", "rw")
        comp.ready()
        assert comp.is_ready
        assert "in" in comp and len(comp) == 3
        assert sorted(comp) == ["gain", "in", "out"]
        hal.setp("pre.in", 2.0)
        hal.setp("pre.gain", 3.0)
        comp["out"] = comp["in"] * comp["gain"]
        assert hal.getp("pre.out") == 6.0
        with pytest.raises(halsdk.NotFoundError, match="'nope'"):
            comp["nope"]
        with pytest.raises(halsdk.ExistsError):
            comp.newpin("in", "bit", "in")
    assert not comp.exists
    assert hal.components() == []


def test_component_removed_by_host_is_noticed(hal):
    comp = halsdk.component("vanish")
    comp.ready()
    hal.unload("vanish")
    assert not comp.exists
    comp.exit()               # harmless afterwards


def test_signal_pins_and_counts(hal):
    comp = halsdk.component("s")
    comp.newpin("o", "s32", "out")
    comp.newpin("i", "s32", "in")
    comp.newpin("io", "s32", "io")
    hal.net("w", "s.o", "=>", "s.i")
    sig = hal.signal("w")
    assert [p.name for p in sig.pins] == ["s.o", "s.i"]
    assert (sig.writers, sig.readers, sig.bidirs) == (1, 1, 0)
    hal.newsig("w2", "s32")
    hal.linksp("w2", "s.io")
    assert hal.signal("w2").bidirs == 1
    comp.exit()


def test_time_follows_stepping(hal):
    hal.newthread("t", 2_000_000)
    assert not hal.info()["simulated_clock"]
    hal.run_for(0.01)
    assert hal.time == 10_000_000
    assert hal.thread("t").cycles == 5
    assert hal.info()["simulated_clock"]


def test_instance_info_counts(hal):
    hal.newsig("x", "bit")
    info = hal.info()
    assert info["counts"]["signal"] == 1
    assert info["bytes_used"] > 0
    assert info["instance"] == hal.instance
    assert _core.serial() > 0


def test_half_made_segment_is_waited_for_and_cleaned_only_when_old():
    name = halsdk.testing.private_instance_name()
    shm = halsdk.core.instance.shm_name(name)
    path = "/dev/shm" + shm
    fd = os.open(path, os.O_CREAT | os.O_WRONLY, 0o600)   # empty: "creating"
    os.close(fd)
    try:
        with pytest.raises(halsdk.InstanceError, match="being created"):
            halsdk.Hal(name, create=False)
        assert n_removed(halsdk.cleanup(name)) == 0       # may be in progress
        old = os.stat(path).st_mtime - 60
        os.utime(path, (old, old))
        assert n_removed(halsdk.cleanup(name)) == 1       # left half-made
        assert not os.path.exists(path)
    finally:
        if os.path.exists(path):
            os.unlink(path)


def n_removed(names: list) -> int:
    return len(names)


def test_source_and_command_run_the_hal_language(hal, tmp_path):
    path = tmp_path / "machine.hal"
    path.write_text("loadrt and2 count=2\n"
                    "net chain and2.0.out and2.1.in0\n"
                    "setp and2.0.in0 1\n"
                    "getp and2.0.in0\n")
    assert hal.source(str(path)) == "TRUE\n"
    assert hal.signal("chain").writers == 1
    assert "==> and2.1.in0" in hal.command("show sig chain")
    with pytest.raises(halsdk.HalError, match="nosuch.pin"):
        hal.command("net x nosuch.pin")
    bad = tmp_path / "bad.hal"
    bad.write_text("setp and2.0.in1 1\nsetp nothing 1\nsetp and2.1.in1 1\n")
    with pytest.raises(halsdk.HalError, match=r"bad.hal:2: "):
        hal.source(str(bad))
    assert hal.getp("and2.0.in1") is True and hal.getp("and2.1.in1") is False
    with pytest.raises(halsdk.HalError, match=r"bad.hal:2: "):
        hal.source(str(bad), keep_going=True)
    assert hal.getp("and2.1.in1") is True
