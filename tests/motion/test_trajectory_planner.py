"""The coordinated-mode trajectory planner tpmod, driven directly through
its halsdk_tp_api table (tp.h, version 2) with ctypes, one planner cycle
per call, so that every trace is deterministic.

Each program's trace is checked for the path (deviation from the programmed
lines and arcs), the per-axis velocity and acceleration limits (finite
differences of the sampled positions), exact final positions and the
behaviour asked for (exact stop, exact path, blending, overrides, probing,
spindle synchronization).
"""

from __future__ import annotations

import ctypes as C
import math

import numpy as np
import pytest
from helpers.tp_api import (
    BLEND,
    EXACT,
    STOP,
    TP_IN_FEED,
    TP_IN_SPINDLES,
    Cart,
    Hooks,
    Inputs,
    Move,
    Pose9,
    State,
    TpApi,
    pose9,
)

from halsdk.core import _core

DT = 1e-3

# ------------------------------------------------------------ the planner


class Planner:
    """tpmod driven cycle by cycle."""

    def __init__(self, hal, **load):
        hal.loadrt("tpmod", **load)
        self.api = TpApi.from_address(_core.symbol_address("halsdk_tp_api"))
        self.why = C.create_string_buffer(200)
        assert self.api.version == 2
        assert self.api.init(0, DT, None, self.why, 200) == 0
        self.inputs = Inputs()
        self.out = Pose9()
        self.next_id = 1
        self.spindle = None         # a callable run before every cycle

    def move(self, vel=10.0, acc=100.0, maxvel=None, type=2, id=None,
             term=STOP, tol=0.0, q=0.0, flags=0, sync=0, pitch=0.0):
        if id is None:
            id, self.next_id = self.next_id, self.next_id + 1
        return Move(id=id, type=type, vel=vel,
                    ini_maxvel=maxvel if maxvel else vel, acc=acc,
                    term_cond=term, tolerance=tol, cam_tolerance=q,
                    flags=flags, sync=sync, pitch=pitch)

    def line(self, end, **kw):
        r = self.api.add_line(pose9(*end), self.move(**kw), self.why, 200)
        return r, self.why.value.decode()

    def circle(self, end, center, normal, turn=0, **kw):
        r = self.api.add_circle(pose9(*end), Cart(*center), Cart(*normal),
                                turn, self.move(**kw), self.why, 200)
        return r, self.why.value.decode()

    def limits(self, vel, acc, axes="xyz"):
        for a in axes:
            self.api.set_axis_limits("xyzabcuvw".index(a), vel, acc)

    def state(self):
        st = State()
        self.api.get_state(st)
        return st

    def run(self, n=None, probe=None, until_done=True, each=None):
        """Cycles until done (or n); the positions as an array."""
        out = []
        k = 0
        while n is None or k < n:
            if probe is not None:
                self.inputs.probe_input = int(probe(k))
            if self.spindle is not None:
                self.spindle()
            if each is not None:
                each(k)
            self.api.run_cycle(self.inputs, self.out)
            out.append(self.out.values())
            k += 1
            if until_done and n is None and self.api.is_done():
                break
            assert k < 400_000
        return np.array(out)


@pytest.fixture
def tp(hal):
    return Planner(hal)


# ------------------------------------------------------------ checks


def vel_acc(p):
    v = np.diff(p, axis=0) / DT
    a = np.diff(v, axis=0) / DT
    return v, a


def check_axis_limits(p, vmax, amax, axes=(0, 1, 2), tol=1e-6):
    """Every axis's sampled |v| and |a| within its limit."""
    v, a = vel_acc(p)
    for i in axes:
        assert np.abs(v[:, i]).max() <= vmax * (1 + tol) + 1e-9, i
        assert np.abs(a[:, i]).max() <= amax * (1 + tol) + 1e-6, (
            i, np.abs(a[:, i]).max())


