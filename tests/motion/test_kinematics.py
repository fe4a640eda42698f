"""Kinematics modules: trivkins, corexykins, scarakins, lineardeltakins.

The load listings are compared with the reference's in
tests/golden/test_kins_listings.py.  The transforms are C functions that
each module exports (kinematicsForward, kinematicsInverse, ...); the tests
call them through ctypes at the addresses halsdk.core._core.symbol_address()
gives: round trips over each workspace, known points (some with the
reference's numbers), and points without a solution, which must give a
non-zero return and leave the output untouched (so no NaN ever comes out).
"""

from __future__ import annotations

import ctypes
import math
import random
from pathlib import Path

import pytest
from helpers import data_path, repo_path
from helpers.halcompile import compiled_on_path

import halsdk
from halsdk.core import _core

MOTION = data_path("motion")
AXES = "x y z a b c u v w".split()
MAX_JOINTS = 16
UNTOUCHED = 1234.5          # what the tests put in outputs beforehand
FLAGS_UNTOUCHED = 77


class EmcPose(ctypes.Structure):
    """components/motion/emcpose.h: tran.x y z, a b c, u v w."""
    _fields_ = [(n, ctypes.c_double) for n in AXES]


_D = ctypes.POINTER(ctypes.c_double)
_P = ctypes.POINTER(EmcPose)
_F = ctypes.POINTER(ctypes.c_ulong)
FWD = ctypes.CFUNCTYPE(ctypes.c_int, _D, _P, _F, _F)
INV = ctypes.CFUNCTYPE(ctypes.c_int, _P, _D, _F, _F)
HOME = ctypes.CFUNCTYPE(ctypes.c_int, _P, _D, _F, _F)
TYPE = ctypes.CFUNCTYPE(ctypes.c_int)
SWITCH = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_int)

IDENTITY, FORWARD_ONLY, INVERSE_ONLY, BOTH = 1, 2, 3, 4


class Kins:
    """The functions of the loaded kinematics module."""

    def __init__(self) -> None:
        def sym(name: str, proto):
            addr = _core.symbol_address(name)
            assert addr, f"{name} is not exported"
            return proto(addr)

        self._fwd = sym("kinematicsForward", FWD)
        self._inv = sym("kinematicsInverse", INV)
        self._home = sym("kinematicsHome", HOME)
        self.type = sym("kinematicsType", TYPE)
        self.switchable = sym("kinematicsSwitchable", TYPE)
        self.switch = sym("kinematicsSwitch", SWITCH)

    def fwd(self, joints, fflags: int = 0):
        """-> (return value, the nine axes, inverse flags)"""
        j = (ctypes.c_double * MAX_JOINTS)(*joints)
        pose = EmcPose(*[UNTOUCHED] * 9)
        ff, fi = ctypes.c_ulong(fflags), ctypes.c_ulong(FLAGS_UNTOUCHED)
        r = self._fwd(j, ctypes.byref(pose), ctypes.byref(ff),
                      ctypes.byref(fi))
        return r, [getattr(pose, n) for n in AXES], fi.value

    def inv(self, pose, iflags: int = 0):
        """-> (return value, the 16 joints, forward flags)"""
        p = EmcPose(*pose, *[0.0] * (9 - len(pose)))
        j = (ctypes.c_double * MAX_JOINTS)(*[UNTOUCHED] * MAX_JOINTS)
        fi, ff = ctypes.c_ulong(iflags), ctypes.c_ulong(FLAGS_UNTOUCHED)
        r = self._inv(ctypes.byref(p), j, ctypes.byref(fi), ctypes.byref(ff))
        return r, list(j), ff.value

    def home(self, joints):
        j = (ctypes.c_double * MAX_JOINTS)(*joints)
        pose = EmcPose(*[UNTOUCHED] * 9)
        ff, fi = ctypes.c_ulong(5), ctypes.c_ulong(5)
        r = self._home(ctypes.byref(pose), j, ctypes.byref(ff),
                       ctypes.byref(fi))
        return r, [getattr(pose, n) for n in AXES]


def load(hal, name: str, *args: str) -> Kins:
    hal.loadrt(name, *args)
    return Kins()


def close(a, b, rel=1e-9) -> bool:
    return all(abs(x - y) <= rel * max(1.0, abs(x), abs(y))
               for x, y in zip(a, b))


def test_only_one_kinematics_module_at_a_time(hal):
    hal.loadrt("trivkins")
    with pytest.raises(halsdk.HalError,
                       match="already exported by module .trivkins."):
        hal.loadrt("corexykins")
    hal.unloadrt("trivkins")
    assert _core.symbol_address("kinematicsForward") == 0
    k = load(hal, "corexykins")
    assert k.type() == BOTH


