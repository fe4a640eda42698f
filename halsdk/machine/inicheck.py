"""Typing mistakes in a machine's INI file, found before it starts.

LinuxCNC, and halsdk's reader (:mod:`halsdk.ini`), take an INI file
silently: a misspelt key (``MAX_VELOCTY``) is never read and its default
applies, a section given twice (``[JOINT_0]`` copied for a new joint and
not renamed) is merged with the first copy, and a key given twice keeps
its *first* value, as LinuxCNC's inifile does.  :func:`check_ini` reports
these, each as an :class:`IniProblem` naming ``file:line``, the section
and the key:

* a key of a known section (``[EMC]``, ``[DISPLAY]``, ``[TRAJ]``,
  ``[JOINT_n]`` ...) that is neither one of LinuxCNC 2.9's documented keys
  of that section, nor one that halsdk reads, nor one that the HAL files
  use (``[JOINT_0]P`` in a HAL file makes ``P`` a key of ``[JOINT_0]``),
  with "did you mean ...?" when a known key is close;
* a section header given again, and each later copy of a key (its value
  is ignored), but the keys meant to be repeated (``[HAL]HALFILE`` ...);
* ``[KINS]JOINTS`` that disagrees with the ``[JOINT_n]`` sections or with
  the ``coordinates=`` of ``trivkins`` in ``[KINS]KINEMATICS``.

Sections that are not LinuxCNC's (``[SIM]``, ``[PROBE]`` ...) belong to
the user and are never checked.  :func:`check_hal_joints` compares
``[KINS]JOINTS`` with the joints that the motion module has once the HAL
files are loaded (``joint.N.`` pins wired for ``N >= JOINTS``).
"""

from __future__ import annotations

import difflib
import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Optional

from halsdk.ini import IniFile
from halsdk.motion.ini import MAX_JOINTS

__all__ = ["IniProblem", "check_ini", "check_hal_joints", "hal_references",
           "known_keys", "section_kind", "DOCUMENTED_KEYS", "HALSDK_KEYS",
           "REPEATABLE_KEYS"]


def _keys(text: str) -> frozenset[str]:
    return frozenset(text.split())


