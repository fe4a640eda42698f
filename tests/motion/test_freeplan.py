"""The single-coordinate planner of the motion controller
(components/motion/freeplan.c and freeplan_jerk.cpp), called through
ctypes from a plain shared library built here.

Property checks over many random cases (numpy, fixed seeds): velocity,
acceleration and (FP_JERK) jerk limits hold in the planner's state and in
the finite differences of the position trace, the final position is the
target exactly, the trapezoid is time optimal within a cycle, and new
targets, stops and lower limits mid-move never make a step.
"""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest
from helpers.freeplan import DPTR, Freeplan, build_library

FP_TRAPEZOID = 0
FP_JERK = 1
REL = 1e-9

# a loop in C so that long traces cost little: targets (optional) is
# written into fp->target before each cycle; until_idle stops the run at
# the first cycle that ends inactive
RUNNER = r"""
#include "freeplan.h"
int fp_run(freeplan_t *fp, double dt, int n, const double *targets,
           double *pos, double *vel, double *acc, int *active,
           int until_idle)
{
    int i;
    for (i = 0; i < n; i++) {
        if (targets)
            fp->target = targets[i];
        fp_update(fp, dt);
        if (pos) pos[i] = fp->pos;
        if (vel) vel[i] = fp->vel;
        if (acc) acc[i] = fp->acc;
        if (active) active[i] = fp->active;
        if (until_idle && !fp->active)
            return i + 1;
    }
    return n;
}
"""


IPTR = ctypes.POINTER(ctypes.c_int)


@pytest.fixture(scope="session")
def lib(tmp_path_factory):
    so = build_library(str(tmp_path_factory.mktemp("freeplan")),
                       ["freeplan.c"], RUNNER)
    lib = ctypes.CDLL(so)
    fp_p = ctypes.POINTER(Freeplan)
    lib.fp_init.argtypes = [fp_p]
    lib.fp_init.restype = ctypes.c_int
    lib.fp_free.argtypes = [fp_p]
    lib.fp_reset.argtypes = [fp_p, ctypes.c_double]
    lib.fp_update.argtypes = [fp_p, ctypes.c_double]
    lib.fp_stopping_distance.argtypes = [fp_p]
    lib.fp_stopping_distance.restype = ctypes.c_double
    lib.fp_run.argtypes = [fp_p, ctypes.c_double, ctypes.c_int, DPTR,
                           DPTR, DPTR, DPTR, IPTR, ctypes.c_int]
    lib.fp_run.restype = ctypes.c_int
    return lib


class Planner:
    """A planner and the trace of everything it did."""

    def __init__(self, lib, profile, pos, vmax, amax, jmax=0.0):
        self.lib = lib
        self.fp = Freeplan()
        assert lib.fp_init(ctypes.byref(self.fp)) == 0
        lib.fp_reset(ctypes.byref(self.fp), pos)
        self.fp.profile = profile
        self.fp.max_vel = vmax
        self.fp.max_acc = amax
        self.fp.max_jerk = jmax
        self.fp.enable = 1
        self.pos = [np.array([pos])]
        self.vel = [np.array([0.0])]
        self.acc = [np.array([0.0])]
        self.active = [np.array([0], dtype=np.int32)]

    def __del__(self):
        self.lib.fp_free(ctypes.byref(self.fp))

    def run(self, dt, n, targets=None, until_idle=False):
        """Run up to n cycles; return the number run."""
        pos, vel, acc = np.empty(n), np.empty(n), np.empty(n)
        act = np.empty(n, dtype=np.int32)
        tg = None
        if targets is not None:
            targets = np.ascontiguousarray(targets, dtype=float)
            tg = targets.ctypes.data_as(DPTR)
        k = self.lib.fp_run(ctypes.byref(self.fp), dt, n, tg,
                            pos.ctypes.data_as(DPTR),
                            vel.ctypes.data_as(DPTR),
                            acc.ctypes.data_as(DPTR),
                            act.ctypes.data_as(IPTR), int(until_idle))
        self.pos.append(pos[:k])
        self.vel.append(vel[:k])
        self.acc.append(acc[:k])
        self.active.append(act[:k])
        return k

    def settle(self, dt, limit=2_000_000):
        """Run until the planner is idle; return the cycles it took."""
        k = self.run(dt, limit, until_idle=True)
        assert not self.fp.active, f"still moving after {limit} cycles"
        return k

    def trace(self):
        return (np.concatenate(self.pos), np.concatenate(self.vel),
                np.concatenate(self.acc), np.concatenate(self.active))

    def stopping_distance(self):
        return self.lib.fp_stopping_distance(ctypes.byref(self.fp))


