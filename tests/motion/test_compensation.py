"""Backlash and lead-screw compensation of the motion controller
(components/motion/mot_comp.c, through ctypes from a library built here)
and the compensation file reader (halsdk.motion.screwcomp)."""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest
from helpers.freeplan import DPTR, Freeplan, build_library

from halsdk.errors import HalError
from halsdk.motion.screwcomp import (
    COMP_SIZE,
    CompFileError,
    parse_comp,
    read_comp_file,
)

EINVAL = 22
REL = 1e-9

RUNNER = r"""
#include <stddef.h>
#include "mot_comp.h"
size_t mot_comp_sizeof(void) { return sizeof(mot_comp_t); }
/* n cycles; pos and vel are the commanded joint motion */
void mot_comp_run(mot_comp_t *c, int n, const double *pos,
                  const double *vel, double dt, double vmax, double amax,
                  double *corr, double *filt, double *fvel)
{
    int i;
    for (i = 0; i < n; i++)
        mot_comp_update(c, pos[i], vel[i], dt, vmax, amax,
                        &corr[i], &filt[i], &fvel[i]);
}
"""


class Entry(ctypes.Structure):
    _fields_ = [("nominal", ctypes.c_double),
                ("fwd_trim", ctypes.c_double),
                ("rev_trim", ctypes.c_double)]


class Comp(ctypes.Structure):
    _fields_ = [("entries", ctypes.c_int),
                ("table", Entry * 256),
                ("backlash", ctypes.c_double),
                ("dir", ctypes.c_int),
                ("corr", ctypes.c_double),
                ("filt", Freeplan)]


@pytest.fixture(scope="session")
def lib(tmp_path_factory):
    so = build_library(str(tmp_path_factory.mktemp("motcomp")),
                       ["freeplan.c", "mot_comp.c"], RUNNER)
    lib = ctypes.CDLL(so)
    cp = ctypes.POINTER(Comp)
    lib.mot_comp_sizeof.restype = ctypes.c_size_t
    lib.mot_comp_init.argtypes = [cp]
    lib.mot_comp_clear.argtypes = [cp]
    lib.mot_comp_add.argtypes = [cp, ctypes.c_double, ctypes.c_double,
                                 ctypes.c_double, ctypes.c_char_p,
                                 ctypes.c_int]
    lib.mot_comp_add.restype = ctypes.c_int
    lib.mot_comp_set_backlash.argtypes = [cp, ctypes.c_double,
                                          ctypes.c_char_p, ctypes.c_int]
    lib.mot_comp_set_backlash.restype = ctypes.c_int
    lib.mot_comp_lookup.argtypes = [cp, ctypes.c_double, ctypes.c_int]
    lib.mot_comp_lookup.restype = ctypes.c_double
    lib.mot_comp_update.argtypes = [cp] + [ctypes.c_double] * 5 + [DPTR] * 3
    lib.mot_comp_run.argtypes = [cp, ctypes.c_int, DPTR, DPTR,
                                 ctypes.c_double, ctypes.c_double,
                                 ctypes.c_double, DPTR, DPTR, DPTR]
    assert lib.mot_comp_sizeof() == ctypes.sizeof(Comp)
    return lib


class Joint:
    def __init__(self, lib):
        self.lib = lib
        self.c = Comp()
        lib.mot_comp_init(ctypes.byref(self.c))

    def add(self, nominal, fwd, rev):
        why = ctypes.create_string_buffer(200)
        r = self.lib.mot_comp_add(ctypes.byref(self.c), nominal, fwd, rev,
                                  why, len(why))
        return r, why.value.decode()

    def backlash(self, value):
        why = ctypes.create_string_buffer(200)
        r = self.lib.mot_comp_set_backlash(ctypes.byref(self.c), value, why,
                                           len(why))
        return r, why.value.decode()

    def lookup(self, pos, direction):
        return self.lib.mot_comp_lookup(ctypes.byref(self.c), pos, direction)

    def run(self, pos, vel, dt=1e-3, vmax=10.0, amax=100.0):
        pos = np.ascontiguousarray(pos, dtype=float)
        vel = np.ascontiguousarray(vel, dtype=float)
        n = len(pos)
        out = [np.empty(n) for _ in range(3)]
        self.lib.mot_comp_run(ctypes.byref(self.c), n,
                              pos.ctypes.data_as(DPTR),
                              vel.ctypes.data_as(DPTR), dt, vmax, amax,
                              *(o.ctypes.data_as(DPTR) for o in out))
        return out

    def hold(self, pos, n, vel=0.0, **kw):
        return self.run(np.full(n, pos), np.full(n, vel), **kw)


