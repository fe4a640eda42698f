"""The tool table file format and the random/nonrandom toolchanger model."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from helpers import data_path

from halsdk.errors import HalError
from halsdk.machine.tooltable import ToolEntry, ToolTable, ToolTableError

DATA = data_path("machine")


def table(tmp_path: Path, name: str, random: bool) -> ToolTable:
    path = tmp_path / name
    shutil.copy(DATA / name, path)
    return ToolTable.load(str(path), random=random)


@pytest.fixture
def nonrandom(tmp_path):
    return table(tmp_path, "nonrandom.tbl", False)


@pytest.fixture
def carousel(tmp_path):
    return table(tmp_path, "random.tbl", True)


def load_text(tmp_path: Path, text: str, random: bool = False) -> ToolTable:
    path = tmp_path / "t.tbl"
    path.write_text(text)
    return ToolTable.load(str(path), random=random)


# -- the file format -------------------------------------------------------

def test_nonrandom_load_compacts_pockets_and_keeps_the_file_pocket(nonrandom):
    assert [p for p, _ in nonrandom.pockets()] == [0, 1, 2, 3]
    assert [nonrandom.entry(p).pocket for p in (1, 2, 3)] == [17, 3, 40]
    assert nonrandom.pocket_of(5) == 2
    assert nonrandom.file_pocket(2) == 3
    t5 = nonrandom.entry(2)
    assert t5.offset == (0.5, 0, -1.25, 0, 0, 0, 0, 0, 0)
    assert (t5.diameter, t5.frontangle, t5.backangle, t5.orientation) == \
        (10.0, 80.0, 20.0, 2)
    assert t5.comment == "lathe insert"
    assert nonrandom.entry(3).offset == (0, 0, 100.125, 1, -2, 3, 4, 5, 6)
    assert nonrandom.spindle.tool == 0 and nonrandom.tool_in_spindle == 0


def test_random_pockets_are_real_and_pocket_0_is_the_spindle(carousel):
    assert carousel.spindle.tool == 0
    assert carousel.pocket_of(3) == 7
    assert carousel.entry(7).offset[2] == 30.0
    assert carousel.entry(5).empty
    assert carousel.tools() == [0, 1, 2, 3]


def test_lower_case_words_and_tabs(tmp_path):
    t = load_text(tmp_path, "t3\tp9 z1.5 d2\n")
    assert t.entry(1).tool == 3 and t.entry(1).offset[2] == 1.5


@pytest.mark.parametrize("name, random", [
    ("nonrandom.tbl", False), ("nonrandom.tbl", True), ("random.tbl", True)])
def test_round_trip_is_exact(tmp_path, name, random):
    t = table(tmp_path, name, random)
    out = tmp_path / "saved.tbl"
    t.save(str(out))
    again = ToolTable.load(str(out), random=t.random)
    assert again == t
    out2 = tmp_path / "saved2.tbl"
    again.save(str(out2))
    assert out.read_text() == out2.read_text()


def test_awkward_numbers_survive_a_round_trip(tmp_path):
    values = (0.1, 1e-05, -123456.789012345, 1 / 3, 2.5e-12, 1e17, -0.0,
              7.0, 0.30000000000000004)
    t = ToolTable(random=True)
    t.set_entry(4, ToolEntry(tool=9, offset=values, diameter=1 / 7,
                             frontangle=-12.5, backangle=1e-9,
                             orientation=9, comment=" spaced ; semi "))
    path = tmp_path / "x.tbl"
    t.save(str(path))
    text = path.read_text()
    assert "e-" not in text and "e+" not in text
    again = ToolTable.load(str(path), random=True)
    assert again.entry(4).offset == values
    assert again.entry(4).diameter == 1 / 7
    assert again.entry(4).comment == "spaced ; semi"


def test_nonrandom_save_writes_home_pockets_only(nonrandom, tmp_path):
    nonrandom.prepare(5)
    nonrandom.change()
    out = tmp_path / "o.tbl"
    nonrandom.save(str(out))
    lines = out.read_text().splitlines()
    assert [ln.split()[:2] for ln in lines] == \
        [["T1", "P17"], ["T5", "P3"], ["T12", "P40"]]


def test_random_save_writes_the_spindle_as_p0(carousel, tmp_path):
    carousel.prepare(3)
    carousel.change()
    lines = Path(carousel.path).read_text().splitlines()
    assert lines[0].startswith("T3 P0 ")
    assert "T0 P7 ;no tool" in lines


# -- errors ------------------------------------------------------------------

@pytest.mark.parametrize("text, random, message", [
    ("T1 P1\nT2 P2 K5\n", False, "2: unknown word 'K5'"),
    ("T1 P1 Z1 Z2\n", False, "1: word Z given twice"),
    ("T1 P1\n\nT1 P2\n", False, "3: tool 1 already defined at line 1"),
    ("T0 P1\n", False, "1: T0 means 'no tool'"),
    ("T1 P0\n", False, "1: pocket P0 must be positive"),
    ("T1 P-3\n", False, "1: pocket P-3 must be positive"),
    ("T1 P1001\n", True, "1: pocket P1001 is not in 0..1000"),
    ("T1 P-1\n", True, "1: pocket P-1 is not in 0..1000"),
    ("T1 P4\nT2 P4\n", True, "2: pocket P4 already used at line 1"),
    ("T1 P1 Zabc\n", False, "1: Z needs a number, not 'abc'"),
    ("T1 P1 Xnan\n", False, "1: X needs a number, not 'nan'"),
    ("T1.5 P1\n", False, "1: T needs an integer, not '1.5'"),
    ("T1 P1 Q12\n", False, "1: orientation Q12 is not in 0..9"),
    ("P1 Z1\n", False, "1: missing T word"),
    ("T1 Z1\n", False, "1: missing P word"),
    ("T-2 P1\n", True, "1: tool number -2 is negative"),
    ("T1 P1 D\n", False, "1: word D has no number"),
])
def test_bad_tables_name_file_and_line(tmp_path, text, random, message):
    with pytest.raises(ToolTableError) as info:
        load_text(tmp_path, text, random)
    assert str(info.value).startswith(f"{tmp_path / 't.tbl'}:{message}")
    assert isinstance(info.value, HalError)
    assert isinstance(info.value, ValueError)


def test_t0_is_allowed_in_a_random_table_and_duplicates_in_nonrandom(
        tmp_path):
    assert load_text(tmp_path, "T0 P3\n", True).pocket_of(0) == 3
    t = load_text(tmp_path, "T1 P2\nT2 P2\n", False)
    assert t.pocket_of(2) == 2 and t.entry(2).pocket == 2


def test_missing_file_is_a_tool_table_error(tmp_path):
    with pytest.raises(ToolTableError, match="cannot read tool table"):
        ToolTable.load(str(tmp_path / "absent.tbl"))


def test_failed_save_leaves_the_old_file_and_no_temporary(
        nonrandom, tmp_path, monkeypatch):
    path = Path(nonrandom.path)
    before = path.read_text()
    nonrandom.set_entry(1, ToolEntry(tool=1, pocket=17, comment="new"))

    def broken_fsync(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", broken_fsync)
    with pytest.raises(OSError, match="No space"):
        nonrandom.save()
    assert path.read_text() == before
    assert sorted(os.listdir(tmp_path)) == ["nonrandom.tbl"]
    monkeypatch.undo()
    nonrandom.save()
    assert "T1 P17 ;new" in path.read_text()


# -- Txxx and M6 ----------------------------------------------------------------

def test_nonrandom_m6_copies_the_home_slot_to_the_spindle(nonrandom):
    assert nonrandom.prepare(12) == 3
    assert nonrandom.selected_pocket == 3
    assert nonrandom.change() == 40          # the file's pocket
    assert nonrandom.spindle == nonrandom.entry(3)
    assert nonrandom.spindle.tool == 12
    assert nonrandom.pocket_of(12) == 3      # still home: nothing moved
    assert nonrandom.selected_pocket is None
    nonrandom.prepare(1)
    nonrandom.change()
    assert nonrandom.spindle.tool == 1
    assert nonrandom.entry(3).tool == 12     # the old tool went home


def test_nonrandom_t0_m6_empties_the_spindle(nonrandom):
    nonrandom.prepare(5)
    nonrandom.change()
    assert nonrandom.prepare(0) == 0
    assert nonrandom.change() == 0
    assert nonrandom.spindle.tool == 0
    assert nonrandom.spindle.offset == (0.0,) * 9
    assert nonrandom.tool_in_spindle == 0
    assert nonrandom.pocket_of(5) == 2


def test_nonrandom_change_does_not_save(nonrandom):
    path = Path(nonrandom.path)
    before = path.stat().st_mtime_ns, path.read_text()
    nonrandom.prepare(5)
    nonrandom.change()
    assert (path.stat().st_mtime_ns, path.read_text()) == before


def test_random_m6_swaps_spindle_and_pocket_and_saves(carousel):
    assert carousel.prepare(2) == 2
    assert carousel.change() == 2
    assert carousel.spindle.tool == 2 and carousel.spindle.pocket == 0
    assert carousel.entry(2).tool == 0 and carousel.entry(2).pocket == 2
    assert carousel.pocket_of(2) == 0
    saved = ToolTable.load(carousel.path, random=True)
    assert saved == carousel
    carousel.prepare(3)
    carousel.change()
    assert carousel.spindle.tool == 3
    assert carousel.entry(7).tool == 2       # tool 2 now lives in pocket 7
    assert ToolTable.load(carousel.path, random=True).pocket_of(2) == 7


def test_random_t0_is_an_ordinary_tool(carousel):
    carousel.prepare(1)
    carousel.change()
    assert carousel.pocket_of(0) == 1        # T0 went to pocket 1
    assert carousel.prepare(0) == 1
    carousel.change()
    assert carousel.spindle.tool == 0 and carousel.entry(1).tool == 1


def test_random_change_into_an_empty_spindle_leaves_an_empty_pocket(
        tmp_path):
    t = load_text(tmp_path, "T4 P3 Z1\n", True)
    assert t.spindle.empty and t.tool_in_spindle == 0
    t.prepare(4)
    t.change()
    assert t.spindle.tool == 4 and t.entry(3).empty
    assert Path(t.path).read_text() == "T4 P0 Z1\n"


def test_prepare_of_a_missing_tool_and_m6_without_t(nonrandom, carousel):
    with pytest.raises(ToolTableError, match="tool 99 is not in the tool"):
        nonrandom.prepare(99)
    with pytest.raises(ToolTableError, match="M6 without a prepared tool"):
        carousel.change()


def test_prepare_of_the_loaded_random_tool_is_pocket_0(carousel):
    assert carousel.prepare(0) == 0
    carousel.change()
    assert carousel.spindle.tool == 0 and carousel.entry(1).tool == 1


# -- M61 ----------------------------------------------------------------------

def test_nonrandom_m61_loads_without_a_move(nonrandom):
    nonrandom.set_tool_number(5)
    assert nonrandom.spindle == nonrandom.entry(2)
    assert nonrandom.current_pocket == 2
    assert nonrandom.selected_pocket is None
    nonrandom.set_tool_number(0)
    assert nonrandom.tool_in_spindle == 0


def test_random_m61_records_the_tool_in_pocket_0(carousel):
    carousel.set_tool_number(3)
    assert carousel.spindle.tool == 3
    assert carousel.entry(7).tool == 0
    assert ToolTable.load(carousel.path, random=True) == carousel


def test_m61_of_a_missing_tool_is_refused(carousel):
    with pytest.raises(ToolTableError, match="tool 42"):
        carousel.set_tool_number(42)


# -- G10 L1 / L10 / L11 ----------------------------------------------------------

def test_nonrandom_g10_of_a_stored_tool_updates_its_home_only(nonrandom):
    nonrandom.prepare(1)
    nonrandom.change()
    assert nonrandom.set_offsets(5, offset=(0, 0, 7, 0, 0, 0, 0, 0, 0),
                                 diameter=2.0) == 2
    assert nonrandom.entry(2).offset[2] == 7.0
    assert nonrandom.entry(2).pocket == 3
    assert nonrandom.spindle.tool == 1       # untouched
    saved = ToolTable.load(nonrandom.path)
    assert saved.entry(2).offset[2] == 7.0 and saved.entry(2).diameter == 2


def test_nonrandom_g10_of_the_loaded_tool_updates_home_and_spindle(
        nonrandom):
    nonrandom.prepare(12)
    nonrandom.change()
    assert nonrandom.set_offsets(12, frontangle=33.0, orientation=4) == 3
    assert nonrandom.entry(3).frontangle == 33.0
    assert nonrandom.spindle == nonrandom.entry(3)
    assert nonrandom.spindle.orientation == 4


def test_random_g10_of_the_loaded_tool_updates_pocket_0_only(carousel):
    carousel.prepare(2)
    carousel.change()
    assert carousel.set_offsets(2, offset=(1, 2, 3, 0, 0, 0, 0, 0, 0)) == 0
    assert carousel.spindle.offset[:3] == (1, 2, 3)
    # no home pocket holds a stale or a new copy of tool 2
    assert all(e.tool != 2 for p, e in carousel.pockets() if p)
    assert ToolTable.load(carousel.path, random=True).spindle.offset[2] == 3


def test_random_g10_of_a_stored_tool_updates_its_pocket_not_the_spindle(
        carousel):
    before = carousel.spindle
    assert carousel.set_offsets(3, backangle=-5.5) == 7
    assert carousel.entry(7).backangle == -5.5
    assert carousel.spindle == before


def test_g10_errors(nonrandom):
    with pytest.raises(ToolTableError, match="T0 is 'no tool'"):
        nonrandom.set_offsets(0, diameter=1)
    with pytest.raises(ToolTableError, match="tool 8 is not"):
        nonrandom.set_offsets(8, diameter=1)
    with pytest.raises(ToolTableError, match="orientation 10"):
        nonrandom.set_offsets(1, orientation=10)


# -- the interpreter's interface ----------------------------------------------

def test_entry_and_set_entry_check_pocket_ranges(nonrandom, carousel):
    with pytest.raises(ToolTableError, match="pocket 4 is not in 0..3"):
        nonrandom.entry(4)
    with pytest.raises(ToolTableError, match="pocket -1"):
        carousel.entry(-1)
    with pytest.raises(ToolTableError, match="pocket 1001"):
        carousel.set_entry(1001, ToolEntry(tool=5))
    carousel.set_entry(1000, ToolEntry(tool=5, pocket=3))
    assert carousel.entry(1000).pocket == 1000
    assert carousel.pocket_of(5) == 1000


def test_set_entry_keeps_the_nonrandom_home_pocket(nonrandom):
    nonrandom.set_entry(2, ToolEntry(tool=5, diameter=9))
    assert nonrandom.entry(2).pocket == 3
    assert nonrandom.random is False


def test_save_without_a_path_is_refused():
    with pytest.raises(ToolTableError, match="no file"):
        ToolTable().save()


def test_tool_entry_needs_nine_offsets():
    with pytest.raises(ValueError, match="9 components"):
        ToolEntry(tool=1, offset=(1, 2, 3))
