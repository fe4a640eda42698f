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


def test_a_backslash_continues_a_value(tmp_path):
    """As the reference: a backslash that ends a line continues the value
    on the next line (up to 20 lines); the entry keeps its first line."""
    path = tmp_path / "m.ini"
    path.write_text("[HALUI]\nMDI_COMMAND = G0 \\\n  X1 \\\nY2\nNEXT = 1\n"
                    "LAST = a\\\n")
    ini = IniFile(str(path))
    assert ini.get("HALUI", "MDI_COMMAND") == "G0 X1 Y2"
    assert ini.line("HALUI", "MDI_COMMAND") == 2
    assert ini.get("HALUI", "NEXT") == "1"
    assert ini.where("HALUI", "NEXT") == f"{path}:5"
    assert ini.get("HALUI", "LAST") == "a\\"        # no line follows


def test_a_nul_character_ends_its_line(tmp_path):
    """As in the reference's C strings: the rest of the line is not read,
    and nothing downstream gets a value it cannot use as a file name."""
    path = tmp_path / "m.ini"
    path.write_bytes(b"[HAL]\nHALFILE = mi\x00ll.hal\nTWOPASS = on\x00\n"
                     b"[EMC]\x00junk\nMACHINE = m\n")
    ini = IniFile(str(path))
    assert ini.get("HAL", "HALFILE") == "mi"
    assert ini.get("HAL", "TWOPASS") == "on"
    assert ini.get("EMC", "MACHINE") == "m"