def check_limits(trace, dt, vmax, amax, jmax=None, fd=True):
    """The planner's state and the finite differences of its positions
    respect the limits (the finite differences with the slack that the
    rounding of the positions themselves brings)."""
    pos, vel, acc, _ = trace
    assert np.all(np.isfinite(pos)) and np.all(np.isfinite(vel))
    assert np.all(np.isfinite(acc))
    assert np.max(np.abs(vel)) <= vmax * (1 + REL)
    assert np.max(np.abs(acc)) <= amax * (1 + REL)
    if jmax is not None:
        jerk = np.diff(acc) / dt
        assert np.max(np.abs(jerk), initial=0) <= jmax * (1 + REL)
    if not fd:
        return
    # a few roundings of the positions (one is at most eps*|pos|)
    eps = np.finfo(float).eps * (np.max(np.abs(pos)) + 1e-300) * 2
    v_fd = np.diff(pos) / dt
    assert np.max(np.abs(v_fd), initial=0) <= vmax * (1 + REL) + 2 * eps / dt
    a_fd = np.diff(pos, 2) / dt**2
    assert np.max(np.abs(a_fd), initial=0) <= amax * (1 + REL) + 4 * eps / dt**2
    if jmax is not None:
        j_fd = np.diff(pos, 3) / dt**3
        assert (np.max(np.abs(j_fd), initial=0)
                <= jmax * (1 + REL) + 8 * eps / dt**3)


def trapezoid_time(dist, vmax, amax):
    """Minimum time of a rest-to-rest move under vmax and amax."""
    dist = abs(dist)
    if dist >= vmax * vmax / amax:
        return dist / vmax + vmax / amax
    return 2 * math.sqrt(dist / amax)


def random_case(rng, dt):
    """Limits and a distance whose move takes up to about 3000 cycles."""
    vmax = 10 ** rng.uniform(-2, 2)
    # time to reach vmax between 2 and 1000 cycles
    amax = vmax / (dt * 10 ** rng.uniform(0.3, 3))
    t_move = dt * 10 ** rng.uniform(0, 3.5)
    dist = rng.choice([-1, 1]) * min(vmax * t_move, 1e4)
    start = rng.uniform(-100, 100)
    return start, dist, vmax, amax


DTS = [1e-3, 25e-6]


# ---------------------------------------------------------------- trapezoid

@pytest.mark.parametrize("dt", DTS)
def test_trapezoid_random_moves_are_exact_and_time_optimal(lib, dt):
    rng = np.random.default_rng(1)
    for _ in range(150):
        start, dist, vmax, amax = random_case(rng, dt)
        p = Planner(lib, FP_TRAPEZOID, start, vmax, amax)
        target = start + dist
        p.fp.target = target
        n = p.settle(dt)
        tr = p.trace()
        check_limits(tr, dt, vmax, amax)
        assert p.fp.pos == target and p.fp.vel == 0.0
        # arrival: the first cycle on the target; the next one ends at rest
        # (trace index k is the state after k cycles)
        arrive = int(np.argmax(tr[0] == target))
        assert arrive == n - 1 or arrive == n
        t_min = trapezoid_time(target - start, vmax, amax)
        assert arrive * dt <= t_min + dt * (1 + 1e-6), (arrive, t_min / dt)
        assert arrive * dt >= t_min - dt * (1 + 1e-6), (arrive, t_min / dt)
        # at rest it stays, exactly and without chatter
        p.run(dt, 50)
        tail = p.trace()
        assert np.all(tail[0][-50:] == target)
        assert np.all(tail[1][-50:] == 0.0) and np.all(tail[3][-50:] == 0)