# ----------------------------------------------------------------- trivkins

def test_trivkins_default_is_identity_over_nine_axes(hal):
    k = load(hal, "trivkins")
    assert k.type() == IDENTITY
    assert k.switchable() == 0 and k.switch(1) == 0
    j = [float(n + 1) for n in range(9)]
    r, pose, iflags = k.fwd(j)
    assert (r, pose, iflags) == (0, j, FLAGS_UNTOUCHED)
    r, joints, _ = k.inv(j)
    assert r == 0
    assert joints[:9] == j
    assert joints[9:] == [UNTOUCHED] * 7      # only the mapped joints
    assert k.home(j) == (0, j)


def test_trivkins_gantry_duplicates(hal):
    k = load(hal, "trivkins", "coordinates=xyyz", "kinstype=b")
    assert k.type() == BOTH
    # both y joints follow Y; the axis reads the first of them
    r, joints, _ = k.inv([10, 20, 30])
    assert r == 0
    assert joints[:4] == [10, 20, 20, 30]
    assert joints[4] == UNTOUCHED
    r, pose, _ = k.fwd([1, 2, 3, 4])
    assert r == 0
    assert pose == [1, 2, 4, 0, 0, 0, 0, 0, 0]   # unnamed axes are 0


def test_trivkins_letters_in_any_order_and_case(hal):
    k = load(hal, "trivkins", "coordinates=ZxC")
    r, pose, _ = k.fwd([1, 2, 3])
    assert r == 0
    assert pose == [2, 0, 1, 0, 0, 3, 0, 0, 0]
    r, joints, _ = k.inv([4, 5, 6, 7, 8, 9, 10, 11, 12])
    assert joints[:4] == [6, 4, 9, UNTOUCHED]


def test_trivkins_sixteen_joints(hal):
    k = load(hal, "trivkins", "coordinates=xyzabcuvwxyzabcu")
    r, joints, _ = k.inv(list(range(1, 10)))
    assert r == 0
    assert joints == [1, 2, 3, 4, 5, 6, 7, 8, 9, 1, 2, 3, 4, 5, 6, 7]


@pytest.mark.parametrize("word, kind", [
    ("1", IDENTITY), ("b", BOTH), ("B", BOTH), ("both", BOTH),
    ("f", FORWARD_ONLY), ("F", FORWARD_ONLY), ("i", INVERSE_ONLY),
    ("I", INVERSE_ONLY)])
def test_trivkins_kinstype(hal, word, kind):
    assert load(hal, "trivkins", f"kinstype={word}").type() == kind


@pytest.mark.parametrize("arg, reason", [
    ("coordinates=xyzq", r"'q' \(joint 3\) is not an axis letter"),
    ("coordinates=x1", r"'1' \(joint 1\) is not an axis letter"),
    ("coordinates=", "coordinates= is empty"),
    ("coordinates=xyzabcuvwxyzabcuvw", "names 18 joints, at most 16"),
    ("kinstype=z", "kinstype=z is not a kinematics type"),
    ("kinstype=identityx", "kinstype=identityx is not"),
])
def test_trivkins_refuses_bad_parameters(hal, arg, reason):
    with pytest.raises(halsdk.HalError, match=reason):
        hal.loadrt("trivkins", arg)
    assert _core.symbol_address("kinematicsForward") == 0
    load(hal, "trivkins")                   # and nothing is left behind


# --------------------------------------------------------------- corexykins

def test_corexykins_known_points_and_pass_through(hal):
    k = load(hal, "corexykins")
    assert k.type() == BOTH and k.switchable() == 0
    r, pose, _ = k.fwd([10, 4, 3, 4, 5, 6, 7, 8, 9])
    assert r == 0
    assert pose == [7, 3, 3, 4, 5, 6, 7, 8, 9]
    r, joints, _ = k.inv([7, 3, 3, 4, 5, 6, 7, 8, 9])
    assert joints[:10] == [10, 4, 3, 4, 5, 6, 7, 8, 9, UNTOUCHED]
    # only motor 0 turns: the head moves diagonally
    assert k.fwd([2, 0, 0])[1][:2] == [1, 1]


def test_corexykins_round_trips(hal):
    k = load(hal, "corexykins")
    rnd = random.Random(6)
    for _ in range(300):
        p = [rnd.uniform(-500, 500) for _ in range(9)]
        r, joints, _ = k.inv(p)
        assert r == 0
        r, back, _ = k.fwd(joints)
        assert r == 0 and close(back, p)
        j = [rnd.uniform(-500, 500) for _ in range(9)]
        assert close(k.inv(k.fwd(j)[1])[1][:9], j)