TABLE = [(-10.0, 0.010, -0.020), (0.0, 0.002, -0.003),
         (5.0, 0.004, 0.001), (20.0, -0.006, -0.012)]


def filled(lib, table=TABLE):
    j = Joint(lib)
    for e in table:
        assert j.add(*e) == (0, "")
    return j


# ---------------------------------------------------------------- table

def test_lookup_is_exact_at_nodes_and_linear_between(lib):
    j = filled(lib)
    nom = np.array([e[0] for e in TABLE])
    fwd = np.array([e[1] for e in TABLE])
    rev = np.array([e[2] for e in TABLE])
    for n, f, r in TABLE:
        assert j.lookup(n, 1) == f
        assert j.lookup(n, -1) == r
        assert j.lookup(n, 0) == pytest.approx((f + r) / 2, abs=1e-18)
    for x in np.linspace(-10, 20, 301):
        assert j.lookup(x, 1) == pytest.approx(np.interp(x, nom, fwd),
                                               abs=1e-15)
        assert j.lookup(x, -1) == pytest.approx(np.interp(x, nom, rev),
                                                abs=1e-15)
    # outside the table: the end values
    assert j.lookup(-1e6, 1) == 0.010 and j.lookup(-10.5, -1) == -0.020
    assert j.lookup(20.001, 1) == -0.006 and j.lookup(1e9, -1) == -0.012
    # NaN is not a crash
    assert math.isfinite(j.lookup(float("nan"), 1))
    # an empty table corrects nothing
    assert Joint(lib).lookup(3.0, 1) == 0.0


def test_add_refuses_with_a_reason(lib):
    j = filled(lib)
    nan, inf = float("nan"), float("inf")
    for args, words in [((20.0, 0, 0), "greater"), ((19.0, 0, 0), "greater"),
                        ((nan, 0, 0), "nominal"), ((inf, 0, 0), "nominal"),
                        ((30.0, nan, 0), "trims"), ((30.0, 0, -inf), "trims")]:
        r, why = j.add(*args)
        assert r == -EINVAL
        assert words in why, why
    assert j.c.entries == len(TABLE)
    r, why = j.add(20.0, 0, 0)
    assert why == "entry 5: nominal position must be greater than the one " \
        "of entry 4"
    # a NULL reason buffer is allowed
    assert lib.mot_comp_add(ctypes.byref(j.c), nan, 0, 0, None, 0) == -EINVAL
    # the table holds 256 entries, no more
    k = Joint(lib)
    for i in range(256):
        assert k.add(float(i), 0.001 * i, -0.001 * i)[0] == 0
    r, why = k.add(1000.0, 0, 0)
    assert r == -EINVAL and "full" in why and "256" in why
    assert k.c.entries == 256
    assert k.lookup(255.0, 1) == pytest.approx(0.255)
    # cleared, it takes entries again from scratch
    lib.mot_comp_clear(ctypes.byref(k.c))
    assert k.c.entries == 0 and k.lookup(5.0, 1) == 0.0
    assert k.add(-3.0, 0.1, 0.2) == (0, "")


def test_backlash_value_is_checked(lib):
    j = Joint(lib)
    for bad in (-0.1, float("nan"), float("inf")):
        r, why = j.backlash(bad)
        assert r == -EINVAL and "backlash" in why
    assert j.backlash(0.02) == (0, "")
    assert j.c.backlash == 0.02


# ---------------------------------------------------------------- backlash