#: the keys of each section in LinuxCNC 2.9's INI chapter (and the GUI
#: chapters, for [DISPLAY]), key names only; ``JOINT_n``, ``SPINDLE_n``
#: and ``AXIS_L`` stand for every joint, spindle and axis letter
DOCUMENTED_KEYS: dict[str, frozenset[str]] = {
    "EMC": _keys("MACHINE VERSION DEBUG"),
    "DISPLAY": _keys("""
        DISPLAY POSITION_OFFSET POSITION_FEEDBACK DRO_FORMAT_MM DRO_FORMAT_IN
        CONE_BASESIZE MAX_FEED_OVERRIDE MIN_SPINDLE_OVERRIDE
        MIN_SPINDLE_0_OVERRIDE MAX_SPINDLE_OVERRIDE MAX_SPINDLE_0_OVERRIDE
        DEFAULT_SPINDLE_SPEED DEFAULT_SPINDLE_0_SPEED SPINDLE_INCREMENT
        MIN_SPINDLE_0_SPEED MAX_SPINDLE_0_SPEED MAX_SPINDLE_POWER
        PROGRAM_PREFIX INTRO_GRAPHIC INTRO_TIME CYCLE_TIME PREVIEW_TIMEOUT
        EMBED_TAB_NAME EMBED_TAB_COMMAND EMBED_TAB_LOCATION
        DEFAULT_LINEAR_VELOCITY MIN_VELOCITY MAX_LINEAR_VELOCITY
        MIN_LINEAR_VELOCITY DEFAULT_ANGULAR_VELOCITY MIN_ANGULAR_VELOCITY
        MAX_ANGULAR_VELOCITY INCREMENTS ANGULAR_INCREMENTS GRIDS OPEN_FILE
        EDITOR TOOL_EDITOR PYVCP PYVCP_POSITION LATHE BACK_TOOL_LATHE FOAM
        GEOMETRY ARCDIVISION MDI_HISTORY_FILE JOG_AXES JOG_INVERT
        USER_COMMAND_FILE HELP_FILE TKPKG GLADEVCP GRAPHICS_CYCLE_TIME
        HALPIN_CYCLE LOG_FILE MACHINE_LOG_PATH PREFERENCE_FILE_PATH
        MESSAGE_BOLDTEXT MESSAGE_TEXT USER_CSS_FILE NGCGUI_FONT
        NGCGUI_OPTIONS NGCGUI_PREAMBLE NGCGUI_POSTAMBLE NGCGUI_SUBFILE
        GCMC_INCLUDE_PATH NC_FILES TTT TTT_PREAMBLE"""),
    "FILTER": _keys("PROGRAM_EXTENSION FILTER_PROGRESS"),
    "RS274NGC": _keys("""
        PARAMETER_FILE ORIENT_OFFSET RS274NGC_STARTUP_CODE SUBROUTINE_PATH
        CENTER_ARC_RADIUS_TOLERANCE_INCH CENTER_ARC_RADIUS_TOLERANCE_MM
        USER_M_PATH USER_DEFINED_FUNCTION_MAX_DIRS INI_VARS HAL_PIN_VARS
        RETAIN_G43 OWORD_NARGS NO_DOWNCASE_OWORD OWORD_WARNONLY
        DISABLE_G92_PERSISTENCE DISABLE_FANUC_STYLE_SUB LOG_LEVEL LOG_FILE
        REMAP ON_ABORT_COMMAND FEATURES"""),
    "EMCMOT": _keys("EMCMOT BASE_PERIOD SERVO_PERIOD TRAJ_PERIOD "
                    "COMM_TIMEOUT HOMEMOD"),
    "TASK": _keys("TASK CYCLE_TIME INTERPRETER"),
    "HAL": _keys("HALFILE TWOPASS HALCMD SHUTDOWN POSTGUI_HALFILE "
                 "POSTGUI_HALCMD HALUI"),
    "HALUI": _keys("MDI_COMMAND"),
    "APPLICATIONS": _keys("DELAY APP"),
    "TRAJ": _keys("""
        ARC_BLEND_ENABLE ARC_BLEND_FALLBACK_ENABLE
        ARC_BLEND_OPTIMIZATION_DEPTH ARC_BLEND_GAP_CYCLES ARC_BLEND_RAMP_FREQ
        SPINDLES COORDINATES LINEAR_UNITS ANGULAR_UNITS
        DEFAULT_LINEAR_VELOCITY DEFAULT_LINEAR_ACCELERATION
        MAX_LINEAR_VELOCITY MAX_LINEAR_ACCELERATION DEFAULT_VELOCITY
        DEFAULT_ACCELERATION MAX_VELOCITY MAX_ACCELERATION POSITION_FILE
        NO_FORCE_HOMING HOME TPMOD NO_PROBE_JOG_ERROR NO_PROBE_HOME_ERROR"""),
    "KINS": _keys("JOINTS KINEMATICS"),
    "AXIS_L": _keys("MAX_VELOCITY MAX_ACCELERATION MIN_LIMIT MAX_LIMIT "
                    "WRAPPED_ROTARY LOCKING_INDEXER_JOINT OFFSET_AV_RATIO"),
    "JOINT_n": _keys("""
        TYPE UNITS MAX_VELOCITY MAX_ACCELERATION BACKLASH COMP_FILE
        COMP_FILE_TYPE MIN_LIMIT MAX_LIMIT MIN_FERROR FERROR LOCKING_INDEXER
        HOME HOME_OFFSET HOME_SEARCH_VEL HOME_LATCH_VEL HOME_FINAL_VEL
        HOME_USE_INDEX HOME_INDEX_NO_ENCODER_RESET HOME_IGNORE_LIMITS
        HOME_IS_SHARED HOME_ABSOLUTE_ENCODER HOME_SEQUENCE VOLATILE_HOME
        HOME_UNLOCK_FIRST HOME_NO_REHOME HOME_NO_FINAL_MOVE
        P I D FF0 FF1 FF2 BIAS DEADBAND OUTPUT_SCALE OUTPUT_OFFSET MAX_OUTPUT
        INPUT_SCALE ENCODER_SCALE SCALE STEP_SCALE STEPGEN_MAXACCEL
        STEPGEN_MAXVEL"""),
    "SPINDLE_n": _keys("MAX_VELOCITY MIN_VELOCITY MAX_REVERSE_VELOCITY "
                       "MIN_REVERSE_VELOCITY INCREMENT HOME_SEARCH_VELOCITY "
                       "HOME_SEQUENCE"),
    "EMCIO": _keys("EMCIO CYCLE_TIME TOOL_TABLE DB_PROGRAM "
                   "TOOL_CHANGE_POSITION TOOL_CHANGE_WITH_SPINDLE_ON "
                   "TOOL_CHANGE_QUILL_UP TOOL_CHANGE_AT_G30 "
                   "RANDOM_TOOLCHANGER"),
}


