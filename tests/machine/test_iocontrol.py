"""The iocontrol.0 component: pins, E-stop chain, coolant and tool handshakes
(a fake toolchanger answers with hal.setp)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from helpers import data_path

import halsdk
from halsdk.machine import IoControl, IoControlError, IoState, ToolTable
from halsdk.machine.iocontrol import PINS, ToolState

DATA = data_path("machine")
P = "iocontrol.0."


def make(tmp_path: Path, random: bool, **kw) -> IoControl:
    name = "random.tbl" if random else "nonrandom.tbl"
    shutil.copy(DATA / name, tmp_path / name)
    return IoControl(ToolTable.load(str(tmp_path / name), random=random),
                     **kw)


def turn_on(hal, io: IoControl) -> None:
    io.estop_reset()
    hal.setp(P + "emc-enable-in", True)
    io.poll()
    io.machine_on()
    assert io.state is IoState.ON


def prepare(hal, io: IoControl, tool: int) -> None:
    io.prepare(tool)
    io.poll()
    assert io.tool_state is ToolState.PREPARING
    hal.setp(P + "tool-prepared", True)
    io.poll()
    hal.setp(P + "tool-prepared", False)
    assert io.tool_state is ToolState.IDLE


def change(hal, io: IoControl) -> None:
    io.change()
    io.poll()
    assert io.tool_state is ToolState.CHANGING
    hal.setp(P + "tool-changed", True)
    io.poll()
    hal.setp(P + "tool-changed", False)
    assert io.tool_state is ToolState.IDLE


def test_pins_have_the_reference_names_types_and_directions(hal, tmp_path):
    with make(tmp_path, False):
        names = {p.name for p in hal.pins() if p.name.startswith(P)}
        assert names == {P + n for n, _, _ in PINS}
        for name, type_, direction in PINS:
            pin = hal.pin(P + name)
            assert pin.type == halsdk.types.parse_type(type_), name
            assert pin.direction == halsdk.types.parse_direction(
                direction), name
        assert hal.component("iocontrol").realtime is False


def test_estop_chain(hal, tmp_path):
    with make(tmp_path, False) as io:
        assert io.state is IoState.ESTOP
        assert hal.getp(P + "user-enable-out") is False
        with pytest.raises(IoControlError, match="from estop"):
            io.machine_on()
        io.estop_reset()
        assert io.state is IoState.RESETTING
        assert hal.getp(P + "user-enable-out") is True
        assert hal.getp(P + "user-request-enable") is True
        io.poll()                      # the chain is still open
        assert hal.getp(P + "user-request-enable") is False   # a pulse
        assert io.state is IoState.RESETTING
        hal.setp(P + "emc-enable-in", True)
        io.poll()
        assert io.state is IoState.ESTOP_RESET
        assert hal.getp(P + "lube") is True        # on out of E-stop
        io.machine_on()
        assert io.state is IoState.ON
        io.machine_off()
        assert io.state is IoState.ESTOP_RESET
        io.machine_on()
        io.flood(True)
        hal.setp(P + "emc-enable-in", False)      # external E-stop
        io.poll()
        assert io.state is IoState.ESTOP
        assert "external E-stop" in io.error
        for pin in ("user-enable-out", "lube", "coolant-flood"):
            assert hal.getp(P + pin) is False, pin


def test_estop_reset_times_out_in_cycles(hal, tmp_path):
    with make(tmp_path, False, timeout=3) as io:
        io.estop_reset()
        for _ in range(3):
            io.poll()
            assert io.state is IoState.RESETTING
        io.poll()
        assert io.state is IoState.ESTOP
        assert "timed out" in io.error
        assert hal.getp(P + "user-enable-out") is False


def test_coolant_and_lube(hal, tmp_path):
    with make(tmp_path, False) as io:
        with pytest.raises(IoControlError, match="E-stop"):
            io.mist(True)
        turn_on(hal, io)
        io.mist(True)
        io.flood(True)
        assert hal.getp(P + "coolant-mist") and hal.getp(P + "coolant-flood")
        io.mist(False)
        io.lube(False)
        assert not hal.getp(P + "coolant-mist") and not hal.getp(P + "lube")
        assert io.lube_level_ok is False
        hal.setp(P + "lube_level", True)
        assert io.lube_level_ok is True
        io.machine_off()
        assert not hal.getp(P + "coolant-flood")


def test_nonrandom_prepare_and_change_handshakes(hal, tmp_path):
    with make(tmp_path, False) as io:
        turn_on(hal, io)
        io.prepare(5)
        assert hal.getp(P + "tool-prepare") is True
        assert hal.getp(P + "tool-prep-number") == 5
        assert hal.getp(P + "tool-prep-pocket") == 3     # the file's pocket
        assert hal.getp(P + "tool-prep-index") == 2      # the load order
        with pytest.raises(IoControlError, match="preparing"):
            io.change()
        hal.setp(P + "tool-prepared", True)
        io.poll()
        assert hal.getp(P + "tool-prepare") is False
        assert io.prepped_pocket == 2
        hal.setp(P + "tool-prepared", False)
        io.change()
        assert hal.getp(P + "tool-change") is True
        io.poll()
        io.poll()
        assert io.table.tool_in_spindle == 0             # not before changed
        hal.setp(P + "tool-changed", True)
        io.poll()
        assert hal.getp(P + "tool-change") is False
        assert hal.getp(P + "tool-number") == 5
        assert hal.getp(P + "tool-from-pocket") == 3
        assert hal.getp(P + "tool-prep-index") == 0
        assert io.table.spindle == io.table.entry(2)     # copied
        assert io.changes == 1


def test_nonrandom_t0_empties_the_spindle(hal, tmp_path):
    with make(tmp_path, False) as io:
        turn_on(hal, io)
        prepare(hal, io, 12)
        change(hal, io)
        assert hal.getp(P + "tool-number") == 12
        io.prepare(0)
        assert hal.getp(P + "tool-prep-pocket") == 0
        assert hal.getp(P + "tool-prep-index") == 0
        hal.setp(P + "tool-prepared", True)
        io.poll()
        hal.setp(P + "tool-prepared", False)
        change(hal, io)
        assert hal.getp(P + "tool-number") == 0
        assert io.table.spindle.offset == (0.0,) * 9


def test_random_change_swaps_and_saves(hal, tmp_path):
    with make(tmp_path, True) as io:
        turn_on(hal, io)
        assert hal.getp(P + "tool-number") == 0
        prepare(hal, io, 3)
        assert hal.getp(P + "tool-prep-pocket") == 7
        assert hal.getp(P + "tool-prep-index") == 7
        change(hal, io)
        assert hal.getp(P + "tool-number") == 3
        assert hal.getp(P + "tool-from-pocket") == 7
        assert io.table.entry(7).tool == 0               # swapped
        saved = ToolTable.load(str(tmp_path / "random.tbl"), random=True)
        assert saved.spindle.tool == 3 and saved.pocket_of(0) == 7


def test_m6_without_t_and_commands_when_off(hal, tmp_path):
    with make(tmp_path, True) as io:
        with pytest.raises(IoControlError, match="not on"):
            io.prepare(1)
        turn_on(hal, io)
        with pytest.raises(IoControlError, match="no tool prepared"):
            io.change()
        with pytest.raises(halsdk.HalError, match="tool 9 is not"):
            io.prepare(9)
        assert hal.getp(P + "tool-prepare") is False


def test_prepare_and_change_time_out(hal, tmp_path):
    with make(tmp_path, False, timeout=2) as io:
        turn_on(hal, io)
        io.prepare(1)
        io.poll()
        io.poll()
        assert io.tool_state is ToolState.PREPARING
        io.poll()
        assert io.tool_state is ToolState.IDLE
        assert hal.getp(P + "tool-prepare") is False
        assert "prepare timed out" in io.error
        prepare(hal, io, 1)
        io.change()
        for _ in range(3):
            io.poll()
        assert hal.getp(P + "tool-change") is False
        assert "change timed out" in io.error
        assert io.table.tool_in_spindle == 0


def test_estop_aborts_a_tool_change(hal, tmp_path):
    with make(tmp_path, False) as io:
        turn_on(hal, io)
        prepare(hal, io, 1)
        io.change()
        io.estop()
        assert hal.getp(P + "tool-change") is False
        assert io.tool_state is ToolState.IDLE
        hal.setp(P + "tool-changed", True)
        io.poll()
        assert io.table.tool_in_spindle == 0


def test_m61_sets_tool_number_and_from_pocket(hal, tmp_path):
    with make(tmp_path, False) as io:
        turn_on(hal, io)
        prepare(hal, io, 12)
        change(hal, io)
        assert hal.getp(P + "tool-from-pocket") == 40
        io.set_tool_number(5)
        assert hal.getp(P + "tool-number") == 5
        assert hal.getp(P + "tool-from-pocket") == 40    # unchanged by Qn
        io.set_tool_number(0)
        assert hal.getp(P + "tool-number") == 0
        assert hal.getp(P + "tool-from-pocket") == 0


def test_g10_through_the_controller_saves_the_table(hal, tmp_path):
    with make(tmp_path, False) as io:
        turn_on(hal, io)
        prepare(hal, io, 1)
        change(hal, io)
        io.set_offsets(1, offset=(0, 0, 3.5, 0, 0, 0, 0, 0, 0))
        assert io.table.spindle.offset[2] == 3.5
        saved = ToolTable.load(str(tmp_path / "nonrandom.tbl"))
        assert saved.entry(1).offset[2] == 3.5


def test_poll_runs_in_a_hal_thread(hal, tmp_path):
    with make(tmp_path, True) as io:
        hal.newthread("slow", 10_000_000)
        io.attach(hal, "slow")
        hal.net("estop-loop", P + "user-enable-out", P + "emc-enable-in")
        hal.net("prep-loop", P + "tool-prepare", P + "tool-prepared")
        hal.net("change-loop", P + "tool-change", P + "tool-changed")
        io.estop_reset()
        hal.step(1)
        io.machine_on()
        io.prepare(2)
        hal.step(1)
        assert io.prepped_pocket == 2
        io.change()
        hal.step(1)
        assert hal.getp(P + "tool-number") == 2
        assert io.changes == 1


def test_a_failed_save_after_a_change_is_reported(hal, tmp_path,
                                                  monkeypatch):
    with make(tmp_path, True) as io:
        turn_on(hal, io)
        prepare(hal, io, 1)

        def no_space(path=None):
            raise OSError(28, "No space left on device")

        monkeypatch.setattr(io.table, "save", no_space)
        change(hal, io)
        assert hal.getp(P + "tool-number") == 1
        assert "not saved" in io.error