def takeup_time(dist, vmax, amax):
    dist = abs(dist)
    if dist >= vmax * vmax / amax:
        return dist / vmax + vmax / amax
    return 2 * math.sqrt(dist / amax)


def check_filter(filt, fvel, dt, vmax, amax):
    """The applied correction moves within its share of the limits."""
    vl, al = 0.5 * vmax, 0.5 * amax
    assert np.max(np.abs(fvel)) <= vl * (1 + REL)
    assert np.max(np.abs(np.diff(fvel)) / dt, initial=0) <= al * (1 + REL)
    eps = 8 * np.finfo(float).eps * (np.max(np.abs(filt)) + 1e-300)
    assert np.max(np.abs(np.diff(filt)) / dt) <= vl * (1 + REL) + eps / dt
    assert (np.max(np.abs(np.diff(filt, 2)) / dt**2, initial=0)
            <= al * (1 + REL) + 2 * eps / dt**2)


@pytest.mark.parametrize("dt", [1e-3, 25e-6])
def test_backlash_reversal_takes_up_within_the_limits(lib, dt):
    vmax, amax, b = 2.0, 20.0, 0.1
    j = Joint(lib)
    assert j.backlash(b) == (0, "")
    # before any motion the direction is unknown: no correction
    corr, filt, _ = j.hold(0.0, 5, dt=dt, vmax=vmax, amax=amax)
    assert np.all(corr == 0) and np.all(filt == 0) and j.c.dir == 0
    # moving positive: +b/2, taken up within the limits, exactly
    n = int(0.25 / dt)
    pos = np.arange(1, n + 1) * 0.5 * dt
    corr, filt, fvel = j.run(pos, np.full(n, 0.5), dt=dt, vmax=vmax,
                             amax=amax)
    assert np.all(corr == b / 2)
    assert filt[-1] == b / 2 and fvel[-1] == 0
    k = int(np.argmax(filt == b / 2)) + 1          # cycles to take up
    assert k * dt <= takeup_time(b / 2, vmax / 2, amax / 2) + dt * (1 + 1e-6)
    check_filter(np.concatenate([[0], filt]), np.concatenate([[0], fvel]),
                 dt, vmax, amax)
    # standing still keeps the direction and the correction
    corr, filt, fvel = j.hold(pos[-1], 10, dt=dt, vmax=vmax, amax=amax)
    assert np.all(corr == b / 2) and np.all(filt == b / 2) and j.c.dir == 1
    # reversing: the correction moves by the whole backlash
    back = pos[-1] - np.arange(1, n + 1) * 0.5 * dt
    corr, filt2, fvel2 = j.run(back, np.full(n, -0.5), dt=dt, vmax=vmax,
                               amax=amax)
    assert np.all(corr == -b / 2) and j.c.dir == -1
    assert filt2[-1] == -b / 2 and fvel2[-1] == 0
    assert np.all(np.diff(filt2) <= 0)
    k = int(np.argmax(filt2 == -b / 2)) + 1
    t_min = takeup_time(b, vmax / 2, amax / 2)
    assert k * dt <= t_min + dt * (1 + 1e-6)
    assert k * dt >= t_min - dt * (1 + 1e-6)
    check_filter(np.concatenate([[b / 2], filt2]),
                 np.concatenate([[0], fvel2]), dt, vmax, amax)


def test_reversal_while_taking_up(lib):
    """A reversal in the middle of a takeup turns the correction around
    without a velocity step."""
    dt, vmax, amax = 1e-3, 1.0, 10.0
    j = Joint(lib)
    j.backlash(0.2)
    filt_all, fvel_all = [np.zeros(1)], [np.zeros(1)]
    for sign, n in [(1, 40), (-1, 30), (1, 300)]:
        _, filt, fvel = j.hold(0.0, n, vel=sign * 0.1, dt=dt, vmax=vmax,
                               amax=amax)
        filt_all.append(filt)
        fvel_all.append(fvel)
    assert filt[-1] == 0.1
    check_filter(np.concatenate(filt_all), np.concatenate(fvel_all), dt,
                 vmax, amax)