def _halsdk_keys() -> dict[str, frozenset[str]]:
    from halsdk.motion.ini import AXIS_KEYS, JOINT_KEYS, TRAJ_KEYS
    return {
        "HAL": _keys("HALFILE TWOPASS HALCMD SHUTDOWN POSTGUI_HALFILE"),
        "KINS": _keys("JOINTS KINEMATICS"),
        "TRAJ": frozenset(TRAJ_KEYS) | _keys("COORDINATES LINEAR_UNITS"),
        "JOINT_n": frozenset(JOINT_KEYS),
        "AXIS_L": frozenset(AXIS_KEYS),
        "TASK": _keys("CYCLE_TIME"),
        "EMCIO": _keys("TOOL_TABLE RANDOM_TOOLCHANGER"),
        "RS274NGC": _keys("SUBROUTINE_PATH PARAMETER_FILE USER_M_PATH "
                          "HAL_PIN_VARS HALSDK_MAX_ITERATIONS "
                          "HALSDK_MAX_IDLE_TIME HALSDK_USER_M_TIMEOUT"),
    }


#: the keys that halsdk itself reads, by section
HALSDK_KEYS: dict[str, frozenset[str]] = _halsdk_keys()

#: keys given once per value, as many times as needed
REPEATABLE_KEYS: dict[str, frozenset[str]] = {
    "HAL": _keys("HALFILE HALCMD SHUTDOWN POSTGUI_HALFILE POSTGUI_HALCMD"),
    "HALUI": _keys("MDI_COMMAND"),
    "APPLICATIONS": _keys("APP"),
    "RS274NGC": _keys("REMAP"),
    "FILTER": _keys("PROGRAM_EXTENSION"),
    "DISPLAY": _keys("EMBED_TAB_NAME EMBED_TAB_COMMAND EMBED_TAB_LOCATION "
                     "USER_COMMAND_FILE"),
}

_NUMBERED = re.compile(r"(JOINT|SPINDLE)_(\d+)\Z")
_AXIS = re.compile(r"AXIS_[XYZABCUVW]\Z")
# the [SECTION]KEY and [SECTION](KEY) words of HAL files
_REFERENCE = re.compile(r"\[([^\]\s]+)\](?:\(([^)]*)\)|([A-Za-z0-9_]+))")
_SOURCE = re.compile(r"^\s*source\s+(\S+)", re.M)


def section_kind(section: str) -> Optional[str]:
    """The name of a known section's key table (``JOINT_3`` ->
    ``JOINT_n``, ``AXIS_Y`` -> ``AXIS_L``), None for a user section."""
    m = _NUMBERED.match(section)
    if m:
        return f"{m.group(1)}_n"
    if _AXIS.match(section):
        return "AXIS_L"
    return section if section in DOCUMENTED_KEYS else None


def known_keys(section: str) -> Optional[frozenset[str]]:
    """LinuxCNC's and halsdk's keys of a section (None: a user section,
    any key goes)."""
    kind = section_kind(section)
    if kind is None:
        return None
    return DOCUMENTED_KEYS[kind] | HALSDK_KEYS.get(kind, frozenset())


