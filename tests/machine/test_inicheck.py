"""halsdk.machine.inicheck: typing mistakes of an INI file (unknown keys
of known sections, repeated sections and keys, joint counts)."""

from __future__ import annotations

import tempfile
from pathlib import Path

from helpers import repo_path
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from halsdk.ini import IniFile
from halsdk.machine.inicheck import (
    DOCUMENTED_KEYS,
    check_ini,
    known_keys,
    section_kind,
)

EXAMPLES = repo_path("examples")


def problems(tmp_path: Path, text: str, name: str = "m.ini"):
    path = tmp_path / name
    path.write_text(text)
    return [str(p) for p in check_ini(IniFile(str(path)))]


def test_the_example_machines_have_no_problem():
    inis = sorted(EXAMPLES.rglob("*.ini"))
    assert inis
    for ini in inis:
        assert [str(p) for p in check_ini(IniFile(str(ini)))] == [], ini


def test_a_typo_names_file_line_section_key_and_the_near_key(tmp_path):
    found = problems(tmp_path, "[KINS]\nJOINTS = 1\n[JOINT_0]\nTYPE = LINEAR"
                     "\nMAX_VELOCTY = 5\n")
    assert found == [f"{tmp_path}/m.ini:5: [JOINT_0]MAX_VELOCTY: unknown "
                     "key: not a key of [JOINT_n] (did you mean "
                     "MAX_VELOCITY?)"]


def test_keys_are_case_sensitive_and_get_their_spelling(tmp_path):
    found = problems(tmp_path, "[TRAJ]\nmax_linear_velocity = 5\n")
    assert found == [f"{tmp_path}/m.ini:2: [TRAJ]max_linear_velocity: "
                     "unknown key: not a key of [TRAJ] (did you mean "
                     "MAX_LINEAR_VELOCITY?)"]


def test_a_key_far_from_any_gets_no_suggestion(tmp_path):
    found = problems(tmp_path, "[EMCMOT]\nZZQQ = 1\n")
    assert found == [f"{tmp_path}/m.ini:2: [EMCMOT]ZZQQ: unknown key: not "
                     "a key of [EMCMOT]"]


def test_linuxcnc_keys_that_halsdk_does_not_use_are_fine(tmp_path):
    assert problems(tmp_path, """\
[DISPLAY]
DISPLAY = axis
POSITION_OFFSET = RELATIVE
[RS274NGC]
REMAP = M6 modalgroup=6 ngc=change
REMAP = M61 modalgroup=6 ngc=set
[FILTER]
PROGRAM_EXTENSION = .py Python Script
py = python3
[EMCMOT]
BASE_PERIOD = 50000
[SPINDLE_0]
MAX_VELOCITY = 20000
[JOINT_0]
STEPGEN_MAXACCEL = 10
[KINS]
JOINTS = 1
""") == []


def test_user_sections_are_never_checked(tmp_path):
    assert problems(tmp_path, "[SIM]\nANYTHING = 1\nANYTHING = 2\n"
                    "[AXIS_Q]\nMAX_VELOCTY = 1\n[PROBE]\nX = 1\n"
                    "[PROBE]\n") == []
    assert section_kind("SIM") is None and known_keys("SIM") is None
    assert section_kind("JOINT_12") == "JOINT_n"
    assert section_kind("AXIS_W") == "AXIS_L"


def test_keys_that_the_hal_files_use_are_keys_of_their_section(tmp_path):
    (tmp_path / "m.hal").write_text("setp pid.0.Pgain [JOINT_0]MOTOR_LAG\n"
                                    "source more.hal\n")
    (tmp_path / "more.hal").write_text("setp x [JOINT_0](SPRING)\n")
    text = ("[HAL]\nHALFILE = m.hal\nHALCMD = setp y [TRAJ]MY_KEY\n"
            "[KINS]\nJOINTS = 1\n[JOINT_0]\nMOTOR_LAG = 1\nSPRING = 2\n"
            "UNUSED = 3\n[TRAJ]\nMY_KEY = 1\n")
    assert problems(tmp_path, text) == [
        f"{tmp_path}/m.ini:9: [JOINT_0]UNUSED: unknown key: not a key of "
        "[JOINT_n]"]


