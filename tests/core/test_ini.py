"""halsdk.ini: INI files read as LinuxCNC reads them, with line numbers."""

from __future__ import annotations

from halsdk.ini import IniFile

TEXT = """\
# a comment
[AXIS_X]
MAX_VELOCITY = 10
MAX_VELOCITY = 20
[HAL]
HALFILE = a.hal
HALFILE = b.hal
[AXIS_X]
MIN_LIMIT = -5
"""


def test_first_value_wins_and_every_value_is_kept(tmp_path):
    path = tmp_path / "m.ini"
    path.write_text(TEXT)
    ini = IniFile(str(path))
    assert ini.get("AXIS_X", "MAX_VELOCITY") == "10"
    assert ini.all("HAL", "HALFILE") == ["a.hal", "b.hal"]
    assert ini.get("AXIS_X", "MIN_LIMIT") == "-5"      # sections merge
    assert ini.where("AXIS_X", "MIN_LIMIT") == f"{path}:9"
    assert ini.headers == [("AXIS_X", 2), ("HAL", 5), ("AXIS_X", 8)]


def test_repeats_name_the_later_line(tmp_path):
    path = tmp_path / "m.ini"
    path.write_text(TEXT)
    ini = IniFile(str(path))
    assert ini.repeats(repeatable={"HALFILE"}) == [
        (4, "[AXIS_X]MAX_VELOCITY is given again (first at line 3)"),
        (8, "[AXIS_X] is given again (first at line 2)")]
    assert ini.repeats(sections=lambda s: s == "HAL") == [
        (7, "[HAL]HALFILE is given again (first at line 6)")]