@dataclass(frozen=True)
class IniProblem:
    """One finding: ``path:line: [SECTION]KEY: message``."""

    path: str
    line: int
    section: str
    key: Optional[str]
    message: str

    def __str__(self) -> str:
        where = f"{self.path}:{self.line}" if self.line else self.path
        return f"{where}: [{self.section}]{self.key or ''}: {self.message}"


def _halfile_paths(ini: IniFile) -> list[str]:
    folder = os.path.dirname(os.path.abspath(ini.path))
    names = []
    for key in ("HALFILE", "POSTGUI_HALFILE", "SHUTDOWN"):
        for value in ini.all("HAL", key):
            words = value.split()
            if words:
                names.append(words[0])
    return [n if os.path.isabs(n) else os.path.join(folder, n)
            for n in names]


def hal_references(ini: IniFile) -> dict[str, set[str]]:
    """The ``[SECTION]KEY`` words of the machine's HAL files (and the
    files they ``source``) and of ``[HAL]HALCMD``, by section: the keys
    that the HAL files use are keys of their section."""
    found: dict[str, set[str]] = {}
    texts = list(ini.all("HAL", "HALCMD"))
    todo, seen = _halfile_paths(ini), set[str]()
    while todo and len(seen) < 200:
        path = todo.pop(0)
        if path in seen:
            continue
        seen.add(path)
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError:
            continue                    # the launcher names it
        texts.append(text)
        folder = os.path.dirname(path)
        for name in _SOURCE.findall(text):
            todo.append(name if os.path.isabs(name)
                        else os.path.join(folder, name))
            # HAL files run in the INI file's folder too
            todo.append(os.path.join(
                os.path.dirname(os.path.abspath(ini.path)), name))
    for text in texts:
        for section, paren, word in _REFERENCE.findall(text):
            found.setdefault(section, set()).add(paren or word)
    return found


def suggestion(key: str, known: Iterable[str]) -> Optional[str]:
    """The known key closest to ``key`` (keys are case sensitive, so
    ``max_velocity`` gets ``MAX_VELOCITY``), None when none is close."""
    names = sorted(known)
    for probe in (key, key.upper()):
        near = difflib.get_close_matches(probe, names, n=1, cutoff=0.75)
        if near and near[0] != key:
            return near[0]
    return None


def _unknown_keys(ini: IniFile, used: Mapping[str, set[str]]
                  ) -> list[IniProblem]:
    out = []
    for (section, key), places in ini.every.items():
        known = known_keys(section)
        if known is None or key in known or key in used.get(section, ()):
            continue
        if section == "FILTER" and key != key.upper():
            continue                    # a file extension: its filter
        near = suggestion(key, known)
        kind = section_kind(section)
        what = f"not a key of [{kind}]" if kind != section else \
            f"not a key of [{section}]"
        hint = f" (did you mean {near}?)" if near else ""
        out.append(IniProblem(ini.path, places[0][1], section, key,
                              f"unknown key: {what}{hint}"))
    return out


def _repeats(ini: IniFile) -> list[IniProblem]:
    """A repeated header (with the keys of its copy that are ignored),
    and each later copy of a key within one copy of a section."""
    out = []
    starts = sorted(number for _, number in ini.headers)
    ignored: dict[int, list[str]] = {}     # header line -> keys ignored
    for (section, key), places in ini.every.items():
        if len(places) < 2 or section_kind(section) is None or \
                key in REPEATABLE_KEYS.get(section, ()):
            continue
        for value, number in places[1:]:
            header = max((h for h in starts if h < number), default=0)
            if header != ini.section_lines.get(section, 0):
                ignored.setdefault(header, []).append(key)
                continue                # told with the repeated header
            out.append(IniProblem(
                ini.path, number, section, key,
                f"given again: {value!r} is ignored, the first value "
                f"{places[0][0]!r} (line {places[0][1]}) is used"))
    for name, number in ini.headers:
        first = ini.section_lines[name]
        if number == first or section_kind(name) is None:
            continue
        keys = ignored.get(number, [])
        shown = ", ".join(keys[:6]) + (" ..." if len(keys) > 6 else "")
        lost = f"; ignored here: {shown}" if keys else ""
        out.append(IniProblem(
            ini.path, number, name, None,
            f"section given again (first at line {first}): its copies "
            f"are merged, and a key given in both keeps its first "
            f"value{lost}"))
    return out