# ---------------------------------------------------------------- scarakins

D = {"D1": 490.0, "D2": 340.0, "D3": 50.0, "D4": 250.0, "D5": 50.0,
     "D6": 50.0}


def scara_fwd(j, d=D):
    """The model of the man page, in Python."""
    a0, a1 = math.radians(j[0]), math.radians(j[0] + j[1])
    c = j[0] + j[1] + j[3]
    return [d["D2"] * math.cos(a0) + d["D4"] * math.cos(a1)
            + d["D6"] * math.cos(math.radians(c)),
            d["D2"] * math.sin(a0) + d["D4"] * math.sin(a1)
            + d["D6"] * math.sin(math.radians(c)),
            d["D1"] + d["D3"] - d["D5"] - j[2], j[4], j[5], c, 0, 0, 0]


def test_scarakins_known_points(hal):
    k = load(hal, "scarakins")
    assert k.type() == BOTH and k.switchable() == 1
    # fully stretched along X, then along Y
    r, pose, _ = k.fwd([0, 0, 0, 0, 0, 0])
    assert r == 0 and close(pose, [640, 0, 490, 0, 0, 0, 0, 0, 0])
    r, pose, _ = k.fwd([90, 0, 0, 0, 0, 0])
    assert close(pose, [0, 640, 490, 0, 0, 90, 0, 0, 0])
    # elbow at 90 degrees, tool turned back to heading 0
    r, pose, _ = k.fwd([0, 90, 10, -90, 0, 0])
    assert close(pose, [390, 250, 480, 0, 0, 0, 0, 0, 0])
    # the reference's numbers for joints 1..6
    r, pose, _ = k.fwd([1, 2, 3, 4, 5, 6])
    assert close(pose[:6], [639.23290762388262, 25.111274419669726, 487,
                            5, 6, 7], 1e-12)
    # and back from full stretch
    r, joints, _ = k.inv([640, 0, 490, 0, 0, 0])
    assert r == 0
    assert all(abs(v) < 1e-5 for v in joints[:6])
    assert joints[6:] == [UNTOUCHED] * 10


def test_scarakins_forward_inverse_round_trip_over_workspace(hal):
    k = load(hal, "scarakins")
    rnd = random.Random(61)
    for _ in range(400):
        # a wrist centre between the inner and outer reach, any heading
        rad, t = rnd.uniform(95, 585), rnd.uniform(-math.pi, math.pi)
        c = rnd.uniform(-400, 400)
        p = [rad * math.cos(t) + 50 * math.cos(math.radians(c)),
             rad * math.sin(t) + 50 * math.sin(math.radians(c)),
             rnd.uniform(200, 500), rnd.uniform(-90, 90),
             rnd.uniform(-90, 90), c]
        for elbow in (0, 1):
            r, joints, fflags = k.inv(p, iflags=elbow)
            assert r == 0, p
            assert fflags == 0
            assert (joints[1] < 0) == (elbow == 1)
            assert -180 < joints[0] <= 180
            r, back, iflags = k.fwd(joints)
            assert r == 0
            assert iflags == elbow          # the flag keeps the elbow
            assert close(back, p + [0, 0, 0]), (p, back)


def test_scarakins_inverse_forward_round_trip(hal):
    k = load(hal, "scarakins")
    rnd = random.Random(62)
    for _ in range(400):
        # unique where the inner arm stays in (-180, 180] and the elbow
        # is bent (its side then comes back through the flag)
        j = [rnd.uniform(-170, 170),
             rnd.choice((-1, 1)) * rnd.uniform(2, 170),
             rnd.uniform(-50, 300), rnd.uniform(-720, 720),
             rnd.uniform(-90, 90), rnd.uniform(-90, 90)]
        r, pose, iflags = k.fwd(j)
        assert r == 0
        assert close(pose, scara_fwd(j), 1e-12)
        r, back, _ = k.inv(pose, iflags)
        assert r == 0
        assert close(back[:6], j), (j, back[:6])


def test_scarakins_follows_its_pins(hal):
    k = load(hal, "scarakins")
    d = dict(D, D2=300.0, D6=-20.0, D5=0.0)
    for name, value in d.items():
        hal.setp(f"scarakins.{name}", value)
    j = [10, 20, 5, 30, 0, 0]
    r, pose, _ = k.fwd(j)
    assert close(pose, scara_fwd(j, d), 1e-12)
    r, back, _ = k.inv(pose)
    assert r == 0 and close(back[:6], j)