def test_trapezoid_reaches_and_keeps_the_velocity_limit(lib):
    dt = 1e-3
    p = Planner(lib, FP_TRAPEZOID, 0.0, 2.0, 10.0)
    p.fp.target = 10.0
    p.settle(dt)
    pos, vel, acc, _ = p.trace()
    assert np.max(vel) == pytest.approx(2.0, rel=1e-12)
    # the cruise may be a hair under the limit (the plan spreads the
    # rounding of the cycle count over it)
    cruise = np.sum(np.abs(vel - 2.0) < 1e-3)
    assert cruise * dt == pytest.approx(10.0 / 2.0 - 2.0 / 10.0, abs=3 * dt)
    # acceleration phases use the full acceleration
    assert np.sum(np.abs(acc - 10.0) < 1e-9) >= 199
    assert np.sum(np.abs(acc + 10.0) < 1e-9) >= 199


@pytest.mark.parametrize("dt", DTS)
def test_trapezoid_new_targets_mid_move(lib, dt):
    rng = np.random.default_rng(2)
    for _ in range(80):
        start, dist, vmax, amax = random_case(rng, dt)
        p = Planner(lib, FP_TRAPEZOID, start, vmax, amax)
        target = start + dist
        for _ in range(rng.integers(1, 6)):
            p.fp.target = target
            p.run(dt, int(rng.integers(1, 400)))
            # anywhere, also behind the planner
            target = p.fp.pos + rng.uniform(-2, 2) * abs(dist)
        p.fp.target = target
        p.settle(dt)
        check_limits(p.trace(), dt, vmax, amax)
        assert p.fp.pos == target


def test_trapezoid_target_behind_decelerates_and_comes_back(lib):
    dt = 1e-3
    p = Planner(lib, FP_TRAPEZOID, 0.0, 1.0, 2.0)
    p.fp.target = 10.0
    p.run(dt, 2000)                     # cruising at 1.0 past 1.25
    here = p.fp.pos
    assert p.fp.vel == pytest.approx(1.0, rel=1e-3)
    p.fp.target = here - 0.01           # just behind
    n = p.run(dt, 5000, until_idle=True)
    pos, vel, acc, _ = (x[-n:] for x in p.trace())
    # full deceleration first, overshooting by the stopping distance
    assert np.all(acc[:499] == pytest.approx(-2.0))
    assert np.max(pos) == pytest.approx(here + 0.25, abs=2e-3)
    assert np.min(vel) < 0                  # and back
    assert p.fp.pos == here - 0.01 and not p.fp.active
    check_limits(p.trace(), dt, 1.0, 2.0)


@pytest.mark.parametrize("dt", DTS)
def test_trapezoid_velocity_limit_lowered_mid_move(lib, dt):
    vmax, amax = 2.0, 20.0
    p = Planner(lib, FP_TRAPEZOID, 0.0, vmax, amax)
    p.fp.target = 5.0
    p.run(dt, int(0.3 / dt))
    assert p.fp.vel == pytest.approx(vmax, rel=1e-3)
    p.fp.max_vel = 0.5
    k = int(0.3 / dt)
    p.run(dt, k)
    pos, vel, acc, _ = p.trace()
    vel = vel[-k:]
    # down at the full deceleration, no step, never below the new limit
    steps = np.diff(np.concatenate([[p.vel[-2][-1]], vel]))
    assert np.all(steps <= 1e-12) and np.all(steps >= -amax * dt * (1 + REL))
    down = int(round(1.5 / (amax * dt)))
    assert np.all(steps[:down - 1] == pytest.approx(-amax * dt))
    assert np.all(vel[down:] <= 0.5 * (1 + REL))
    assert np.min(vel) == pytest.approx(0.5, rel=1e-3)
    p.settle(dt)
    assert p.fp.pos == 5.0
    check_limits(p.trace(), dt, vmax, amax)


