"""The motion part of a machine's INI file: [KINS], [TRAJ], [JOINT_n] and
[AXIS_L], checked before anything is sent to the motion controller.

:func:`read_motion_ini` reads the sections with the reference's key names
and returns what :meth:`halsdk.motion.Motion.configure` takes.  Keys that
motion does not use (SCALE, P, I, D ... for the HAL files) are left alone.
A bad value is a :class:`MotionIniError` naming the file and line of the
key (``mill.ini:42: [JOINT_1] HOME_SEQUENCE = 'x' is not an integer``);
a bad compensation file is a ``CompFileError`` naming its own line.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

from halsdk.errors import HalError
from halsdk.ini import IniFile
from halsdk.motion.client import (
    HOMING_KEYS,
    _axis_plan,
    _joint_plan,
    _traj_plan,
)

#: keys of [JOINT_n] that motion takes (the homing keys included)
JOINT_KEYS = {"MIN_LIMIT", "MAX_LIMIT", "MAX_VELOCITY", "MAX_ACCELERATION",
              "MAX_JERK", "FERROR", "MIN_FERROR", "BACKLASH", "COMP_FILE",
              "COMP_FILE_TYPE"} | {k.upper() for k in HOMING_KEYS}
#: keys of [AXIS_L]
AXIS_KEYS = {"MIN_LIMIT", "MAX_LIMIT", "MAX_VELOCITY", "MAX_ACCELERATION",
             "MAX_JERK"}
#: keys of [TRAJ]
TRAJ_KEYS = {"MAX_LINEAR_VELOCITY", "MAX_VELOCITY", "DEFAULT_LINEAR_VELOCITY",
             "DEFAULT_VELOCITY", "MAX_LINEAR_ACCELERATION", "MAX_ACCELERATION",
             "DEFAULT_LINEAR_ACCELERATION", "DEFAULT_ACCELERATION"}
MAX_JOINTS = 16


class MotionIniError(HalError, ValueError):
    """A motion key of an INI file is missing or has a bad value."""


@dataclass
class MotionConfig:
    """The motion keys of an INI file, ready for ``Motion.configure``."""

    path: str
    joints: list = field(default_factory=list)     # one dict per joint
    axes: dict = field(default_factory=dict)       # letter -> dict
    traj: dict = field(default_factory=dict)


#: keys whose value must be > 0, and >= 0
_POSITIVE = {"MAX_VELOCITY", "MAX_ACCELERATION", "FERROR",
             "MAX_LINEAR_VELOCITY", "MAX_LINEAR_ACCELERATION",
             "DEFAULT_LINEAR_VELOCITY", "DEFAULT_VELOCITY",
             "DEFAULT_LINEAR_ACCELERATION", "DEFAULT_ACCELERATION"}
_NOT_NEGATIVE = {"MAX_JERK", "MIN_FERROR", "BACKLASH"}
_FINITE = _POSITIVE | _NOT_NEGATIVE | {
    "MIN_LIMIT", "MAX_LIMIT", "HOME", "HOME_OFFSET", "HOME_SEARCH_VEL",
    "HOME_LATCH_VEL", "HOME_FINAL_VEL"}


def _range(section: str, key: str, value: str) -> None:
    """The ranges that motion would refuse later, checked here so that
    the message names the line."""
    if key not in _FINITE:
        return
    x = float(value)            # a non-number was refused before
    if x != x or x in (float("inf"), float("-inf")):
        raise ValueError(f"[{section}] {key} = {value!r} is not a finite "
                         "number")
    if key in _POSITIVE and x <= 0:
        raise ValueError(f"[{section}] {key} = {value!r} must be greater "
                         "than 0")
    if key in _NOT_NEGATIVE and x < 0:
        raise ValueError(f"[{section}] {key} = {value!r} must not be "
                         "negative")


def _check(ini: IniFile, section: str, keys: dict, plan: Any) -> None:
    """Each key alone (so that an error names its line), then the
    section as a whole (errors that involve two keys)."""
    for key, value in keys.items():
        try:
            plan({key: value})
            _range(section, key, value)
        except HalError:
            raise
        except ValueError as e:
            raise MotionIniError(f"{ini.where(section, key)}: {e}") from None
    lo, hi = keys.get("MIN_LIMIT"), keys.get("MAX_LIMIT")
    if lo is not None and hi is not None and float(lo) > float(hi):
        raise MotionIniError(f"{ini.where(section, 'MAX_LIMIT')}: "
                             f"[{section}] MAX_LIMIT = {hi} is below "
                             f"MIN_LIMIT = {lo}")
    try:
        plan(keys)
    except HalError:
        raise
    except ValueError as e:
        raise MotionIniError(f"{ini.where(section)}: {e}") from None


def read_motion_ini(path: str) -> MotionConfig:
    """Read and check the motion sections of the INI file at ``path``."""
    try:
        ini = IniFile(path)
    except OSError as e:
        raise MotionIniError(f"{path}: cannot read: {e.strerror}") from None
    config = MotionConfig(path)
    text = ini.get("KINS", "JOINTS")
    if text is None:
        raise MotionIniError(f"{path}: [KINS]JOINTS is missing (the number "
                             "of joints)")
    try:
        njoints = int(text)
    except ValueError:
        njoints = 0
    if not 1 <= njoints <= MAX_JOINTS:
        raise MotionIniError(f"{ini.where('KINS', 'JOINTS')}: [KINS]JOINTS "
                             f"= {text!r} is not a number of joints from 1 "
                             f"to {MAX_JOINTS}")
    folder = os.path.dirname(os.path.abspath(path))
    for j in range(njoints):
        section = f"JOINT_{j}"
        if not ini.has_section(section):
            raise MotionIniError(f"{path}: [{section}] is missing "
                                 f"([KINS]JOINTS = {njoints})")
        keys: dict = {k: v for k, v in ini.items(section) if k in JOINT_KEYS}
        if "COMP_FILE" in keys:
            keys["COMP_FILE"] = os.path.join(folder, keys["COMP_FILE"])
        _check(ini, section, keys, lambda d, j=j: _joint_plan(j, d))
        config.joints.append(keys)
    for letter in "XYZABCUVW":
        section = f"AXIS_{letter}"
        if ini.has_section(section):
            keys = {k: v for k, v in ini.items(section) if k in AXIS_KEYS}
            _check(ini, section, keys, lambda d, a=letter: _axis_plan(a, d))
            config.axes[letter.lower()] = keys
    keys = {k: v for k, v in ini.items("TRAJ") if k in TRAJ_KEYS}
    _check(ini, "TRAJ", keys, _traj_plan)
    config.traj = keys
    return config
