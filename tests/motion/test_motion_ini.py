"""The motion keys of an INI file: read, checked with errors that name
the file and line, and sent to motmod."""

from __future__ import annotations

import re

import pytest
from helpers import repo_path

from halsdk.motion import Motion, MotionIniError, read_motion_ini
from halsdk.motion.screwcomp import CompFileError

EXAMPLE = str(repo_path("examples", "motion", "mill3.ini"))

GOOD = """\
[KINS]
JOINTS = 2

[TRAJ]
MAX_LINEAR_VELOCITY = 40

[AXIS_X]
MAX_VELOCITY = 30

[JOINT_0]
TYPE = LINEAR
SCALE = 1000
MIN_LIMIT = -10
MAX_LIMIT = 200
MAX_VELOCITY = 30
MAX_ACCELERATION = 300
FERROR = 2
MIN_FERROR = 0.2
HOME_SEQUENCE = 0
HOME_SEARCH_VEL = 5
HOME_LATCH_VEL = -1

[JOINT_1]
MIN_LIMIT = -20
MAX_LIMIT = 20
MAX_VELOCITY = 10
MAX_ACCELERATION = 100
BACKLASH = 0.02
"""


def write(tmp_path, text: str, name: str = "m.ini") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_reads_the_motion_keys_only(tmp_path):
    config = read_motion_ini(write(tmp_path, GOOD))
    assert len(config.joints) == 2
    assert "SCALE" not in config.joints[0] and "TYPE" not in config.joints[0]
    assert config.joints[0]["HOME_SEQUENCE"] == "0"
    assert config.joints[1]["BACKLASH"] == "0.02"
    assert config.axes == {"x": {"MAX_VELOCITY": "30"}}
    assert config.traj == {"MAX_LINEAR_VELOCITY": "40"}


def test_the_example_configuration_reads(tmp_path):
    config = read_motion_ini(EXAMPLE)
    assert len(config.joints) == 3
    assert config.joints[2]["HOME_SEQUENCE"] == "0"


def line_of(text: str, needle: str) -> int:
    return next(n for n, line in enumerate(text.splitlines(), 1)
                if needle in line)


@pytest.mark.parametrize("old, new, words", [
    ("MAX_VELOCITY = 30\nMAX_ACCELERATION = 300",
     "MAX_VELOCITY = fast\nMAX_ACCELERATION = 300", "not a number"),
    ("MAX_ACCELERATION = 100", "MAX_ACCELERATION = -100",
     "must be greater than 0"),
    ("BACKLASH = 0.02", "BACKLASH = -0.02", "must not be negative"),
    ("HOME_SEQUENCE = 0", "HOME_SEQUENCE = first", "not an integer"),
    ("HOME_LATCH_VEL = -1", "HOME_LATCH_VEL = nan", "not a finite"),
    ("FERROR = 2", "FERROR = inf", "not a finite"),
    ("MAX_LIMIT = 20", "MAX_LIMIT = -30", "below MIN_LIMIT"),
])
def test_a_bad_value_names_file_and_line(tmp_path, old, new, words):
    text = GOOD.replace(old, new, 1)
    assert text != GOOD
    path = write(tmp_path, text)
    with pytest.raises(MotionIniError) as info:
        read_motion_ini(path)
    bad = new.splitlines()[0].split("=")[0].strip()
    number = line_of(text, new.splitlines()[0])
    assert str(info.value).startswith(f"{path}:{number}: ")
    assert bad in str(info.value) and words in str(info.value)


@pytest.mark.parametrize("old, new, words", [
    ("JOINTS = 2", "", r"\[KINS\]JOINTS is missing"),
    ("JOINTS = 2", "JOINTS = 17", "from 1 to 16"),
    ("JOINTS = 2", "JOINTS = 3", r"\[JOINT_2\] is missing"),
])
def test_missing_or_bad_joint_count(tmp_path, old, new, words):
    path = write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(MotionIniError, match=words):
        read_motion_ini(path)


def test_a_bad_compensation_file_names_its_own_line(tmp_path):
    write(tmp_path, "0 0 0\n10 10.01 9.99\nnot numbers\n", "x.comp")
    path = write(tmp_path, GOOD.replace(
        "BACKLASH = 0.02", "COMP_FILE = x.comp\nCOMP_FILE_TYPE = 0", 1))
    with pytest.raises(CompFileError, match=re.escape("x.comp") + ":3: "):
        read_motion_ini(path)


def test_an_unreadable_file_is_named(tmp_path):
    with pytest.raises(MotionIniError, match="nothing.ini: cannot read"):
        read_motion_ini(str(tmp_path / "nothing.ini"))


@pytest.fixture
def motion(hal) -> Motion:
    """The client of a two-joint motmod (trivkins x y, homemod, tpmod) in
    the servo thread."""
    hal.loadrt("trivkins", "coordinates=xy")
    hal.loadrt("homemod")
    hal.loadrt("tpmod")
    hal.loadrt("motmod", "num_joints=2")
    hal.addf("motion-command-handler", "servo-thread")
    hal.addf("motion-controller", "servo-thread")
    m = Motion.connect(hal)
    return m


def test_configure_ini_reaches_motmod(motion, tmp_path):
    m = motion
    m.configure_ini(write(tmp_path, GOOD))
    s = m.status()
    j0, j1 = s.joints[:2]
    assert (j0.min_pos_limit, j0.max_pos_limit) == (-10, 200)
    assert (j0.vel_limit, j0.acc_limit) == (30, 300)
    assert (j0.min_ferror, j0.max_ferror) == (0.2, 2)
    assert (j1.vel_limit, j1.backlash) == (10, 0.02)


def test_nothing_is_sent_when_a_late_key_is_bad(motion, tmp_path):
    m = motion
    before = m.status().joints[0].vel_limit
    path = write(tmp_path, GOOD.replace("BACKLASH = 0.02", "BACKLASH = x"))
    with pytest.raises(MotionIniError):
        m.configure_ini(path)
    assert m.status().joints[0].vel_limit == before