@pytest.mark.parametrize("dt", DTS)
def test_trapezoid_stop_and_stopping_distance(lib, dt):
    rng = np.random.default_rng(3)
    for _ in range(60):
        start, dist, vmax, amax = random_case(rng, dt)
        p = Planner(lib, FP_TRAPEZOID, start, vmax, amax)
        p.fp.target = start + 5 * dist
        p.run(dt, int(rng.integers(1, 2000)))
        predicted = p.stopping_distance()
        v = p.fp.vel
        assert predicted == pytest.approx(v * abs(v) / (2 * amax))
        here = p.fp.pos
        p.fp.enable = 0
        p.settle(dt)
        moved = p.fp.pos - here
        # the sampled stop is shorter than the continuous one by at most
        # half a cycle at the initial speed
        assert abs(moved) <= abs(predicted) * (1 + 1e-9) + 1e-12
        assert abs(moved) >= abs(predicted) - abs(v) * dt * 0.5 - 1e-12
        assert p.fp.vel == 0.0
        check_limits(p.trace(), dt, vmax, amax)
        # staying stopped
        p.run(dt, 10)
        assert p.fp.pos == here + moved
        assert p.fp.vel == 0.0 and p.fp.acc == 0.0 and not p.fp.active
        # enabled again: to the target
        p.fp.enable = 1
        p.settle(dt)
        assert p.fp.pos == start + 5 * dist


@pytest.mark.parametrize("dt", DTS)
def test_trapezoid_tiny_moves(lib, dt):
    for dist in [1e-15, 3e-12, 1e-9, -2.5e-7, 1e-6, -1e-4]:
        for start in [0.0, 1.0, -123.456]:
            p = Planner(lib, FP_TRAPEZOID, start, 1.0, 10.0)
            p.fp.target = start + dist
            n = p.settle(dt)
            assert p.fp.pos == start + dist
            assert n <= trapezoid_time(dist, 1.0, 10.0) / dt + 2
            check_limits(p.trace(), dt, 1.0, 10.0)


@pytest.mark.parametrize("profile", [FP_TRAPEZOID, FP_JERK])
def test_jog_wheel_and_cumulative_increments(lib, profile):
    """The target changes (almost) every cycle: a jog wheel at 1 ms and
    cumulative increments at 25 us."""
    rng = np.random.default_rng(4)
    vmax, amax, jmax = 5.0, 50.0, 2000.0
    dt = 1e-3
    p = Planner(lib, profile, 0.0, vmax, amax, jmax)
    counts = np.cumsum(rng.integers(-3, 9, size=3000))
    targets = counts * 0.01
    p.run(dt, len(targets), targets)
    p.fp.target = targets[-1]
    p.settle(dt)
    assert p.fp.pos == targets[-1]
    check_limits(p.trace(), dt, vmax, amax,
                 jmax if profile == FP_JERK else None)

    dt = 25e-6
    p = Planner(lib, profile, 1.0, vmax, amax, jmax)
    target = 1.0
    for _ in range(40):
        target += 0.01
        p.fp.target = target
        p.run(dt, int(rng.integers(20, 800)))
    p.settle(dt)
    assert p.fp.pos == target
    check_limits(p.trace(), dt, vmax, amax,
                 jmax if profile == FP_JERK else None)