def test_a_repeated_section_and_key_say_which_value_wins(tmp_path):
    found = problems(tmp_path, """\
[KINS]
JOINTS = 1
[JOINT_0]
MAX_VELOCITY = 10
MAX_VELOCITY = 15
[HAL]
HALFILE = a.hal
HALFILE = b.hal
[JOINT_0]
MAX_VELOCITY = 20
TYPE = LINEAR
""")
    path = f"{tmp_path}/m.ini"
    assert found == [
        f"{path}:5: [JOINT_0]MAX_VELOCITY: given again: '15' is ignored, "
        "the first value '10' (line 4) is used",
        f"{path}:9: [JOINT_0]: section given again (first at line 3): its "
        "copies are merged, and a key given in both keeps its first value; "
        "ignored here: MAX_VELOCITY"]


def test_joints_disagreeing_with_the_joint_sections(tmp_path):
    found = problems(tmp_path, """\
[KINS]
KINEMATICS = trivkins coordinates=xyz
JOINTS = 2
[JOINT_0]
[JOINT_2]
""")
    path = f"{tmp_path}/m.ini"
    assert found == [
        f"{path}:3: [KINS]JOINTS: [KINS]JOINTS = 2 but [JOINT_1] is missing",
        f"{path}:3: [KINS]JOINTS: [KINS]JOINTS = 2 but [KINS]KINEMATICS "
        "'coordinates=xyz' has 3 joints",
        f"{path}:5: [JOINT_2]: joint 2 is beyond [KINS]JOINTS = 2 (line 3): "
        "this section is not used"]


def test_joints_beyond_what_motion_has_is_one_problem(tmp_path):
    """A count no motion has: one line at once (no list of 2**31 missing
    sections, nor the time to make it)."""
    found = problems(tmp_path, "[KINS]\nJOINTS = 2147483647\n[JOINT_0]\n")
    assert found == [f"{tmp_path}/m.ini:2: [KINS]JOINTS: [KINS]JOINTS = "
                     "2147483647 is more than 16, the most motion has"]


# ------------------------------------------------- property: every typo

SECTIONS = ["EMC", "DISPLAY", "RS274NGC", "EMCMOT", "TASK", "HAL", "HALUI",
            "APPLICATIONS", "TRAJ", "KINS", "AXIS_X", "JOINT_0", "SPINDLE_0",
            "EMCIO", "FILTER"]
ALPHABET = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_"


@st.composite
def typo(draw):
    """A section, one of its known keys, and that key with one character
    replaced, removed, inserted or two neighbours swapped."""
    section = draw(st.sampled_from(SECTIONS))
    keys = sorted(known_keys(section) or ())
    key = draw(st.sampled_from(keys))
    kind = draw(st.sampled_from(["replace", "delete", "insert", "swap"]))
    at = draw(st.integers(0, len(key) - 1))
    ch = draw(st.sampled_from(ALPHABET + ALPHABET.lower()))
    if kind == "replace":
        wrong = key[:at] + ch + key[at + 1:]
    elif kind == "delete":
        wrong = key[:at] + key[at + 1:]
    elif kind == "insert":
        wrong = key[:at] + ch + key[at:]
    else:
        wrong = key[:at] + key[at + 1:at + 2] + key[at] + key[at + 2:]
    return section, key, wrong


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(typo())
def test_every_single_character_typo_is_reported(case):
    section, key, wrong = case
    known = known_keys(section) or frozenset()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "m.ini"
        # the correct key never warns
        path.write_text(f"[{section}]\n{key} = 0\n")
        assert check_ini(IniFile(str(path))) == []
        if wrong in known or not wrong or \
                (section == "FILTER" and wrong != wrong.upper()):
            return              # another known key (FF0 -> FF1), or none
        path.write_text(f"[{section}]\n{wrong} = 0\n")
        found = check_ini(IniFile(str(path)))
        assert [(p.line, p.section, p.key) for p in found] == \
            [(2, section, wrong)]
        assert "unknown key" in found[0].message


def test_the_table_has_every_section_of_the_manual():
    assert set(DOCUMENTED_KEYS) == {
        "EMC", "DISPLAY", "FILTER", "RS274NGC", "EMCMOT", "TASK", "HAL",
        "HALUI", "APPLICATIONS", "TRAJ", "KINS", "AXIS_L", "JOINT_n",
        "SPINDLE_n", "EMCIO"}