@pytest.mark.parametrize("pose", [
    [2000, 0, 490, 0, 0, 0],          # beyond the outer reach
    [0, 0, 490, 0, 0, 0],             # wrist inside the inner reach
    [float("nan"), 0, 490, 0, 0, 0],
    [400, 0, float("inf"), 0, 0, 0],
    [400, 0, 490, 0, 0, float("nan")],
])
def test_scarakins_unreachable_poses_fail_cleanly(hal, pose):
    k = load(hal, "scarakins")
    r, joints, fflags = k.inv(pose)
    assert r != 0
    assert joints == [UNTOUCHED] * MAX_JOINTS
    assert fflags == FLAGS_UNTOUCHED


def test_scarakins_bad_arms_and_joints_fail_cleanly(hal):
    k = load(hal, "scarakins")
    r, pose, _ = k.fwd([float("nan"), 0, 0, 0, 0, 0])
    assert r != 0 and pose == [UNTOUCHED] * 9
    hal.setp("scarakins.D4", 0.0)
    assert k.inv([300, 0, 490, 0, 0, 0])[0] != 0
    hal.setp("scarakins.D4", float("nan"))
    r, joints, _ = k.inv([300, 0, 490, 0, 0, 0])
    assert r != 0 and joints == [UNTOUCHED] * MAX_JOINTS


def test_scarakins_switches_to_identity_and_user_types(hal):
    k = load(hal, "scarakins", "coordinates=zyx")

    def is_(n):
        return [hal.getp(f"kinstype.is-{i}") for i in range(3)] == [
            i == n for i in range(3)]

    assert is_(0)
    assert k.switch(1) == 0 and is_(1)
    r, pose, _ = k.fwd([1, 2, 3])
    assert r == 0 and pose[:3] == [3, 2, 1]
    assert k.inv([7, 8, 9])[1][:4] == [9, 8, 7, UNTOUCHED]
    assert k.switch(2) == 0 and is_(2)
    k.fwd([1, 2, 3])
    k.fwd([1, 2, 3])
    k.inv([1, 2, 3])
    assert (hal.getp("userk.fct"), hal.getp("userk.ict")) == (2, 1)
    assert k.switch(3) == -1 and is_(2)      # refused, nothing changes
    assert k.switch(-1) == -1 and is_(2)
    assert k.switch(0) == 0 and is_(0)
    assert close(k.fwd([0, 0, 0, 0, 0, 0])[1], [640, 0, 490] + [0] * 6)


@pytest.mark.parametrize("arg, reason", [
    ("coordinates=xyy", "letter Y is given twice"),
    ("coordinates=xyzabcu", "names 7 joints, at most 6"),
    ("coordinates=xyq", "'q' .* is not an axis letter"),
])
def test_scarakins_refuses_bad_coordinates(hal, arg, reason):
    # the reference prints an error and loads anyway; we refuse
    with pytest.raises(halsdk.HalError, match=reason):
        hal.loadrt("scarakins", arg)


# ---------------------------------------------------------- lineardeltakins

R, L = 130.25, 269.0


def test_lineardeltakins_known_points(hal):
    k = load(hal, "lineardeltakins")
    assert k.type() == BOTH and k.switchable() == 0
    h = math.sqrt(L * L - R * R)
    r, joints, _ = k.inv([0, 0, 0, 1, 2, 3, 4, 5, 6])
    assert r == 0
    assert close(joints[:9], [h, h, h, 1, 2, 3, 4, 5, 6])
    assert close([h], [235.3634158062803])           # the reference's
    r, pose, _ = k.fwd([h + 10, h + 10, h + 10, 1, 2, 3, 4, 5, 6])
    assert r == 0 and close(pose, [0, 0, 10, 1, 2, 3, 4, 5, 6])
    # which carriage is which: the reference's numbers
    r, joints, _ = k.inv([-37.17434044157503, 22.14937349292589,
                          34.31438605576409])
    assert close(joints[:3], [277.81658925218682, 277.26494123210853,
                              239.86714881464391], 1e-12)
    # right under tower 0 at (0, R): its rod hangs straight down
    r, joints, _ = k.inv([0, R, -50])
    assert close([joints[0]], [-50 + L])


