"""The Python side of the motion protocol equals the C headers.

components/motion/channel.h (with homing.h, mot_joint.h and freeplan.h)
is the one source of the protocol's numbers: halsdk.motion._channel
takes them from the headers when it is compiled and
halsdk.motion.protocol names them.  These tests read the headers' text
and check that every name of each enum or #define group is in the
matching Python enum, with the compiled value, and nothing more.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest
from helpers import repo_path

from halsdk import motion
from halsdk.motion import _channel, protocol

HEADERS = repo_path("components", "motion")


def _text(name: str) -> str:
    """A header without its comments."""
    text = (HEADERS / name).read_text(encoding="utf-8")
    return re.sub(r"/\*.*?\*/", "", text, flags=re.S)


def _enum(header: str, name: str) -> dict[str, int]:
    m = re.search(r"enum " + name + r" \{(.*?)\};", _text(header),
                  re.S)
    assert m, f"enum {name} not found in {header}"
    return {k: int(v, 0) for k, v in
            re.findall(r"(\w+)\s*=\s*(-?\w+)", m.group(1))}


def _defines(header: str, prefix: str) -> dict[str, int]:
    return {k: int(v, 0) for k, v in re.findall(
        r"#define (" + prefix + r"\w*)\s+\(?(-?(?:0x)?[0-9a-fA-F]+)u?\)?",
        _text(header))}


def _strip(values: dict[str, int], prefix: str, skip=()) -> dict[str, int]:
    return {k[len(prefix):]: v for k, v in values.items() if k not in skip}


CMD_EXTRA = ("MOT_CMD_NONE", "MOT_CMD_RESERVED_FIRST",
             "MOT_CMD_RESERVED_LAST", "MOT_CMD_LAST")

CASES = [
    ("Cmd", _strip(_enum("channel.h", "mot_cmd"), "MOT_CMD_", CMD_EXTRA)),
    ("Echo", _strip(_enum("channel.h", "mot_echo"), "MOT_ECHO_")),
    ("Mode", _strip(_enum("channel.h", "mot_mode"), "MOT_MODE_")),
    ("TermCond", _strip(_enum("channel.h", "mot_term"), "MOT_TERM_")),
    ("MotionType", _strip(_enum("channel.h", "mot_motion_type"),
                          "MOT_MOTION_")),
    ("KinsType", _strip(_enum("channel.h", "mot_kins_type"), "MOT_KINS_")),
    ("OrientState", _strip(_enum("channel.h", "mot_orient_state"),
                           "MOT_ORIENT_")),
    ("Profile", _strip(_enum("freeplan.h", "fp_profile"), "FP_")),
    ("ProbeFlag", _strip(_defines("channel.h", "MOT_PROBE_"),
                         "MOT_PROBE_")),
    ("HomeFlag", _strip(_defines("homing.h", "HOME_"), "HOME_",
                        ("HOME_SEQUENCE_NONE",))),
    ("JointFlag", _strip(_defines("mot_joint.h", "MOT_JOINT_"),
                         "MOT_JOINT_")),
]


@pytest.mark.parametrize("name, header", CASES, ids=[c[0] for c in CASES])
def test_python_enum_equals_the_header(name, header):
    assert header, f"nothing parsed for {name}"
    enum_cls = getattr(protocol, name)
    assert {m.name: m.value for m in enum_cls} == header
    assert getattr(motion, name) is enum_cls      # exported as it is


def test_scalars_equal_the_header():
    cmd = _enum("channel.h", "mot_cmd")
    assert protocol.CMD_LAST == cmd["MOT_CMD_LAST"]
    assert all(v < protocol.CMD_LAST for v in protocol.Cmd)
    homing = _defines("homing.h", "HOME_SEQUENCE_NONE")
    assert protocol.HOME_SEQUENCE_NONE == homing["HOME_SEQUENCE_NONE"]
    assert motion.HOME_SEQUENCE_NONE == protocol.HOME_SEQUENCE_NONE


def test_values_come_from_the_compiled_extension():
    """protocol holds no number of its own: each enum is the dict that
    the extension compiled from the headers."""
    pairs = {"Cmd": _channel.CMD, "Echo": _channel.ECHO,
             "Mode": _channel.MODE, "TermCond": _channel.TERM,
             "MotionType": _channel.MOTION_TYPE,
             "KinsType": _channel.KINS_TYPE,
             "OrientState": _channel.ORIENT_STATE,
             "Profile": _channel.PROFILE, "ProbeFlag": _channel.PROBE,
             "HomeFlag": _channel.HOME_FLAGS,
             "JointFlag": _channel.JOINT_FLAGS}
    assert set(pairs) == {c[0] for c in CASES}
    for name, values in pairs.items():
        enum_cls = getattr(protocol, name)
        assert {m.name: m.value for m in enum_cls} == values, name
    tree = ast.parse(Path(protocol.__file__).read_text(encoding="utf-8"))
    numbers = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)
               and isinstance(n.value, (int, float))]
    assert numbers == [], "halsdk/motion/protocol.py must not type numbers"


DICTS = {"Cmd": "CMD", "Echo": "ECHO", "Mode": "MODE", "TermCond": "TERM",
         "MotionType": "MOTION_TYPE", "KinsType": "KINS_TYPE",
         "OrientState": "ORIENT_STATE", "Profile": "PROFILE",
         "ProbeFlag": "PROBE", "HomeFlag": "HOME_FLAGS",
         "JointFlag": "JOINT_FLAGS"}


def _declared() -> dict[str, list[tuple[str, ast.expr]]]:
    """The member names written in each enum class of protocol.py (what a
    type checker sees), with the expression each one is given."""
    tree = ast.parse(Path(protocol.__file__).read_text(encoding="utf-8"))
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            out[node.name] = [
                (t.id, stmt.value) for stmt in node.body
                if isinstance(stmt, ast.Assign) for t in stmt.targets
                if isinstance(t, ast.Name)]
    return out


def test_declared_names_are_exactly_the_header():
    """The names listed in protocol.py are the header's: none missing,
    none extra, none twice (both directions, so the members a type
    checker sees are the members the enum has)."""
    declared = _declared()
    assert set(declared) == {c[0] for c in CASES} == set(DICTS)
    for name, header in CASES:
        names = [n for n, _ in declared[name]]
        assert len(names) == len(set(names)), f"{name}: a name twice"
        missing = set(header) - set(names)
        extra = set(names) - set(header)
        assert not missing, f"{name}: not declared in protocol.py: {missing}"
        assert not extra, f"{name}: not in the header: {extra}"


def test_each_declared_member_reads_its_own_name():
    """NAME = _channel.<DICT>["NAME"]: the value of every member is looked
    up under its own name in the extension's dict of its group."""
    for cls, members in _declared().items():
        for name, value in members:
            assert ast.unparse(value) == \
                f"_channel.{DICTS[cls]}[{name!r}]", f"{cls}.{name}"
