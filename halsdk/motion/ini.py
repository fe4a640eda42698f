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
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from halsdk.errors import HalError
from halsdk.ini import IniFile
from halsdk.motion.protocol import HOME_SEQUENCE_NONE, HomeFlag
from halsdk.motion.screwcomp import read_comp_file

__all__ = ["read_motion_ini", "MotionConfig", "MotionIniError",
           "homing_fields", "joint_plan", "axis_plan", "traj_plan",
           "HOMING_KEYS", "JOINT_KEYS", "AXIS_KEYS", "TRAJ_KEYS"]

# ------------------------------------------------- keys -> client calls
#
# A "plan" is the list of Motion calls that send the keys of one section:
# (method name, positional arguments, keyword arguments); the joint or
# axis number goes first when Motion.configure makes the call.
Plan = list[tuple[str, tuple[Any, ...], dict[str, Any]]]

_HOME_FLOATS = {"home": "home", "home_offset": "home_offset",
                "home_search_vel": "home_search_vel",
                "home_latch_vel": "home_latch_vel",
                "home_final_vel": "home_final_vel"}
_HOME_BOOLS = {"home_use_index": HomeFlag.USE_INDEX,
               "home_ignore_limits": HomeFlag.IGNORE_LIMITS,
               "home_is_shared": HomeFlag.IS_SHARED,
               "home_unlock_first": HomeFlag.UNLOCK_FIRST,
               "home_no_rehome": HomeFlag.NO_REHOME,
               "home_no_final_move": HomeFlag.NO_FINAL_MOVE,
               "home_index_no_encoder_reset":
                   HomeFlag.INDEX_NO_ENCODER_RESET}
#: the homing keys of [JOINT_n] (lower case)
HOMING_KEYS = (set(_HOME_FLOATS) | set(_HOME_BOOLS) |
               {"home_sequence", "volatile_home", "home_absolute_encoder"})


def _ini_bool(v: Any, key: str) -> bool:
    if isinstance(v, str):
        s = v.strip().lower()
        if s in ("1", "yes", "true", "on"):
            return True
        if s in ("0", "no", "false", "off", ""):
            return False
        raise ValueError(f"{key} = {v!r} is not a yes/no value")
    return bool(v)


def homing_fields(keys: Mapping[str, Any], where: str = "") -> dict:
    """[JOINT_n] homing keys -> fields of SET_JOINT_HOMING_PARAMS (the
    values of an unset key are the reference's defaults; no
    HOME_SEQUENCE: the joint is not part of "home all")."""
    out = {"home": 0.0, "home_offset": 0.0, "home_search_vel": 0.0,
           "home_latch_vel": 0.0, "home_final_vel": -1.0,
           "home_sequence": HOME_SEQUENCE_NONE, "volatile_home": 0,
           "home_flags": 0}
    flags = 0
    pre = f"{where}: " if where else ""

    def conv(fn, k, v):
        try:
            return fn(v)
        except (TypeError, ValueError):
            raise ValueError(f"{pre}{k.upper()} = {v!r} is not "
                             f"{'a number' if fn is float else 'an integer'}"
                             ) from None

    for k, v in keys.items():
        key = k.lower()
        if key in _HOME_FLOATS:
            out[_HOME_FLOATS[key]] = conv(float, k, v)
        elif key in _HOME_BOOLS:
            if _ini_bool(v, pre + key):
                flags |= int(_HOME_BOOLS[key])
        elif key == "home_sequence":
            out["home_sequence"] = conv(int, k, v)
        elif key == "volatile_home":
            out["volatile_home"] = 1 if _ini_bool(v, pre + key) else 0
        elif key == "home_absolute_encoder":
            n = conv(int, k, v)
            if n not in (0, 1, 2):
                raise ValueError(f"{pre}HOME_ABSOLUTE_ENCODER = {v!r} must "
                                 "be 0, 1 or 2")
            if n:
                flags |= int(HomeFlag.ABSOLUTE_ENCODER)
            if n == 2:
                flags |= int(HomeFlag.NO_FINAL_MOVE)
        else:
            raise ValueError(f"{pre}unknown homing key {k.upper()}")
    out["home_flags"] = flags
    return out


def _num(keys: Mapping[str, Any], key: str, where: str) -> float:
    v = keys[key]
    try:
        return float(v)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: {key.upper()} = {v!r} is not a "
                         "number") from None


def _lower(keys: Mapping[str, Any]) -> dict:
    return {k.lower(): v for k, v in keys.items()}