def test_trapezoid_follows_a_slow_moving_target_smoothly(lib):
    """A target moving slower than one acceleration step per cycle is
    followed at its own speed: no stop-and-go."""
    dt = 1e-3
    p = Planner(lib, FP_TRAPEZOID, 0.0, 1.0, 10.0)
    targets = np.arange(1, 2001) * 0.005 * dt       # 5 mm/s, h = 10 mm/s
    p.run(dt, len(targets), targets)
    _, vel, _, _ = p.trace()
    assert np.allclose(vel[1:], 0.005, rtol=1e-9)
    assert p.fp.pos == targets[-1]


# ---------------------------------------------------------------- jerk

def random_jerk_case(rng, dt):
    start, dist, vmax, amax = random_case(rng, dt)
    # time to reach amax between 1 and 300 cycles
    jmax = amax / (dt * 10 ** rng.uniform(0, 2.5))
    return start, dist, vmax, amax, jmax


@pytest.mark.parametrize("dt", DTS)
def test_jerk_random_moves(lib, dt):
    rng = np.random.default_rng(5)
    for _ in range(120):
        start, dist, vmax, amax, jmax = random_jerk_case(rng, dt)
        p = Planner(lib, FP_JERK, start, vmax, amax, jmax)
        target = start + dist
        p.fp.target = target
        n = p.settle(dt)
        check_limits(p.trace(), dt, vmax, amax, jmax)
        assert p.fp.pos == target and p.fp.vel == 0 and p.fp.acc == 0
        # no slower than the trapezoid smoothed over 2 amax / jmax
        # (a moving average makes it a jerk-limited motion), and no
        # faster than the trapezoid
        t_trap = trapezoid_time(dist, vmax, amax)
        assert n * dt <= t_trap + 2 * amax / jmax + dt
        assert n * dt >= t_trap - dt
        p.run(dt, 20)
        assert np.all(p.trace()[0][-20:] == target)


@pytest.mark.parametrize("dt", DTS)
def test_jerk_new_targets_stops_and_lower_limits(lib, dt):
    rng = np.random.default_rng(6)
    for _ in range(60):
        start, dist, vmax, amax, jmax = random_jerk_case(rng, dt)
        p = Planner(lib, FP_JERK, start, vmax, amax, jmax)
        target = start + dist
        for _ in range(rng.integers(1, 5)):
            p.fp.target = target
            p.run(dt, int(rng.integers(1, 500)))
            target = p.fp.pos + rng.uniform(-2, 2) * abs(dist)
            if rng.random() < 0.3:
                p.fp.enable = 0
                p.run(dt, int(rng.integers(1, 300)))
                p.fp.enable = 1
        p.fp.target = target
        p.settle(dt)
        check_limits(p.trace(), dt, vmax, amax, jmax)
        assert p.fp.pos == target


@pytest.mark.parametrize("dt", DTS)
def test_jerk_stop_matches_stopping_distance(lib, dt):
    rng = np.random.default_rng(7)
    for _ in range(60):
        start, dist, vmax, amax, jmax = random_jerk_case(rng, dt)
        p = Planner(lib, FP_JERK, start, vmax, amax, jmax)
        p.fp.target = start + 5 * dist
        p.run(dt, int(rng.integers(1, 3000)))
        predicted = p.stopping_distance()
        here, v = p.fp.pos, p.fp.vel
        p.fp.enable = 0
        p.settle(dt)
        assert p.fp.vel == 0 and p.fp.acc == 0
        moved = p.fp.pos - here
        assert moved == pytest.approx(predicted, rel=1e-6,
                                      abs=abs(v) * dt + 1e-12)
        check_limits(p.trace(), dt, vmax, amax, jmax)


