"""Links between realtime modules (EXPORT_SYMBOL, halsdk_symbol_find) and
named shared blocks: C API version 4."""

from __future__ import annotations

import ctypes

import pytest
from helpers.halcompile import comp_files, compiled_on_path

import halsdk
from halsdk.core import _core

MODS = ["hcsymexp", "hcsymuse"]


@pytest.fixture(scope="module")
def sym_dir(tmp_path_factory: pytest.TempPathFactory):
    with compiled_on_path(tmp_path_factory.mktemp("sym-modules"),
                          *comp_files(*MODS)) as folder:
        yield folder


def test_a_module_calls_what_another_exported(hal, sym_dir):
    hal.loadrt("hcsymexp")
    hal.loadrt("hcsymuse")
    hal.newthread("t", 1_000_000)
    hal.addf("hcsymuse", "t")
    hal.setp("hcsymuse.in", 7)
    hal.step(1)
    assert hal.getp("hcsymuse.out") == 3 * 2 * 7


def test_the_user_fails_clearly_without_the_exporter(hal, sym_dir):
    with pytest.raises(halsdk.NotFoundError, match="load hcsymexp first"):
        hal.loadrt("hcsymuse")
    assert _core.symbol_address("hcsym_twice") == 0


def test_the_exporter_cannot_go_before_its_user(hal, sym_dir):
    hal.loadrt("hcsymexp")
    hal.loadrt("hcsymuse")
    with pytest.raises(halsdk.ConflictError, match="hcsymuse"):
        hal.unloadrt("hcsymexp")
    assert hal.getp("hcsymexp.counter") == 0       # still loaded
    hal.unloadrt("hcsymuse")
    hal.unloadrt("hcsymexp")
    assert _core.symbol_address("hcsym_scale") == 0
    # and both load again afresh
    hal.loadrt("hcsymexp")
    hal.loadrt("hcsymuse")


def test_a_symbol_address_is_callable(hal, sym_dir):
    hal.loadrt("hcsymexp")
    twice = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_int)(
        _core.symbol_address("hcsym_twice"))
    assert twice(21) == 42
    scale = ctypes.c_int.from_address(_core.symbol_address("hcsym_scale"))
    assert scale.value == 3


def test_a_shared_block_is_found_by_name(hal, sym_dir):
    hal.loadrt("hcsymexp")
    addr, size = _core.shmem_attach("hcsym.block")
    assert size == 256
    assert addr % 64 == 0
    assert bytes((ctypes.c_ubyte * 256).from_address(addr)) == bytes(range(256))
    hal.unloadrt("hcsymexp")
    with pytest.raises(halsdk.NotFoundError, match="hcsym.block"):
        _core.shmem_attach("hcsym.block")