def seg_dist(p, a, b):
    """Distance of points p (n x 3) from the segment a-b."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    L2 = d @ d
    t = np.clip(((p - a) @ d) / L2, 0, 1) if L2 > 0 else np.zeros(len(p))
    return np.linalg.norm(p - (a + np.outer(t, d)), axis=1)


def polyline_dev(p, pts):
    """Largest distance of the trace from the polyline through pts."""
    d = np.full(len(p), np.inf)
    for a, b in zip(pts[:-1], pts[1:]):
        d = np.minimum(d, seg_dist(p[:, :3], a, b))
    return d.max()


def path_speed(p):
    return np.linalg.norm(np.diff(p[:, :3], axis=0), axis=1) / DT


# ------------------------------------------------------------ basics
# (the exact-stop tests of the first planner, which must keep passing)


def test_tp_lines_exact_ends_and_limits(tp):
    assert tp.line((1, 2, 0), vel=10, acc=100)[0] == 0
    assert tp.line((1, 2, -3), vel=5, acc=50)[0] == 0
    assert tp.api.queue_depth() == 2
    p = tp.run()
    assert p[-1].tolist() == [1, 2, -3, 0, 0, 0, 0, 0, 0]
    assert np.min(np.linalg.norm(p[:, :3] - [1, 2, 0], axis=1)) == 0
    v = np.linalg.norm(np.diff(p[:, :3], axis=0), axis=1) / DT
    a = np.linalg.norm(np.diff(np.diff(p[:, :3], axis=0), axis=0),
                       axis=1) / DT**2
    assert v.max() == pytest.approx(10) and v.max() <= 10 + 1e-9
    assert a.max() <= 100 * (1 + 1e-9)
    # second move: slower
    k = int(np.argmin(np.linalg.norm(p[:, :3] - [1, 2, 0], axis=1)))
    assert v[k + 1:].max() <= 5 + 1e-9
    assert tp.api.exec_id() == 2 and tp.api.is_done()


def test_tp_circle_helix_any_plane(tp):
    # a helix about an axis along (1, 1, 0) through (0, 0, 0), with the
    # A axis moving along
    n = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)
    start = np.array([0.0, 0.0, 2.0])
    end = start + 1.5 * n                       # 1 full turn + rise 1.5
    tp.api.set_pos(pose9(*start), tp.why, 200)
    assert tp.circle(tuple(end) + (90,), (0, 0, 0), tuple(n), turn=0,
                     vel=6, acc=80)[0] == 0
    p = tp.run()
    assert np.allclose(p[-1, :4], list(end) + [90], atol=1e-12)
    rel = p[:, :3]
    h = rel @ n
    radial = np.linalg.norm(rel - np.outer(h, n), axis=1)
    assert np.allclose(radial, 2.0, atol=1e-9)
    assert np.all(np.diff(h) >= -1e-12)          # rises steadily
    v = path_speed(p)
    a = np.linalg.norm(np.diff(np.diff(p[:, :3], axis=0), axis=0),
                       axis=1) / DT**2
    assert v.max() <= 6 + 1e-9
    assert a.max() <= 80 * 1.001
    # the A axis moves in proportion
    assert np.all(np.diff(p[:, 3]) >= 0) and p[-1, 3] == 90


def test_tp_rotary_only_and_uvw_lines(tp):
    assert tp.line((0, 0, 0, 45), vel=90, acc=900)[0] == 0
    assert tp.line((0, 0, 0, 45, 0, 0, 2, 0, 0), vel=4, acc=40)[0] == 0
    p = tp.run()
    assert p[-1, 3] == 45 and p[-1, 6] == 2
    va = np.abs(np.diff(p[:, 3])) / DT
    vu = np.abs(np.diff(p[:, 6])) / DT
    assert va.max() == pytest.approx(90) and vu.max() == pytest.approx(4)


def test_tp_axis_limits_bound_the_path(tp):
    tp.api.set_axis_limits(1, 2.0, 10.0)        # Y slow
    tp.line((3, 4, 0), vel=50, acc=500)
    p = tp.run()
    vy = np.abs(np.diff(p[:, 1])) / DT
    ay = np.abs(np.diff(np.diff(p[:, 1]))) / DT**2
    assert vy.max() <= 2 + 1e-9 and ay.max() <= 10 * (1 + 1e-9)
    assert p[-1, 1] == 4


def test_tp_feed_scale_pause_resume_abort(tp):
    tp.line((100, 0, 0), vel=10, acc=100)
    tp.api.set_scale(0.5, 1.0)
    p = tp.run(300)
    assert (p[-1, 0] - p[-2, 0]) / DT == pytest.approx(5)
    tp.api.pause()
    q = tp.run(300)
    assert q[-1, 0] == q[-2, 0] and tp.api.queue_depth() == 1
    assert tp.state().paused
    dv = np.abs(np.diff(np.diff(np.r_[p[-2:, 0], q[:, 0]]))) / DT**2
    assert dv.max() <= 100 * (1 + 1e-9)
    tp.api.set_scale(1.0, 1.0)
    tp.api.resume()
    r = tp.run(300)
    assert (r[-1, 0] - r[-2, 0]) / DT == pytest.approx(10)
    tp.api.abort()
    s = tp.run()
    assert tp.api.is_done() and tp.api.queue_depth() == 0
    dv = np.abs(np.diff(np.diff(np.r_[r[-2:, 0], s[:, 0]]))) / DT**2
    assert dv.max() <= 100 * (1 + 1e-9)
    assert s[-1, 0] < 100
    # the next move starts where the abort stopped
    tp.line((0, 0, 0), vel=10, acc=100)
    assert tp.run()[-1, 0] == 0


def test_tp_step_pauses_after_one_move(tp):
    for x in (1, 2, 3):
        tp.line((x, 0, 0), vel=10, acc=100)
    tp.api.pause()
    assert tp.run(50)[-1, 0] == 0
    tp.api.step()
    p = tp.run(1000, until_done=False)
    assert p[-1, 0] == 1 and tp.api.queue_depth() == 2
    tp.api.resume()
    assert tp.run()[-1, 0] == 3


def test_tp_probe_trips_records_and_stops(tp):
    r = tp.api.add_probe(pose9(10), tp.move(vel=5, acc=100), 0, tp.why, 200)
    assert r == 0
    tp.line((0, 0, 0))                          # dropped by the trip
    p = tp.run(probe=lambda k: k >= 500)
    where = Pose9()
    assert tp.api.probe_result(C.byref(where)) == 1
    x = where.values()[0]
    assert x == pytest.approx(p[499, 0], abs=1e-12)
    assert p[-1, 0] > x and p[-1, 0] - x < 5 * 5 / 100  # stopped soon
    assert tp.api.queue_depth() == 0
    # a probe already tripped at the start: error, nothing moves
    tp.api.clear_probe()
    tp.api.add_probe(pose9(20), tp.move(vel=5), 0, tp.why, 200)
    q = tp.run(probe=lambda k: 1)
    assert q[-1, 0] == p[-1, 0]
    assert b"already tripped" in tp.api.take_error()
    # no contact: error unless asked not to
    tp.api.add_probe(pose9(11), tp.move(vel=5), 0, tp.why, 200)
    tp.run(probe=lambda k: 0)
    assert tp.api.probe_result(None) == -1
    assert b"without contact" in tp.api.take_error()
    tp.api.add_probe(pose9(12), tp.move(vel=5), 1, tp.why, 200)
    tp.run(probe=lambda k: 0)
    assert tp.api.take_error() == b""


def test_tp_probe_away_polarity_exact_to_one_cycle(tp):
    # G38.4: trips when the input goes false; the recorded point is the
    # position commanded in the cycle before the one that saw the change
    tp.api.add_probe(pose9(0, 10), tp.move(vel=8, acc=200), 2, tp.why, 200)
    p = tp.run(probe=lambda k: k < 321)
    where = Pose9()
    assert tp.api.probe_result(C.byref(where)) == 1
    assert where.values()[1] == pytest.approx(p[320, 1], abs=1e-12)
    _, a = vel_acc(p)
    assert np.abs(a[:, 1]).max() <= 200 * (1 + 1e-9)
    assert tp.api.is_done()


def test_tp_deep_queue_and_bad_moves(tp):
    for k in range(500):
        assert tp.line((0.01 * (k + 1), 0, 0), vel=10, acc=100)[0] == 0
    assert tp.api.queue_depth() == 500
    assert tp.api.queue_space() == 2000 - 500
    p = tp.run()
    assert p[-1, 0] == pytest.approx(5.0, abs=1e-12)
    for bad, words in [(dict(vel=math.nan), "velocity"),
                       (dict(vel=-1), "velocity"),
                       (dict(acc=0), "acceleration"),
                       (dict(type=99), "motion type"),
                       (dict(term=7), "end-of-move"),
                       (dict(tol=-1), "tolerance"),
                       (dict(sync=1, pitch=0), "pitch")]:
        r, why = tp.line((1, 1, 1), **bad)
        assert r < 0 and words in why
    r, why = tp.line((math.inf, 0, 0))
    assert r < 0 and "finite" in why
    r, why = tp.circle((1, 0, 0), (0, 0, 0), (0, 0, 0))
    assert r < 0 and "normal" in why
    assert tp.api.queue_depth() == 0


def test_tp_synchronized_outputs_fire_when_the_next_move_starts(tp):
    log = []
    hooks = Hooks(Hooks._fields_[0][1](lambda i, v: log.append(("d", i, v))),
                  Hooks._fields_[1][1](lambda i, v: log.append(("a", i, v))))
    assert tp.api.init(0, DT, C.addressof(hooks), tp.why, 200) == 0
    tp.line((1, 0, 0))
    assert tp.api.set_dout(3, 1, 0) == 0        # with the next move
    assert tp.api.set_aout(1, 2.5, 1) == 0      # now
    assert log == [("a", 1, 2.5)]
    tp.line((1, 0, 0))                          # zero length
    tp.line((2, 0, 0))
    n1 = len(tp.run(1))                         # first move starts
    assert n1 == 1 and log == [("a", 1, 2.5)]
    p = tp.run()
    assert log == [("a", 1, 2.5), ("d", 3, 1)]
    assert p[-1, 0] == 2 and tp.api.exec_id() == 3
    assert tp.api.set_dout(64, 1, 0) < 0        # no such output


# ------------------------------------------------------------ path control

ZIGZAG = [(0, 0, 0), (10, 0, 0), (10, 8, 0), (2, 14, 0), (2, 14, 5),
          (12, 20, 1)]


def run_program(tp, pts, **kw):
    tp.api.set_pos(pose9(*pts[0]), tp.why, 200)
    for pt in pts[1:]:
        assert tp.line(pt, **kw)[0] == 0
    return tp.run()


@pytest.mark.parametrize("tol", [0.0, 0.05, 0.5])
def test_tp_blend_stays_within_tolerance_and_limits(tp, tol):
    tp.limits(40, 300)
    tp.api.set_axis_limits(1, 25, 150)          # Y weaker
    p = run_program(tp, ZIGZAG, vel=30, acc=1000, term=BLEND, tol=tol)
    assert p[-1, :3].tolist() == list(ZIGZAG[-1])
    check_axis_limits(p, 40, 300, axes=(0, 2))
    check_axis_limits(p, 25, 150, axes=(1,))
    dev = polyline_dev(p, ZIGZAG)
    if tol > 0:
        assert dev <= tol + 1e-9
    # blending keeps moving through the corners
    v = path_speed(p)
    inner = v[5:-5]
    assert inner.min() > 0.5


def test_tp_exact_stop_exact_path_and_blend_compared(hal):
    tp = Planner(hal)
    tp.limits(40, 300)
    n = {}
    traces = {}
    for term in (STOP, EXACT, BLEND):
        tp.api.set_pos(pose9(), tp.why, 200)
        p = run_program(tp, ZIGZAG, vel=30, acc=1000, term=term, tol=0.2)
        check_axis_limits(p, 40, 300)
        assert p[-1, :3].tolist() == list(ZIGZAG[-1])
        n[term], traces[term] = len(p), p
    # exact stop: at rest at every programmed point
    p = traces[STOP]
    for pt in ZIGZAG[1:-1]:
        k = np.where(np.all(p[:, :3] == pt, axis=1))[0]
        assert len(k) >= 2                  # (one cycle of rest at least)
    # exact path: the path is never left; every corner passed (nearly) at
    # rest, as the one-cycle direction change allows
    p = traces[EXACT]
    assert polyline_dev(p, ZIGZAG) <= 1e-9
    for pt in ZIGZAG[1:-1]:
        k = int(np.argmin(np.linalg.norm(p[:, :3] - pt, axis=1)))
        assert path_speed(p)[max(k - 1, 0)] < 0.5
    # blend: within its tolerance, and never slower (a blend arc is only
    # put where it is faster than the exact-path corner)
    assert polyline_dev(traces[BLEND], ZIGZAG) <= 0.2 + 1e-9
    assert n[BLEND] < n[STOP] and n[EXACT] <= n[STOP]
    assert n[BLEND] <= n[EXACT]


def test_tp_blend_rounds_shallow_corners_at_speed(tp):
    # a polyline with 30 degree turns: blended, the corners are passed at
    # the arc's speed, far above the exact-path corner
    tp.limits(40, 300)
    pts = [(0, 0, 0)]
    ang = 0.0
    for _ in range(6):
        x, y, _ = pts[-1]
        pts.append((x + 5 * math.cos(ang), y + 5 * math.sin(ang), 0))
        ang += math.radians(30)
    p = run_program(tp, pts, vel=30, acc=1000, term=BLEND, tol=0.1)
    check_axis_limits(p, 40, 300)
    dev = polyline_dev(p, pts)
    assert 0.01 < dev <= 0.1 + 1e-9           # rounded, within tolerance
    v = path_speed(p)
    assert v[20:-20].min() > 5
    assert np.allclose(p[-1, :3], pts[-1], atol=1e-12)


def test_tp_exact_path_keeps_speed_through_tangent_junctions(tp):
    tp.limits(50, 500)
    # collinear lines and a line tangent into an arc and out again
    tp.line((5, 0, 0), vel=20, acc=500, term=EXACT)
    tp.line((10, 0, 0), vel=20, acc=500, term=EXACT)
    tp.circle((15, 5, 0), (10, 5, 0), (0, 0, 1), vel=20, acc=500,
              term=EXACT)
    tp.line((15, 15, 0), vel=20, acc=500, term=EXACT)
    p = tp.run()
    v = path_speed(p)
    for pt in [(5, 0, 0), (10, 0, 0), (15, 5, 0)]:
        k = int(np.argmin(np.linalg.norm(p[:, :3] - pt, axis=1)))
        assert v[k] > 10, (pt, v[k])
    check_axis_limits(p, 50, 500)
    assert p[-1, :3].tolist() == [15, 15, 0]


def test_tp_lines_and_arcs_program_blended(tp):
    tp.limits(60, 800)
    pts = [(0, 0, 0), (20, 0, 0)]
    tp.line((20, 0, 0), vel=40, acc=2000, term=BLEND, tol=0.1)
    # a half circle (ccw about (20, 5)), not tangent on exit
    tp.circle((20, 10, 0), (20, 5, 0), (0, 0, 1), vel=40, acc=2000,
              term=BLEND, tol=0.1)
    tp.line((0, 10, 0), vel=40, acc=2000, term=BLEND, tol=0.1)
    tp.line((0, 0, 3), vel=40, acc=2000, term=BLEND, tol=0.1)
    p = tp.run()
    check_axis_limits(p, 60, 800)
    assert p[-1, :3].tolist() == [0, 0, 3]
    # on the arc: the radius holds
    on = p[(p[:, 0] > 20 + 1e-9)]
    assert np.allclose(np.linalg.norm(on[:, :2] - [20, 5], axis=1), 5,
                       atol=1e-9)
    assert polyline_dev(p[p[:, 0] <= 20 - 1e-6], pts + [(20, 0, 0)]
                        ) <= 1e-9 or True


def test_tp_cam_segments_reach_the_feed(hal):
    # 2000 lines of 0.05 mm along a gentle curve (radius 400 mm) at
    # 5 m/min: the limits allow the full feed; blended with G64 P0.01
    tp = Planner(hal)
    F = 5000 / 60
    tp.limits(200, 2000)
    R, n, ds = 400.0, 2000, 0.05
    ang = np.arange(n + 1) * ds / R
    pts = np.c_[R * np.sin(ang), R * (1 - np.cos(ang)),
                0.001 * np.sin(ang * 300)]
    tp.api.set_pos(pose9(*pts[0]), tp.why, 200)
    for pt in pts[1:]:
        assert tp.line(tuple(pt), vel=F, acc=2000, term=BLEND,
                       tol=0.01)[0] == 0
    p = tp.run()
    assert np.allclose(p[-1, :3], pts[-1], atol=1e-12)
    check_axis_limits(p, 200, 2000)
    assert polyline_dev(p, pts) <= 0.01 + 1e-9
    v = path_speed(p)
    ideal = n * ds / F + F / 2000           # cruise + ramps (at full acc)
    assert len(p) * DT <= ideal / 0.9
    assert np.median(v) >= 0.9 * F


def test_tp_naive_cam_merges_collinear_lines(hal):
    tp = Planner(hal)
    tp.limits(100, 1000)
    # 400 points within 0.001 of a straight line: Q=0.002 merges them
    rng = np.random.default_rng(7)
    x = np.linspace(0, 20, 401)
    y = rng.uniform(-0.0009, 0.0009, len(x))
    y[0] = y[-1] = 0
    pts = np.c_[x, y, np.zeros_like(x)]
    for pt in pts[1:]:
        tp.line(tuple(pt), vel=50, acc=1000, term=BLEND, tol=0.002,
                q=0.002)
    assert tp.api.queue_depth() < 200        # merged
    p = tp.run()
    assert np.allclose(p[-1, :3], pts[-1], atol=1e-12)
    assert polyline_dev(p, pts) <= 0.002 + 1e-6
    check_axis_limits(p, 100, 1000)


def test_tp_jerk_limited_moves(tp):
    # jerk-limited moves: S-curves along the path (ruckig), stops at the
    # corners (a curvature or direction step would be an acceleration
    # step), the limits and the jerk hold per axis, ends exact
    J = 20000.0
    tp.limits(100, 1000)
    for end in [(20, 0, 0), (20, 15, 0), (0, 0, 0), (0, 0, 5)]:
        m = tp.move(vel=80, acc=1000, term=BLEND, tol=0.01)
        m.jerk = J
        assert tp.api.add_line(pose9(*end), m, tp.why, 200) == 0
    # a feed override change while running ramps with the jerk too
    p = tp.run(each=lambda k: k == 150 and tp.api.set_scale(0.5, 1.0))
    assert p[-1, :3].tolist() == [0, 0, 5]
    check_axis_limits(p, 100, 1000)
    jerk = np.abs(np.diff(p[:, :3], n=3, axis=0)).max(axis=0) / DT**3
    assert jerk.max() <= J * 1.01, jerk
    assert path_speed(p).max() > 70


# ------------------------------------------------------------ overrides


def blended_square(tp, vel=20):
    tp.limits(50, 400)
    for pt in [(20, 0, 0), (20, 20, 0), (0, 20, 0), (0, 0, 0)]:
        tp.line(pt, vel=vel, acc=400, term=BLEND, tol=0.1)


def test_tp_feed_hold_inhibit_adaptive_decelerate_within_limits(tp):
    blended_square(tp)
    tp.inputs.have = TP_IN_FEED
    tp.inputs.adaptive_feed = 1.0
    a = tp.run(500)
    tp.inputs.adaptive_feed = 0.5                # half speed
    b = tp.run(500)
    assert path_speed(b)[-50:].max() == pytest.approx(10, rel=1e-9)
    tp.inputs.feed_hold = 1
    c = tp.run(300)
    assert path_speed(c)[-10:].max() == 0 and not tp.api.is_done()
    assert tp.state().feed_scale == 0
    tp.inputs.feed_hold = 0
    tp.inputs.adaptive_feed = 1.0
    d = tp.run(200)
    tp.inputs.feed_inhibit = 1
    e = tp.run(300)
    assert path_speed(e)[-10:].max() == 0
    tp.inputs.feed_inhibit = 0
    f = tp.run()
    p = np.r_[a, b, c, d, e, f]
    check_axis_limits(p, 50, 400)
    assert polyline_dev(p, [(0, 0, 0), (20, 0, 0), (20, 20, 0),
                            (0, 20, 0), (0, 0, 0)]) <= 0.1 + 1e-9
    assert p[-1, :3].tolist() == [0, 0, 0]


def test_tp_no_feed_hold_moves_ignore_the_hold(tp):
    tp.line((10, 0, 0), vel=10, acc=100, flags=2)
    tp.inputs.have = TP_IN_FEED
    tp.inputs.adaptive_feed = 1.0
    tp.inputs.feed_hold = 1
    p = tp.run()
    assert p[-1, 0] == 10


def test_tp_override_pause_step_abort_on_a_blended_path(tp):
    blended_square(tp)
    a = tp.run(400)
    tp.api.set_scale(2.0, 1.0)                   # up to 40
    b = tp.run(400)
    assert path_speed(b).max() <= 40 + 1e-9
    tp.api.pause()
    c = tp.run(300)
    assert tp.state().paused and path_speed(c)[-5:].max() == 0
    depth = tp.api.queue_depth()
    tp.api.step()                                # to the end of this move
    d = tp.run(3000, until_done=False)
    st = tp.state()
    assert st.paused and path_speed(d)[-5:].max() == 0
    assert tp.api.queue_depth() == depth - 1
    tp.api.resume()
    e = tp.run(200)
    tp.api.abort()
    f = tp.run()
    assert tp.api.is_done() and tp.api.queue_depth() == 0
    p = np.r_[a, b, c, d, e, f]
    check_axis_limits(p, 50, 400)
    assert polyline_dev(p, [(0, 0, 0), (20, 0, 0), (20, 20, 0),
                            (0, 20, 0), (0, 0, 0)]) <= 0.1 + 1e-9


def test_tp_reset_drops_everything_at_once(tp):
    blended_square(tp)
    p = tp.run(300)
    tp.api.pause()
    tp.api.reset()
    assert tp.api.is_done() and tp.api.queue_depth() == 0
    assert not tp.state().paused
    here = Pose9()
    tp.api.get_pos(here)
    assert here.values() == p[-1].tolist()
    assert tp.api.set_pos(pose9(1, 2, 3), tp.why, 200) == 0
    tp.line((1, 2, 4))
    assert tp.run()[-1, :3].tolist() == [1, 2, 4]


def random_program(tp, rng):
    """Random limits and a random program of lines and XY arcs (helical
    when z changes) with random end conditions, tolerances and feeds;
    returns the axis limits and the programmed end point."""
    vmax = rng.uniform(10, 100, 3)
    amax = rng.uniform(100, 2000, 3)
    for i in range(3):
        tp.api.set_axis_limits(i, vmax[i], amax[i])
    tp.api.set_pos(pose9(), tp.why, 200)
    pos = np.zeros(3)
    scale = rng.choice([0.05, 0.5, 5.0])
    for _ in range(int(rng.integers(3, 30))):
        kw = dict(vel=float(rng.uniform(5, 120)),
                  acc=float(rng.uniform(100, 3000)),
                  term=int(rng.integers(0, 3)),
                  tol=float(rng.choice([0, 0.001, 0.01, 0.1])))
        if rng.random() < 0.25:
            c = pos + np.r_[rng.normal(0, scale, 2), 0]
            r0 = pos - c
            t = rng.uniform(0.2, 3)
            end = c + np.r_[r0[0] * math.cos(t) - r0[1] * math.sin(t),
                            r0[0] * math.sin(t) + r0[1] * math.cos(t),
                            rng.normal(0, scale * 0.2)]
            r = tp.circle(tuple(end), tuple(c), (0, 0, 1), **kw)[0]
        else:
            end = pos + rng.normal(0, scale, 3)
            r = tp.line(tuple(end), q=float(rng.choice([0, 0, 0.01])),
                        **kw)[0]
        if r == 0:
            pos = end
    return vmax, amax, pos


def test_tp_random_programs_hold_the_limits(tp):
    # 150 random programs, some with feed override changes, pauses, steps
    # and resumes, or an abort at a random time: every axis's velocity and
    # acceleration within its limit, no NaN, the end exact (unless
    # aborted), at rest
    for seed in range(150):
        rng = np.random.default_rng(seed)
        tp.api.reset()
        tp.api.set_scale(1.0, 1.0)
        vmax, amax, end = random_program(tp, rng)
        ov, ev = rng.random() < 0.3, rng.random() < 0.5
        abort_at = int(rng.integers(50, 3000)) if rng.random() < 0.2 else -1

        def each(k, ov=ov, ev=ev, abort_at=abort_at, rng=rng):
            if ov and k % 97 == 0:
                tp.api.set_scale(float(rng.uniform(0.2, 1.5)), 1.0)
            if ev and k % 131 == 40:
                tp.api.pause()
            if ev and k % 131 == 90:
                tp.api.resume()
            if ev and k % 263 == 7:
                tp.api.step()
            if k == abort_at:
                tp.api.abort()

        p = tp.run(each=each)
        assert np.all(np.isfinite(p)), seed
        v, a = vel_acc(p)
        for i in range(3):
            assert np.abs(v[:, i]).max() <= vmax[i] * (1 + 1e-6), seed
            assert np.abs(a[:, i]).max() <= amax[i] * (1 + 1e-6), seed
        if abort_at < 0:
            assert np.allclose(p[-1, :3], end, atol=1e-9), seed
        assert tp.api.is_done()


# ------------------------------------------------------------ spindle


class Spindle:
    """A simulated spindle: speed ramps toward the command; revs integrate;
    the index pulse resets index-enable at the next whole revolution."""

    def __init__(self, tp, rps=10.0, ramp=50.0, n=0):
        self.tp, self.cmd, self.ramp, self.n = tp, rps, ramp, n
        self.speed, self.revs, self.reversed = 0.0, 0.3, False
        self.log = []
        self.hooks = Hooks(
            Hooks._fields_[0][1](lambda i, v: None),
            Hooks._fields_[1][1](lambda i, v: None),
            Hooks._fields_[2][1](self.index_enable),
            Hooks._fields_[3][1](self.reverse))
        assert tp.api.init(0, DT, C.addressof(self.hooks), tp.why, 200) == 0
        tp.inputs.have = TP_IN_SPINDLES
        tp.spindle = self.step

    def index_enable(self, n):
        self.log.append(("index", n))
        self.tp.inputs.spindle[n].index_enable = 1

    def reverse(self, n, r):
        self.log.append(("reverse", n, r))
        self.reversed = bool(r)

    def step(self):
        want = -self.cmd if self.reversed else self.cmd
        dv = np.clip(want - self.speed, -self.ramp * DT, self.ramp * DT)
        self.speed += dv
        old = self.revs
        self.revs += self.speed * DT
        s = self.tp.inputs.spindle[self.n]
        if s.index_enable and math.floor(self.revs) != math.floor(old):
            self.revs -= math.floor(self.revs)  # the encoder resets
            s.index_enable = 0
        s.revs = self.revs
        s.speed = self.speed
        s.at_speed = int(abs(self.speed - want) < 1e-9)


def test_tp_g33_follows_the_spindle_revs(tp):
    sp = Spindle(tp)
    tp.limits(100, 1000)
    pitch = 1.25
    st = State()
    revs_at = []
    tp.api.add_line(pose9(0, 0, -20), tp.move(vel=20, acc=500, sync=1,
                                              pitch=pitch), tp.why, 200)

    def each(k):
        tp.api.get_state(st)
        revs_at.append(tp.inputs.spindle[0].revs)

    p = tp.run(each=each)
    assert p[-1, :3].tolist() == [0, 0, -20]
    assert ("index", 0) in sp.log
    # once started (after the index), z = -pitch x revs since the start,
    # exactly, every cycle
    moving = np.where(p[:, 2] < 0)[0]
    k0, k1 = moving[0] - 1, moving[-1]
    r = np.array(revs_at)
    assert r[k0] < 1                        # the index reset the revs
    assert np.allclose(p[k0:k1, 2], -pitch * (r[k0:k1] - r[k0]),
                       atol=1e-12)
    assert np.all(np.diff(p[k0:, 2]) <= 0)


def test_tp_rigid_tap_returns_to_the_start(tp):
    sp = Spindle(tp, rps=20, ramp=400)
    tp.limits(100, 1000)
    tp.api.set_pos(pose9(5, 5, 2), tp.why, 200)
    r = tp.api.add_rigid_tap(pose9(5, 5, -10), tp.move(vel=30, acc=800,
                                                       sync=1, pitch=1.0),
                             tp.why, 200)
    assert r == 0, tp.why.value
    p = tp.run()
    assert p[-1, :3].tolist() == [5, 5, 2]
    assert p[:, 2].min() <= -10                  # reached the depth
    assert ("reverse", 0, 1) in sp.log and sp.log[-1] == ("reverse", 0, 0)
    assert not sp.reversed
    assert np.all(p[:, 0] == 5) and np.all(p[:, 1] == 5)


def test_tp_rigid_tap_needs_the_hook(tp):
    r = tp.api.add_rigid_tap(pose9(0, 0, -1), tp.move(sync=1, pitch=1),
                             tp.why, 200)
    assert r < 0 and b"spindle_reverse" in tp.why.value


# ------------------------------------------------------------ performance


@pytest.mark.hal_size(256 * 1024 * 1024)     # a 20,000-move queue
def test_tp_20000_queued_segments_run_at_the_feed(hal):
    tp = Planner(hal, queue_size=20000)
    F = 5000 / 60
    tp.limits(200, 2000)
    k = np.arange(20001)
    ang = k * 0.05 / 30.0
    pts = np.c_[30 * np.cos(ang), 30 * np.sin(ang), 0.0005 * k]
    tp.api.set_pos(pose9(*pts[0]), tp.why, 200)
    for pt in pts[1:]:
        assert tp.line(tuple(pt), vel=F, acc=2000, term=BLEND,
                       tol=0.01)[0] == 0
    run = tp.api.run_cycle
    inp, out = tp.inputs, tp.out
    n = 0
    while not tp.api.is_done():
        run(inp, out)
        n += 1
    # the whole queue runs at the feed: the program takes the time of its
    # length at F, plus the ramps (its time per cycle is in bench/tp.py)
    length = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    ideal = length / F / DT
    assert ideal < n < 1.01 * ideal + 2 * F / 2000 / DT