def test_jerk_stopping_distance_formula(lib):
    p = Planner(lib, FP_JERK, 0.0, 10.0, 4.0, 8.0)
    # symmetric stops from a = 0 cover v * T / 2: without a plateau
    # T = 2 sqrt(v / J), with one T = v / A + A / J
    cases = [(0.0, 0.0, 0.0), (1.0, 0.0, 1 / math.sqrt(8)),
             (5.0, 0.0, 4.375), (-5.0, 0.0, -4.375)]
    for v, a, want in cases:
        p.fp.vel, p.fp.acc = v, a
        assert p.stopping_distance() == pytest.approx(want)
    # and ruckig's stop (velocity interface) goes exactly that far
    for v, a in [(1.0, 0.0), (3.0, 2.0), (-2.0, 3.0), (0.1, -4.0),
                 (5.0, -4.0), (0.0, 4.0), (-0.01, 0.3)]:
        p.fp.vel, p.fp.acc = v, a
        p.fp.pos = 0.0
        expect = p.stopping_distance()
        p.fp.enable = 0
        p.settle(1e-5)
        assert p.fp.pos == pytest.approx(expect, rel=1e-6, abs=1e-7)
        p.lib.fp_reset(ctypes.byref(p.fp), 0.0)


@pytest.mark.parametrize("dt", DTS)
def test_jerk_velocity_limit_lowered_mid_move(lib, dt):
    vmax, amax, jmax = 2.0, 20.0, 400.0
    p = Planner(lib, FP_JERK, 0.0, vmax, amax, jmax)
    p.fp.target = 5.0
    p.run(dt, int(0.4 / dt))
    assert p.fp.vel == pytest.approx(vmax, rel=1e-3)
    p.fp.max_vel = 0.5
    k = int(0.4 / dt)
    p.run(dt, k)
    _, vel, acc, _ = p.trace()
    # decelerates within the jerk limit (the whole trace is checked
    # below), monotonically, and stays under the new limit once there
    assert np.all(np.diff(vel[-k - 1:]) <= 1e-12)
    below = np.argmax(vel[-k:] <= 0.5 * (1 + REL))
    assert below * dt < 1.5 / amax + amax / jmax + 2 * dt
    assert np.all(vel[-k:][below:] <= 0.5 * (1 + REL))
    p.settle(dt)
    assert p.fp.pos == 5.0
    check_limits(p.trace(), dt, vmax, amax, jmax)


@pytest.mark.parametrize("seed", range(12))
def test_jerk_targets_every_cycle_at_25us(lib, seed):
    """Small, fast moves with a new target every cycle (durations of a
    few cycles, jerk limits up to 1e8): ruckig fails or misbehaves on some
    of these states; the planner must still keep every limit."""
    dt = 25e-6
    rng = np.random.default_rng(seed + 100)
    vmax = 10 ** rng.uniform(-2, 1)
    amax = vmax / (dt * 10 ** rng.uniform(0.3, 2))
    jmax = amax / (dt * 10 ** rng.uniform(0, 1.5))
    start = float(rng.choice([0.0, 1e3, -1e5]))
    p = Planner(lib, FP_JERK, start, vmax, amax, jmax)
    step = rng.uniform(0.1, 3) * vmax * dt
    targets = start + np.cumsum(rng.integers(-2, 5, size=1500)) * step
    p.run(dt, len(targets), targets)
    p.fp.target = targets[-1]
    p.settle(dt)
    assert p.fp.pos == targets[-1]
    check_limits(p.trace(), dt, vmax, amax, jmax)


@pytest.mark.parametrize("dt", DTS)
def test_jerk_tiny_moves(lib, dt):
    for dist in [1e-15, 3e-12, 1e-9, -2.5e-7, 1e-6, -1e-4]:
        for start in [0.0, 1.0, -123.456]:
            p = Planner(lib, FP_JERK, start, 1.0, 10.0, 100.0)
            p.fp.target = start + dist
            p.settle(dt, 100000)
            assert p.fp.pos == start + dist
            check_limits(p.trace(), dt, 1.0, 10.0, 100.0)