def _limits_plan(kind: str, k: Mapping[str, Any], where: str) -> Plan:
    """Soft limits, velocity, acceleration and jerk of a joint or axis
    (kind): the calls that send the keys present."""
    plan: Plan = []
    if "min_limit" in k or "max_limit" in k:
        lo = _num(k, "min_limit", where) if "min_limit" in k else -1e99
        hi = _num(k, "max_limit", where) if "max_limit" in k else 1e99
        plan.append((f"set_{kind}_limits", (lo, hi), {}))
    for key in ("max_velocity", "max_acceleration", "max_jerk"):
        if key in k:
            plan.append((f"set_{kind}_{key}", (_num(k, key, where),), {}))
    return plan


def joint_plan(j: int, keys: Mapping[str, Any]) -> Plan:
    """The calls that send the keys of [JOINT_j] (lower or upper case);
    ValueError for an unknown key or a bad value."""
    where = f"[JOINT_{j}]"
    k = _lower(keys)
    known = {"min_limit", "max_limit", "max_velocity", "max_acceleration",
             "max_jerk", "ferror", "min_ferror", "backlash", "comp_file",
             "comp_file_type", "type"} | HOMING_KEYS
    bad = sorted(set(k) - known)
    if bad:
        raise ValueError(f"{where}: unknown key(s) "
                         f"{', '.join(b.upper() for b in bad)}")
    plan = _limits_plan("joint", k, where)
    if "ferror" in k or "min_ferror" in k:
        fe = _num(k, "ferror", where) if "ferror" in k else 1.0
        mfe = _num(k, "min_ferror", where) if "min_ferror" in k else fe
        plan.append(("set_joint_ferror", (mfe, fe), {}))
    if "backlash" in k:
        plan.append(("set_joint_backlash", (_num(k, "backlash", where),),
                     {}))
    homing = {key: v for key, v in k.items() if key in HOMING_KEYS}
    if homing:
        homing_fields(homing, where)        # check before sending
        plan.append(("set_joint_homing", (), homing))
    if "comp_file" in k:
        ctype = k.get("comp_file_type", 0)
        try:
            ctype = int(ctype)
        except (TypeError, ValueError):
            raise ValueError(f"{where}: COMP_FILE_TYPE = {ctype!r} is not "
                             "0 or 1") from None
        entries = read_comp_file(str(k["comp_file"]), ctype)
        plan.append(("set_joint_comp", (entries,), {}))
    return plan


def axis_plan(letter: Any, keys: Mapping[str, Any]) -> Plan:
    """The calls that send the keys of [AXIS_letter]."""
    where = f"[AXIS_{str(letter).upper()}]"
    k = _lower(keys)
    known = {"min_limit", "max_limit", "max_velocity", "max_acceleration",
             "max_jerk"}
    bad = sorted(set(k) - known)
    if bad:
        raise ValueError(f"{where}: unknown key(s) "
                         f"{', '.join(b.upper() for b in bad)}")
    return _limits_plan("axis", k, where)


def traj_plan(keys: Mapping[str, Any]) -> Plan:
    """The calls that send the keys of [TRAJ]."""
    where = "[TRAJ]"
    k = _lower(keys)
    known = {"max_linear_velocity", "max_velocity",
             "default_linear_velocity", "default_velocity",
             "max_linear_acceleration", "max_acceleration",
             "default_linear_acceleration", "default_acceleration"}
    bad = sorted(set(k) - known)
    if bad:
        raise ValueError(f"{where}: unknown key(s) "
                         f"{', '.join(b.upper() for b in bad)}")
    plan: Plan = []
    for key in ("max_linear_velocity", "max_velocity"):
        if key in k:
            plan.append(("set_vel_limit", (_num(k, key, where),), {}))
    for key in ("default_linear_velocity", "default_velocity"):
        if key in k:
            plan.append(("set_vel", (_num(k, key, where),), {}))
    for key in ("max_linear_acceleration", "max_acceleration",
                "default_linear_acceleration", "default_acceleration"):
        if key in k:
            plan.append(("set_acc", (_num(k, key, where),), {}))
    return plan


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
        _check(ini, section, keys, lambda d, j=j: joint_plan(j, d))
        config.joints.append(keys)
    for letter in "XYZABCUVW":
        section = f"AXIS_{letter}"
        if ini.has_section(section):
            keys = {k: v for k, v in ini.items(section) if k in AXIS_KEYS}
            _check(ini, section, keys, lambda d, a=letter: axis_plan(a, d))
            config.axes[letter.lower()] = keys
    keys = {k: v for k, v in ini.items("TRAJ") if k in TRAJ_KEYS}
    _check(ini, "TRAJ", keys, traj_plan)
    config.traj = keys
    return config