def _joints(ini: IniFile) -> Optional[int]:
    try:
        return int(str(ini.get("KINS", "JOINTS")).strip())
    except ValueError:
        return None


def _joint_counts(ini: IniFile) -> list[IniProblem]:
    out: list[IniProblem] = []
    njoints = _joints(ini)
    if njoints is None:
        return out                      # motion's own check says why
    line = ini.line("KINS", "JOINTS")
    if njoints > MAX_JOINTS:
        return [IniProblem(ini.path, line, "KINS", "JOINTS",
                           f"[KINS]JOINTS = {njoints} is more than "
                           f"{MAX_JOINTS}, the most motion has")]
    numbers = sorted(int(m.group(2)) for m in map(_NUMBERED.match,
                                                  ini.section_lines)
                     if m and m.group(1) == "JOINT")
    for n in numbers:
        if n >= njoints:
            out.append(IniProblem(
                ini.path, ini.line(f"JOINT_{n}"), f"JOINT_{n}", None,
                f"joint {n} is beyond [KINS]JOINTS = {njoints} (line "
                f"{line}): this section is not used"))
    for n in range(njoints):
        if n not in numbers:
            out.append(IniProblem(
                ini.path, line, "KINS", "JOINTS",
                f"[KINS]JOINTS = {njoints} but [JOINT_{n}] is missing"))
    kins = str(ini.get("KINS", "KINEMATICS") or "").split()
    if kins and kins[0] == "trivkins":
        for word in kins[1:]:
            if word.lower().startswith("coordinates="):
                letters = [c for c in word.partition("=")[2]
                           if c.isalpha()]
                if len(letters) != njoints:
                    out.append(IniProblem(
                        ini.path, line, "KINS", "JOINTS",
                        f"[KINS]JOINTS = {njoints} but [KINS]KINEMATICS "
                        f"'{word}' has {len(letters)} joints"))
    return out


def check_ini(ini: IniFile, used: Optional[Mapping[str, set[str]]] = None
              ) -> list[IniProblem]:
    """Every problem of the INI file, in line order.  ``used``: the keys
    that the HAL files use, by section (default: :func:`hal_references`
    of the file's HAL files)."""
    if used is None:
        used = hal_references(ini)
    found = _unknown_keys(ini, used) + _repeats(ini) + _joint_counts(ini)
    return sorted(found, key=lambda p: (p.line, p.section, p.key or ""))


_JOINT_PIN = re.compile(r"joint\.(\d+)\.")


def check_hal_joints(ini: IniFile, hal: Any) -> list[IniProblem]:
    """After the HAL files loaded the motion module: ``[KINS]JOINTS``
    against the joints it has (``joint.N.`` pins) and the ``joint.N.``
    pins that the HAL files wire for ``N >= JOINTS``."""
    njoints = _joints(ini)
    if njoints is None:
        return []
    pins = hal.pins("joint.*")
    have: set[int] = set()
    wired: dict[int, list[str]] = {}
    for pin in pins:
        m = _JOINT_PIN.match(pin.name)
        if not m:
            continue
        n = int(m.group(1))
        have.add(n)
        signal = pin.signal
        if n >= njoints and signal is not None:
            wired.setdefault(n, []).append(f"{pin.name} ({signal.name})")
    out = []
    line = ini.line("KINS", "JOINTS")
    if have and max(have) + 1 != njoints:
        out.append(IniProblem(
            ini.path, line, "KINS", "JOINTS",
            f"[KINS]JOINTS = {njoints} but the motion module has "
            f"{max(have) + 1} joints (its num_joints)"))
    for n, names in sorted(wired.items()):
        shown = ", ".join(names[:3]) + (" ..." if len(names) > 3 else "")
        out.append(IniProblem(
            ini.path, line, "KINS", "JOINTS",
            f"[KINS]JOINTS = {njoints} but the HAL files wire joint {n}: "
            f"{shown}"))
    return out