def test_lineardeltakins_round_trips_over_workspace(hal):
    k = load(hal, "lineardeltakins")
    rnd = random.Random(63)
    for _ in range(400):
        rad, t = 100 * math.sqrt(rnd.random()), rnd.uniform(0, 2 * math.pi)
        p = [rad * math.cos(t), rad * math.sin(t), rnd.uniform(-200, 200)] \
            + [rnd.uniform(-50, 50) for _ in range(6)]
        r, joints, _ = k.inv(p)
        assert r == 0
        r, back, _ = k.fwd(joints)
        assert r == 0
        assert close(back, p), (p, back)
        r, again, _ = k.inv(back)
        assert close(again[:9], joints[:9])


def test_lineardeltakins_follows_its_pins(hal):
    k = load(hal, "lineardeltakins")
    hal.setp("lineardeltakins.R", 100.0)
    hal.setp("lineardeltakins.L", 200.0)
    r, joints, _ = k.inv([0, 0, 0])
    assert close(joints[:3], [math.sqrt(200**2 - 100**2)] * 3)
    assert close(k.fwd(joints)[1][:3], [0, 0, 0])


@pytest.mark.parametrize("pose", [
    [300, 0, 0], [0, -250, 0], [float("nan"), 0, 0], [0, 0, float("inf")],
])
def test_lineardeltakins_unreachable_poses_fail_cleanly(hal, pose):
    k = load(hal, "lineardeltakins")
    r, joints, _ = k.inv(pose)
    assert r != 0 and joints == [UNTOUCHED] * MAX_JOINTS


@pytest.mark.parametrize("joints", [
    [500, 0, 0],                       # carriages too far apart
    [0, 0, 1000],
    [float("nan"), 0, 0],
])
def test_lineardeltakins_impossible_joints_fail_cleanly(hal, joints):
    k = load(hal, "lineardeltakins")
    r, pose, _ = k.fwd(joints)
    assert r != 0 and pose == [UNTOUCHED] * 9


def test_lineardeltakins_bad_geometry_fails_cleanly(hal):
    k = load(hal, "lineardeltakins")
    hal.setp("lineardeltakins.L", 0.0)
    r, joints, _ = k.inv([0, 0, 0])
    assert r != 0 and joints == [UNTOUCHED] * MAX_JOINTS
    hal.setp("lineardeltakins.L", L)
    hal.setp("lineardeltakins.R", float("nan"))
    r, pose, _ = k.fwd([235, 235, 235])
    assert r != 0 and pose == [UNTOUCHED] * 9


# ------------------------------------- the examples of docs/kinematics.rst

DOC = repo_path("docs", "kinematics.rst")


def _doc_block(caption_or_lang: str) -> str:
    """The first code block of the docs with that caption or language."""
    lines = DOC.read_text().splitlines()
    for n, line in enumerate(lines):
        if line.startswith(".. code-block::") and (
                line.endswith(caption_or_lang)
                or lines[n + 1].strip() == f":caption: {caption_or_lang}"):
            body = []
            for text in lines[n + 1:]:
                if text and not text.startswith("   "):
                    break
                if not text.strip().startswith(":caption:"):
                    body.append(text[3:])
            return "\n".join(body).strip("\n") + "\n"
    raise AssertionError(f"no code block {caption_or_lang} in {DOC}")


@pytest.fixture
def skewkins_dir(tmp_path: Path):
    (tmp_path / "skewkins.c").write_text(_doc_block("skewkins.c"))
    # kinematics.h and emcpose.h are installed headers: no -I needed
    with compiled_on_path(tmp_path, "--extra-compile-args", "-Wall -Werror",
                          "skewkins.c"):
        yield tmp_path


def test_doc_example_module_builds_and_transforms(hal, skewkins_dir):
    k = load(hal, "skewkins")
    assert k.type() == BOTH and k.switchable() == 0
    hal.setp("skewkins.angle", 0.5)
    rnd = random.Random(64)
    for _ in range(50):
        p = [rnd.uniform(-300, 300) for _ in range(3)]
        r, joints, _ = k.inv(p)
        assert r == 0
        assert close(k.fwd(joints)[1][:3], p)
    s = math.sin(math.radians(0.5))
    assert close(k.fwd([0, 100, 0])[1][:2], [100 * s, 100 * math.cos(
        math.radians(0.5))])
    hal.setp("skewkins.angle", 90.0)
    r, joints, _ = k.inv([1, 2, 3])
    assert r != 0 and joints == [UNTOUCHED] * MAX_JOINTS


def test_doc_python_example_runs(hal, capsys):
    exec(_doc_block("python"), {"hal": hal})
    rc, joints = capsys.readouterr().out.split(" ", 1)
    assert rc == "0"
    assert joints.startswith("[235.36341580628")