def test_jerk_very_long_move(lib):
    """ruckig refuses trajectories over about 7600 s; the planner still
    makes a 20000 s move, at full speed."""
    dt = 0.05
    p = Planner(lib, FP_JERK, 0.0, 1.0, 1.0, 1.0)
    p.fp.target = 20000.0
    n = p.settle(dt)
    assert p.fp.pos == 20000.0
    assert n * dt <= 20000.0 + 1.0 + 1.0 + 2 * dt
    check_limits(p.trace(), dt, 1.0, 1.0, 1.0)


# ---------------------------------------------------------------- bad input

@pytest.mark.parametrize("profile", [FP_TRAPEZOID, FP_JERK])
def test_bad_input_never_makes_nan(lib, profile):
    dt = 1e-3
    nan, inf = float("nan"), float("inf")
    p = Planner(lib, profile, 0.0, 1.0, 10.0, 100.0)
    p.fp.target = 1.0
    p.run(dt, 100)
    v = p.fp.vel
    # a NaN or infinite target: a stop
    p.fp.target = nan
    p.run(dt, 300)
    assert p.fp.vel == 0.0 and np.isfinite(p.fp.pos)
    p.fp.target = inf
    p.run(dt, 10)
    assert p.fp.vel == 0.0
    # bad limits: NaN velocity limit means no motion, decelerating
    p.fp.target = 0.5
    p.run(dt, 50)
    assert p.fp.vel > 0
    p.fp.max_vel = nan
    p.run(dt, 300)
    assert p.fp.vel == 0.0 and np.isfinite(p.fp.pos)
    p.fp.max_vel = 1.0
    p.fp.max_jerk = nan          # FP_JERK without a jerk limit: trapezoid
    p.settle(dt)
    assert p.fp.pos == 0.5
    check_limits(p.trace(), dt, 1.0, 10.0)
    # zero or NaN acceleration limit: stands still at once
    p.fp.target = 2.0
    p.run(dt, 20)
    p.fp.max_acc = 0.0
    p.run(dt, 1)
    assert p.fp.vel == 0.0 and not p.fp.active
    p.fp.max_acc = nan
    p.run(dt, 5)
    here = p.fp.pos
    assert np.isfinite(here) and p.fp.vel == 0.0
    # bad dt: nothing happens
    p.fp.max_acc = 10.0
    for bad in (0.0, -1e-3, nan, inf):
        p.lib.fp_update(ctypes.byref(p.fp), bad)
        assert p.fp.pos == here
    del v


@pytest.mark.parametrize("profile", [FP_TRAPEZOID, FP_JERK])
def test_reset_puts_the_planner_at_rest(lib, profile):
    p = Planner(lib, profile, 0.0, 1.0, 10.0, 100.0)
    p.fp.target = 3.0
    p.run(1e-3, 500)
    assert p.fp.active
    lib.fp_reset(ctypes.byref(p.fp), 7.0)
    assert (p.fp.pos, p.fp.target, p.fp.vel, p.fp.acc) == (7.0, 7.0, 0, 0)
    assert p.fp.enable == 0 and p.fp.active == 0
    p.fp.enable = 1
    p.run(1e-3, 10)
    assert p.fp.pos == 7.0 and not p.fp.active
    p.fp.target = 6.0
    p.settle(1e-3)
    assert p.fp.pos == 6.0


def test_profiles_switch_mid_move(lib):
    """Trapezoid to jerk and back while moving: the jerk profile starts
    from the trapezoid's state; no NaN, exact arrival."""
    dt = 1e-3
    p = Planner(lib, FP_TRAPEZOID, 0.0, 1.0, 10.0, 200.0)
    p.fp.target = 3.0
    p.run(dt, 300)
    p.fp.profile = FP_JERK
    p.run(dt, 300)
    p.fp.profile = FP_TRAPEZOID
    p.run(dt, 300)
    p.fp.profile = FP_JERK
    p.settle(dt)
    assert p.fp.pos == 3.0
    check_limits(p.trace(), dt, 1.0, 10.0)