def test_no_usable_limits_apply_the_correction_at_once(lib):
    j = Joint(lib)
    j.backlash(0.04)
    for vmax, amax in [(0.0, 10.0), (1.0, 0.0), (float("nan"), 1.0)]:
        corr, filt, fvel = j.hold(0.0, 1, vel=1.0, vmax=vmax, amax=amax)
        assert filt[0] == 0.02 and fvel[0] == 0
        corr, filt, fvel = j.hold(0.0, 1, vel=-1.0, vmax=vmax, amax=amax)
        assert filt[0] == -0.02


def test_nan_commands_keep_the_correction(lib):
    j = Joint(lib)
    j.backlash(0.04)
    j.hold(0.0, 100, vel=1.0)
    corr, filt, _ = j.run([float("nan")] * 3, [float("nan")] * 3)
    assert np.all(corr == 0.02) and np.all(filt == 0.02) and j.c.dir == 1
    # a bad dt does not move the filter
    out = [ctypes.c_double() for _ in range(3)]
    lib.mot_comp_update(ctypes.byref(j.c), 0.0, -1.0, float("nan"), 1.0,
                        1.0, *(ctypes.byref(o) for o in out))
    assert out[0].value == -0.02 and out[1].value == 0.02


# ---------------------------------------------------------------- screw

def test_screw_table_follows_position_and_direction(lib):
    """Moving along the table, the raw correction is the forward trim at
    the commanded position; reversing, the reverse trim.  The table
    replaces the backlash value."""
    dt, vmax, amax = 1e-3, 20.0, 200.0
    j = filled(lib)
    j.backlash(0.5)                      # not used with a table
    nom = np.array([e[0] for e in TABLE])
    fwd = np.array([e[1] for e in TABLE])
    rev = np.array([e[2] for e in TABLE])
    # before any motion: the mean of both trims
    corr, filt, _ = j.hold(-12.0, 3, vmax=vmax, amax=amax)
    assert corr[0] == pytest.approx((0.010 - 0.020) / 2)
    # sweep up at 5 units/s
    up = -12.0 + np.arange(1, 7001) * 5 * dt
    corr, filt, fvel = j.run(up, np.full(len(up), 5.0), dt=dt, vmax=vmax,
                             amax=amax)
    assert np.allclose(corr, np.interp(up, nom, fwd), atol=1e-15, rtol=0)
    # the applied correction follows closely while moving (slopes are
    # small) and exactly at rest
    assert np.max(np.abs(filt[100:] - corr[100:])) < 1e-4
    corr, filt2, _ = j.hold(up[-1], 200, vmax=vmax, amax=amax)
    assert filt2[-1] == corr[-1] == np.interp(up[-1], nom, fwd)
    # sweep down
    down = up[-1] - np.arange(1, 7001) * 5 * dt
    corr, filt3, fvel3 = j.run(down, np.full(len(down), -5.0), dt=dt,
                               vmax=vmax, amax=amax)
    assert np.allclose(corr, np.interp(down, nom, rev), atol=1e-15, rtol=0)
    check_filter(np.concatenate([filt, filt2, filt3]),
                 np.concatenate([fvel, np.zeros(200), fvel3]), dt, vmax,
                 amax)
    # at a node, at rest, exact
    j.hold(0.0, 300, vel=-1.0, vmax=vmax, amax=amax)
    corr, filt, _ = j.hold(0.0, 300, vmax=vmax, amax=amax)
    assert corr[-1] == -0.003 and filt[-1] == -0.003


def test_cleared_table_falls_back_to_backlash(lib):
    j = filled(lib)
    j.backlash(0.1)
    corr, _, _ = j.hold(0.0, 1, vel=1.0)
    assert corr[0] == 0.002
    lib.mot_comp_clear(ctypes.byref(j.c))
    corr, filt, _ = j.hold(0.0, 500, vel=1.0)
    assert corr[0] == 0.05 and filt[-1] == 0.05


# ---------------------------------------------------------------- file

def write(tmp_path, text, name="comp.txt"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_read_type_1_and_type_0(tmp_path):
    text = ("# X axis screw map\n"
            "\n"
            "-1.000 0.005 -0.005   # left end\n"
            "  0.000\t0.002 -0.003\n"
            "1.000 0.003 -0.004\n")
    path = write(tmp_path, text)
    assert read_comp_file(path, 1) == [(-1.0, 0.005, -0.005),
                                       (0.0, 0.002, -0.003),
                                       (1.0, 0.003, -0.004)]
    # type 0 holds actual positions: the trims are actual - nominal
    path0 = write(tmp_path, "-1.000 -1.005 -0.995\n0.000 0.002 -0.003\n"
                  "1.000 1.003 0.998\n", "t0.txt")
    got = read_comp_file(str(path0), 0)
    want = [(-1.0, -0.005, 0.005), (0.0, 0.002, -0.003), (1.0, 0.003, -0.002)]
    assert len(got) == 3
    for g, w in zip(got, want):
        assert g == pytest.approx(w, abs=1e-12)
    assert read_comp_file(write(tmp_path, "# nothing\n\n", "e.txt")) == []
    assert parse_comp("1e-3 2E-4 -3.5e-4") == [(1e-3, 2e-4, -3.5e-4)]


@pytest.mark.parametrize("text, line, words", [
    ("0 0 0\n1 0.1\n", 2, "expected 3 numbers"),
    ("0 0 0\n1 0.1 0.2 0.3\n", 2, "found 4 values"),
    ("0 0 0\n\n# c\n1 x 0\n", 4, "forward value 'x' is not a number"),
    ("zero 0 0\n", 1, "nominal value 'zero'"),
    ("0 0 0\n1 0 0\n1 0 0\n", 3, "not greater than 1.0 on line 2"),
    ("0 0 0\n-1 0 0\n", 2, "must increase"),
    ("0 nan 0\n", 1, "not a finite number"),
    ("0 0 inf\n", 1, "reverse value 'inf' is not a finite number"),
    ("0 0 0,1\n", 1, "not a number"),
])
def test_malformed_files_name_file_and_line(tmp_path, text, line, words):
    path = write(tmp_path, text)
    with pytest.raises(CompFileError) as e:
        read_comp_file(path, 1)
    msg = str(e.value)
    assert msg.startswith(f"{path}:{line}: "), msg
    assert words in msg
    assert isinstance(e.value, HalError) and isinstance(e.value, ValueError)


def test_too_many_entries_and_other_errors(tmp_path):
    ok = "".join(f"{i} 0.001 -0.001\n" for i in range(COMP_SIZE))
    assert len(read_comp_file(write(tmp_path, ok), 1)) == 256
    path = write(tmp_path, "# header\n" + ok + "999 0 0\n", "big.txt")
    with pytest.raises(CompFileError,
                       match=r"big\.txt:258: more than 256 entries"):
        read_comp_file(path, 1)
    with pytest.raises(CompFileError, match="COMP_FILE_TYPE must be 0 or 1"):
        read_comp_file(path, 2)
    missing = tmp_path / "nope.txt"
    with pytest.raises(CompFileError, match="nope.txt: cannot read"):
        read_comp_file(missing, 0)


def test_file_into_the_realtime_table(lib, tmp_path):
    """A file read by screwcomp goes into mot_comp entry by entry and the
    lookup reproduces its trims."""
    rng = np.random.default_rng(8)
    nom = np.cumsum(rng.uniform(0.1, 5, size=40)) - 50
    fwd = rng.uniform(-0.01, 0.01, size=40)
    rev = rng.uniform(-0.01, 0.01, size=40)
    text = "".join(f"{float(a)!r} {float(b)!r} {float(c)!r}\n"
                   for a, b, c in zip(nom, fwd, rev))
    entries = read_comp_file(write(tmp_path, text), 1)
    j = Joint(lib)
    for e in entries:
        assert j.add(*e) == (0, "")
    for a, b, c in zip(nom, fwd, rev):
        assert j.lookup(a, 1) == b and j.lookup(a, -1) == c
