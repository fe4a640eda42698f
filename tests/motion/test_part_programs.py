"""Part programs of lines and arcs on a simulated machine (issue 7, Tests).

Each test builds a machine with tests/helpers/motion_trace.py (motmod, trivkins,
homemod, tpmod; every joint's motor-pos-cmd looped to its motor-pos-fb;
homed on the spot; coordinated mode), queues a program through
halsdk.motion, steps the servo thread deterministically and checks the
trace recorded every cycle: distance from the programmed path, per-axis
velocity / acceleration (/ jerk) from finite differences against the axis
limits, final positions, stops, feed, override, pause, abort, probing.
"""

from __future__ import annotations

import importlib.util
import math
import os
import sys

import numpy as np
import pytest
from helpers import REPO
from helpers import motion_trace as mt
from helpers.motion_trace import Arc, Line, PathMode, Probe

ROOT = str(REPO)
CONTOUR = os.path.join(ROOT, "examples", "contour", "contour.py")

# a small mill: X Y fast, Z slower (mm, s)
VEL = {"x": 100.0, "y": 100.0, "z": 40.0, "a": 360.0, "u": 80.0, "v": 80.0,
       "w": 30.0}
ACC = {"x": 1000.0, "y": 1000.0, "z": 400.0, "a": 3600.0, "u": 800.0,
       "v": 800.0, "w": 300.0}
EPS = 1e-9


def mill(hal, coordinates="xyz", **kw):
    ini = mt.machine_ini(coordinates, vel=VEL, acc=ACC, **kw)
    return mt.build_machine(hal, coordinates, ini)


def check_limits(trace, machine, jerk=False):
    bad = mt.limit_violations(trace, machine, jerk=jerk)
    assert not bad, f"axis limits exceeded: {bad}"


def check_end(trace, program):
    end = mt.program_end(program, trace.start)
    assert trace.pos[-1].tolist() == end.tolist(), \
        f"ends at {trace.pos[-1]}, programmed {end}"


def rounded_polygon(n=6, r=20.0, fillet=2.0, feed=60.0, z=0.0):
    """A regular n-gon of radius r centred on (0, 0) with arcs of radius
    ``fillet`` at its corners (lines tangent to arcs), counterclockwise;
    starts at the middle of the first side."""
    corners = [(r * math.cos(2 * math.pi * k / n),
                r * math.sin(2 * math.pi * k / n)) for k in range(n)]
    half = math.pi / n                          # half the exterior turn
    prog = []
    pts = []
    for k in range(n):
        c = np.array(corners[k])
        prv = np.array(corners[k - 1])
        nxt = np.array(corners[(k + 1) % n])
        d_in = (c - prv) / np.linalg.norm(c - prv)
        d_out = (nxt - c) / np.linalg.norm(nxt - c)
        back = fillet * math.tan(half)          # tangent length
        p_in = c - d_in * back
        p_out = c + d_out * back
        center = p_in + fillet * np.array([-d_in[1], d_in[0]])
        pts.append((p_in, p_out, center))
    first = 0.5 * (np.array(corners[0]) + np.array(corners[-1]))
    prog.append(Line({"x": first[0], "y": first[1], "z": z}, feed,
                     rapid=True))
    for p_in, p_out, center in pts:
        prog.append(Line({"x": p_in[0], "y": p_in[1]}, feed))
        prog.append(Arc({"x": p_out[0], "y": p_out[1]},
                        center=(center[0], center[1], z), feed=feed))
    prog.append(Line({"x": first[0], "y": first[1]}, feed))
    return prog


def zigzag(n=12, dx=2.0, dy=6.0, feed=80.0, z=0.0):
    """Sharp corners: a zigzag of n lines (each corner turns ~143 deg)."""
    prog = [Line({"x": 0, "y": 0, "z": z}, feed)]
    for k in range(1, n + 1):
        prog.append(Line({"x": k * dx, "y": dy if k % 2 else 0.0}, feed))
    return prog


def corners_of(program, start):
    """Vertices where consecutive lines meet (the inner ones)."""
    pts, _ = mt.program_path(program, start)
    pts = pts[:, :3]
    keep = np.concatenate([[True], np.any(np.diff(pts, axis=0) != 0,
                                          axis=1)])
    return pts[keep][1:-1]


def min_speed_near(trace, point, radius):
    v = trace.path_speed()
    d = np.linalg.norm(trace.pos[:, :3] - point, axis=1)
    return float(v[d <= radius].min())


# ---------------------------------------------------------------- blending


@pytest.mark.parametrize("tol", [0.01, 0.1])
def test_blended_zigzag_stays_within_tolerance_and_never_stops(hal, tol):
    m = mill(hal)
    prog = [PathMode("blend", tol)] + zigzag()
    tr = m.run(prog)
    dev = mt.path_deviation(tr, prog)
    assert dev.max() <= tol * (1 + 1e-6) + EPS, dev.max()
    # it did cut the corners (a blend, not an exact stop), by a
    # visible part of the tolerance
    assert dev.max() > 0.2 * tol
    assert mt.stops(tr) == []
    check_limits(tr, m)
    check_end(tr, prog)


def test_larger_tolerance_runs_faster_and_exact_stop_slowest(hal):
    m = mill(hal)
    times = {}
    for shape, n, dx, dy in (("sharp", 12, 2.0, 6.0),      # 143-deg turns
                             ("shallow", 12, 6.0, 2.0)):   # 37-deg turns
        for mode, tol in (("stop", 0), ("blend", 0.01), ("blend", 0.2)):
            prog = [PathMode(mode, tol)] + zigzag(n, dx, dy, z=-1.0)
            tr = m.run(prog)
            times[(shape, mode, tol)] = mt.moving_time(tr)
            check_limits(tr, m)
            m.run([Line({"x": 0, "y": 0, "z": 0}, 100, rapid=True)])
    # sharp corners: a 0.01 blend passes at a few mm/s, about as long as
    # stopping (not much longer); shallow ones: the larger the tolerance,
    # the faster (0.2 lets the corners pass at ~55 mm/s)
    assert times[("sharp", "blend", 0.01)] <= \
        1.05 * times[("sharp", "stop", 0)]
    assert times[("sharp", "blend", 0.2)] < times[("sharp", "blend", 0.01)]
    assert times[("shallow", "blend", 0.2)] < \
        times[("shallow", "blend", 0.01)] < times[("shallow", "stop", 0)]
    assert times[("shallow", "blend", 0.2)] < \
        0.8 * times[("shallow", "stop", 0)]


def test_rounded_polygon_tangent_arcs_blend_at_full_feed(hal):
    m = mill(hal)
    feed = 60.0
    prog = [PathMode("blend", 0.005)] + rounded_polygon(feed=feed)
    tr = m.run(prog)
    check_end(tr, prog)
    check_limits(tr, m)
    dev = mt.path_deviation(tr, prog)
    assert dev.max() <= 0.005 + EPS
    # no stop between the rapid and the contour either: the lines meet
    # the arcs tangentially, so the speed along the contour stays high;
    # the arcs (r 2 mm) allow sqrt(1000 * 2) = 44.7 mm/s
    v = tr.path_speed()
    assert mt.stops(tr) == []
    moving = v[v > 0]
    assert np.percentile(moving, 20) > 0.6 * math.sqrt(1000 * 2)
    if m.streaming:
        # motion.program-line follows the program: lines 2 .. n+1 in order
        ids = tr.line[tr.line > 0]
        assert np.all(np.diff(ids) >= 0)
        assert ids[0] == 2 and ids[-1] == len(prog)


def test_exact_stop_stops_at_every_corner_on_the_path(hal):
    m = mill(hal)
    prog = [PathMode("stop")] + zigzag(n=6)
    tr = m.run(prog)
    dev = mt.path_deviation(tr, prog)
    assert dev.max() <= 1e-9
    corners = corners_of(prog, tr.start)
    # one stop per corner (the first line starts where the machine is)
    assert len(mt.stops(tr)) == len(corners)
    for c in corners:
        d = np.linalg.norm(tr.pos[:, :3] - c, axis=1)
        assert d.min() == 0.0, f"corner {c} not reached exactly"
    check_limits(tr, m)
    check_end(tr, prog)


def test_exact_path_follows_corners_and_keeps_speed_on_tangents(hal):
    m = mill(hal)
    feed = 60.0
    prog = [PathMode("exact")] + rounded_polygon(n=4, fillet=5,
                                                 feed=feed) + zigzag(n=3)
    tr = m.run(prog)
    dev = mt.path_deviation(tr, prog)
    assert dev.max() <= 1e-6
    # sharp zigzag corners: (nearly) at rest there
    for c in corners_of(zigzag(n=3), tr.start)[1:]:
        assert min_speed_near(tr, c, 0.05) <= ACC["x"] * 2e-3
    # tangent line/arc junctions of the rounded square (r 5: the arcs
    # allow sqrt(1000 * 5) = 70 > 60): no slow-down to rest there
    pts, owner = mt.program_path(prog, tr.start)
    junction = pts[np.flatnonzero(np.diff(owner) != 0)][3, :3]
    assert min_speed_near(tr, junction, 0.2) > 0.5 * feed
    check_limits(tr, m)
    check_end(tr, prog)


# ---------------------------------------------------------------- geometry


def test_3d_contour_with_slow_z_holds_every_axis_limit(hal):
    m = mill(hal)
    tol = 0.02
    pts = [(5, 0, -1), (10, 5, -3), (10, 10, 0), (4, 12, -5), (0, 6, -2),
           (3, 3, -8), (8, 1, -4), (0, 0, 0)]
    prog = [PathMode("blend", tol)] + [
        Line({"x": x, "y": y, "z": z}, 90.0) for x, y, z in pts]
    tr = m.run(prog)
    dev = mt.path_deviation(tr, prog)
    assert dev.max() <= tol + EPS
    check_limits(tr, m)
    ext = mt.axis_extremes(tr, "z")["z"]
    # Z did work near its limits (the program asks for more than it can)
    assert ext["vel"] > 0.6 * VEL["z"] or ext["acc"] > 0.6 * ACC["z"]
    check_end(tr, prog)


@pytest.mark.parametrize("normal,end", [
    ((0, 0, 1), {"x": 0, "y": 0, "z": -6}),     # XY helix
    ((0, 1, 0), {"x": 0, "y": -4, "z": 0}),     # XZ plane, along -Y
    ((1, 0, 0), {"x": 3, "y": 0, "z": 0}),      # YZ plane, along X
])
def test_helix_in_any_plane_is_followed_exactly(hal, normal, end):
    m = mill(hal)
    n = np.array(normal, float)
    # start 5 mm off the axis through the origin, perpendicular to n
    u = np.array([0, 0, 1.0]) if n[2] == 0 else np.array([1.0, 0, 0])
    u = u - (u @ n) * n
    p0 = 5 * u / np.linalg.norm(u)
    end = dict(end)
    for k, a in enumerate("xyz"):
        if n[k] == 0:
            end[a] = p0[k]
    prog = [PathMode("blend", 0.01),
            Line({"x": p0[0], "y": p0[1], "z": p0[2]}, 50, rapid=True),
            Arc(end, center=(0, 0, 0), normal=normal, feed=50, turn=2)]
    tr = m.run(prog)
    dev = mt.path_deviation(tr, prog)
    # the rapid's end blends into the helix; the rest is on the helix
    k = int(np.argmin(np.linalg.norm(tr.pos[:, :3] - p0, axis=1)))
    assert dev.max() <= 0.01 + EPS
    assert dev[k + 50:].max() <= 1e-6
    # on the cylinder of radius 5 ...
    q = tr.pos[k:, :3]
    rad = np.linalg.norm(np.cross(q[50:], n), axis=1)
    assert np.allclose(rad, 5.0, atol=1e-6)
    # ... three turns counterclockwise about n (turn=2: two extra), with
    # the axial travel proportional to the angle
    w = np.cross(n, u / np.linalg.norm(u))
    ang = np.unwrap(np.arctan2(q @ w, q @ (u / np.linalg.norm(u))))
    assert ang[-1] - ang[0] == pytest.approx(3 * 2 * math.pi, abs=1e-6)
    axial = q @ n
    h = axial[-1] - axial[0]
    expect = axial[0] + h * (ang - ang[0]) / (ang[-1] - ang[0])
    assert np.abs(axial[50:] - expect[50:]).max() <= 1e-6
    check_limits(tr, m)
    check_end(tr, prog)


def test_rotary_axis_with_linear_moves_holds_its_own_limits(hal):
    m = mill(hal, "xyza")
    prog = [PathMode("blend", 0.01),
            Line({"x": 10, "a": 720}, 50),          # A dominates
            Line({"x": 20, "a": 720}, 50),
            Line({"x": 0, "y": 5, "a": 0}, 50),
            Line({"a": 90}, 50)]                    # A alone
    tr = m.run(prog)
    check_limits(tr, m)
    ext = mt.axis_extremes(tr, "a")["a"]
    assert ext["vel"] > 0.9 * VEL["a"]              # A ran at its limit
    dev = mt.path_deviation(tr, prog, axes="xyza")
    assert dev.max() <= 0.01 + EPS
    check_end(tr, prog)


def test_uvw_axes_move_with_xyz(hal):
    m = mill(hal, "xyzuvw")
    prog = [PathMode("blend", 0.01),
            Line({"x": 5, "u": 10, "w": -3}, 60),
            Line({"y": 5, "v": 8}, 60),
            Arc({"x": 0, "y": 0, "u": 0, "v": 0, "w": 0},
                center=(0, 5, 0), feed=40)]
    tr = m.run(prog)
    check_limits(tr, m)
    check_end(tr, prog)
    dev = mt.path_deviation(tr, prog, axes="xyzuvw")
    assert dev.max() <= 0.01 + EPS
    # the joints (trivkins) are the axes
    assert np.array_equal(tr.joints[:, 3], tr.pos[:, 6])
    assert np.array_equal(tr.joints[:, 5], tr.pos[:, 8])


def test_same_program_twice_gives_the_same_trace(hal):
    m = mill(hal)
    prog = [PathMode("blend", 0.05)] + rounded_polygon(n=5, feed=80) + [
        Line({"x": 0, "y": 0, "z": 0}, 100, rapid=True)]
    t1 = m.run(prog)
    t2 = m.run(prog)
    assert np.array_equal(t1.start, t2.start)
    assert len(t1) == len(t2) and np.array_equal(t1.pos, t2.pos)


def test_per_move_feeds_and_rapids(hal):
    m = mill(hal)
    prog = [PathMode("stop"), Line({"x": 20}, 10),
            Line({"x": 40}, 30), Line({"x": 0}, 1000, rapid=True)]
    m.motion.set_feed_scale(0.5)                  # not for the rapid
    tr = m.run(prog)
    v = tr.path_speed()
    x = tr.pos[:, 0]
    going = np.arange(len(x)) < np.argmax(x)
    assert v[going & (x > 2) & (x < 18)].max() == pytest.approx(5.0,
                                                                rel=1e-9)
    assert v[going & (x > 25) & (x < 38)].max() == pytest.approx(15.0,
                                                                 rel=1e-9)
    # the rapid: limited by X's velocity, not by the feed scale
    assert v[~going].max() == pytest.approx(VEL["x"], rel=1e-9)
    check_limits(tr, m)
    # the rapid scale applies to rapids only
    m.motion.set_feed_scale(1.0)
    m.motion.set_rapid_scale(0.25)
    # (a G0 asks for the machine's traverse rate, here X's limit)
    tr = m.run([Line({"x": 30}, VEL["x"], rapid=True), Line({"x": 0}, 20)])
    v = tr.path_speed()
    x = tr.pos[:, 0]
    going = np.arange(len(x)) < np.argmax(x)
    assert v[going].max() == pytest.approx(0.25 * VEL["x"], rel=1e-9)
    assert v[~going].max() == pytest.approx(20, rel=1e-9)


def test_jerk_limited_moves_hold_the_jerk_limit(hal):
    m = mill(hal)
    jerk = 20_000.0                         # mm/s^3, path
    mo = m.motion
    queue = mo.queue_line if m.streaming else mo.set_line
    start = m.start_recording()
    mo.set_term_cond(2, 0.01)
    queue({"x": 20}, 80, jerk=jerk)
    queue({"x": 20, "y": 15}, 80, jerk=jerk)
    queue({"x": 0, "y": 0}, 80, jerk=jerk)
    m.run_until_done()
    tr = mt.trim_rest(m.trace(start))
    assert tr.pos[-1, :2].tolist() == [0, 0]
    check_limits(tr, m)
    ext = mt.axis_extremes(tr, "xy")
    for a in "xy":
        assert ext[a]["jerk"] <= jerk * 1.01, (a, ext[a]["jerk"])
    # and it did not crawl: a jerk-limited ramp to 80 mm/s
    assert tr.path_speed().max() > 70


# ---------------------------------------------------------------- overrides


def _program_long(feed=60.0):
    return [PathMode("blend", 0.01)] + [
        Line({"x": 40 * (k % 2), "y": 2.0 * k}, feed) for k in range(1, 9)]


def test_feed_override_changes_speed_within_limits(hal):
    m = mill(hal)
    prog = _program_long()
    start = m.start_recording()
    m.queue_program(prog)
    m.step(300)
    m.motion.set_feed_scale(0.5)
    m.step(600)
    m.motion.set_feed_scale(1.5)
    m.run_until_done()
    tr = mt.trim_rest(m.trace(start))
    v = tr.path_speed()
    # the override never lets the path speed exceed feed x scale, and
    # the new speed is reached
    n_half = slice(400, 900)
    assert v[n_half].max() <= 30 * (1 + 1e-9)
    assert np.isclose(v[n_half], 30, rtol=1e-6).any()
    assert v.max() <= 90 * (1 + 1e-9) and v.max() > 85
    check_limits(tr, m)
    dev = mt.path_deviation(tr, prog)
    assert dev.max() <= 0.01 + EPS
    check_end(tr, prog)


def test_pause_decelerates_on_the_path_and_resume_finishes(hal):
    m = mill(hal)
    prog = _program_long(feed=80.0)
    start = m.start_recording()
    m.queue_program(prog)
    m.step(250)
    v0 = m.motion.status().current_vel
    beat = m.motion.status().heartbeat
    m.motion.pause()
    p_pause = m.position()
    st = m.motion.wait_for(lambda s: s.paused, timeout=1)
    p_rest = m.position()
    # it brakes promptly: within the distance and time of a braking with a
    # quarter of the acceleration limit (X, Y: 1000), plus a cycle
    a_min = 1000 / 4
    assert np.linalg.norm(p_rest - p_pause) <= v0 ** 2 / (2 * a_min) + \
        v0 * 1e-3
    assert st.heartbeat - beat <= math.ceil(v0 / a_min / 1e-3) + 2
    m.step(200)
    assert np.array_equal(m.position(), p_rest)     # it stays put
    assert st.queue_depth > 0
    m.motion.resume()
    m.run_until_done()
    tr = mt.trim_rest(m.trace(start))
    check_limits(tr, m)
    assert mt.path_deviation(tr, prog).max() <= 0.01 + EPS
    assert len(mt.stops(tr)) == 1                    # only the pause
    check_end(tr, prog)


def test_step_runs_one_move_at_a_time(hal):
    m = mill(hal)
    prog = [PathMode("stop"), Line({"x": 5}, 50),
            Line({"x": 5, "y": 5}, 50), Line({"x": 0, "y": 0}, 50)]
    m.motion.pause()
    m.queue_program(prog)
    m.step(50)
    assert np.array_equal(m.position(), np.zeros(9))    # paused
    for k in (1, 2):
        m.motion.step()
        m.step(10)
        st = m.motion.wait_for(lambda s: s.paused and s.current_vel == 0,
                               timeout=2)
        # at rest exactly at the end of the move
        end = mt.program_end(prog[:k + 1])
        assert m.position().tolist() == end.tolist()
        assert st.queue_depth == 3 - k
    m.motion.resume()
    m.run_until_done()
    assert m.position().tolist() == [0.0] * 9


def test_abort_stops_within_limits_and_empties_the_queue(hal):
    m = mill(hal)
    prog = _program_long(feed=80.0)
    start = m.start_recording()
    m.queue_program(prog)
    m.step(300)
    m.motion.abort()
    st = m.motion.wait_inpos(timeout=1)
    assert st.queue_depth == 0
    tr = m.trace(start)
    check_limits(tr, m)
    assert mt.path_deviation(tr, prog).max() <= 0.01 + EPS
    # a new program runs from where it stopped
    here = m.position()
    assert not np.array_equal(here, mt.program_end(prog, start))
    tr2 = m.run([Line({"x": 0, "y": 0}, 50)])
    assert tr2.pos[-1, :2].tolist() == [0, 0]


@pytest.mark.parametrize("pin", ["motion.feed-inhibit", "motion.feed-hold"])
def test_feed_inhibit_and_hold_stop_and_restart(hal, pin):
    m = mill(hal)
    if pin == "motion.feed-hold" and not _has_pin(hal, pin):
        pytest.skip("no motion.feed-hold pin")
    _enable_feed_hold(m)
    prog = _program_long(feed=80.0)
    start = m.start_recording()
    m.queue_program(prog)
    m.step(300)
    hal.set({pin: True})
    m.step(300)
    a = m.position()
    m.step(100)
    assert np.array_equal(m.position(), a), f"{pin} did not stop motion"
    assert m.motion.status().queue_depth > 0
    hal.set({pin: False})
    m.run_until_done()
    tr = mt.trim_rest(m.trace(start))
    check_limits(tr, m)
    assert mt.path_deviation(tr, prog).max() <= 0.01 + EPS
    check_end(tr, prog)


def test_adaptive_feed_scales_the_path_speed(hal):
    m = mill(hal)
    if not hasattr(m.motion, "set_adaptive_feed_enable"):
        pytest.skip("the client has no set_adaptive_feed_enable (M52)")
    hal.set({"motion.adaptive-feed": 0.25})
    tr = m.run([Line({"x": 30}, 40)])               # disabled: ignored
    assert tr.path_speed().max() == pytest.approx(40, rel=1e-9)
    m.motion.set_adaptive_feed_enable(True)
    start = m.start_recording()
    m.queue(Line({"x": 0}, 40))
    m.step(300)
    hal.set({"motion.adaptive-feed": 1.0})           # back to full speed
    m.run_until_done()
    tr = mt.trim_rest(m.trace(start))
    v = tr.path_speed()
    assert v[100:300].max() == pytest.approx(10, rel=1e-6)
    assert v.max() == pytest.approx(40, rel=1e-9)
    check_limits(tr, m)
    check_end(tr, [Line({"x": 0}, 40)])


def test_feed_hold_is_ignored_while_disabled(hal):
    m = mill(hal)
    if not hasattr(m.motion, "set_feed_hold_enable"):
        pytest.skip("the client has no set_feed_hold_enable (M53)")
    m.motion.set_feed_hold_enable(False)
    hal.set({"motion.feed-hold": True})
    tr = m.run(_program_long(feed=80.0))
    assert mt.stops(tr) == []
    check_end(tr, _program_long())
    m.motion.set_feed_hold_enable(True)         # now it holds
    start = m.start_recording()
    m.queue(Line({"x": 0, "y": 0}, 50))
    m.step(100)
    assert np.array_equal(m.position(), start)


def _has_pin(hal, name):
    return any(p.name == name for p in hal.pins(name))


def _enable_feed_hold(m):
    """Feed hold obeys its pin only when enabled (M53 P1): use the
    client's call when it has one."""
    for name in ("set_feed_hold_enable", "feed_hold_enable",
                 "enable_feed_hold"):
        fn = getattr(m.motion, name, None)
        if fn is not None:
            fn(True)
            return


# ---------------------------------------------------------------- probing


@pytest.mark.parametrize("away", [False, True])
def test_probe_records_the_position_of_the_trip_cycle(hal, away):
    m = mill(hal)
    hal.set({"motion.probe-input": away})
    start = m.start_recording()
    m.queue(Probe({"x": -20, "y": -10}, 40, away=away))
    m.step(400)
    hal.set({"motion.probe-input": not away})      # trips now
    m.step(1)
    tripped_at = m.position()
    m.motion.wait_done(timeout=2)
    st = m.motion.status()
    tr = m.trace(start)
    assert st.probe_tripped
    probed = np.array([getattr(st.probed_pos, a) for a in "xyz"])
    # the recorded point is where the commanded position was when the
    # input changed: within one servo period of motion (40 mm/s -> 0.04)
    assert np.linalg.norm(probed - tripped_at[:3]) <= 40 * 1e-3 + 1e-12
    # and on the probe line; the machine stopped past it, on the line too
    assert mt.path_deviation(tr, [Line({"x": -20, "y": -10}, 40)]).max() \
        <= 1e-9
    check_limits(tr, m)
    hal.set({"motion.probe-input": away})
    m.motion.clear_probe_flag()


def test_probe_without_contact_reports_an_error(hal):
    m = mill(hal)
    m.queue(Probe({"x": 3}, 40))
    m.motion.wait_done(timeout=2)
    st = m.motion.status()
    assert not st.probe_tripped
    assert st.carte_pos_cmd.x == 3
    assert any("probe" in e.lower() for e in m.motion.errors())


# ---------------------------------------------------------------- CAM-like


def cam_program(n=2000, seg=0.05, feed=5000 / 60, r=12.0, z_amp=1.0):
    """A CAM-like smooth 3D curve of n short lines (a wavy circle)."""
    s = np.arange(1, n + 1) * seg
    out = []
    # parameterize by arc length (approximately) of the wavy circle
    for k in range(n):
        t = s[k] / r
        rr = r + 1.5 * math.sin(3 * t)
        out.append(Line({"x": rr * math.cos(t) - r, "y": rr * math.sin(t),
                         "z": z_amp * (math.cos(2 * t) - 1)}, feed))
    return out


def test_short_segments_run_near_the_feed_the_limits_allow(hal):
    m = mill(hal)
    tol = 0.01
    prog = [PathMode("blend", tol)] + cam_program()
    # streamed through the move queue (many moves per cycle) when the
    # client has it; else queued while paused (one command per cycle
    # would starve the planner: 0.05 mm per ms < the feed)
    tr = m.run(prog, prequeue=not m.streaming)
    check_end(tr, prog)
    check_limits(tr, m)
    dev = mt.path_deviation(tr, prog)
    assert dev.max() <= tol + EPS
    pts, _ = mt.program_path(prog, tr.start)
    allowed = mt.allowed_time(pts, 5000 / 60, [VEL[a] for a in "xyz"],
                              [ACC[a] for a in "xyz"])
    took = mt.moving_time(tr)
    assert allowed / took >= 0.9, (allowed, took)
    assert mt.stops(tr) == []


def test_bench_program_20000_lines_streamed(hal):
    """bench/tp.py's program: 20,000 lines of 0.05 mm at F5000, streamed:
    no stop, the limits held, at least 90 % of the feed they allow."""
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    import tp as bench
    pts = bench.contour(20_000, 0.05)
    prog = bench.program(pts, 5000 / 60, 0.01)
    ini = mt.machine_ini("xyz", vel=bench.VEL, acc=bench.ACC,
                         traj_vel=200, traj_acc=3000)
    m = mt.build_machine(hal, "xyz", ini)
    tr = m.run(prog, timeout=60, prequeue=False)
    check_end(tr, prog)
    check_limits(tr, m)
    assert mt.stops(tr) == []
    allowed = mt.allowed_time(pts, 5000 / 60, [bench.VEL[a] for a in "xyz"],
                              [bench.ACC[a] for a in "xyz"])
    assert allowed / mt.moving_time(tr) >= 0.9


# ---------------------------------------------------------------- helpers


def _trace(points, start=None):
    p = np.zeros((len(points), 9))
    p[:, :3] = points
    z = np.zeros(len(points))
    return mt.Trace(p, p[:, :3], z, z.astype(int),
                    start=np.zeros(9) if start is None else start)


def test_trace_helpers_measure_what_they_say():
    prog = [Line({"x": 10}, 10), Arc({"x": 10, "y": 10}, center=(10, 5, 0),
                                     feed=10)]
    # points 0.3 off the line, then on the arc's radius + 0.2
    a = np.linspace(-math.pi / 2, math.pi / 2, 50)
    pts = np.vstack([np.column_stack([np.linspace(0, 10, 50),
                                      np.full(50, 0.3), np.zeros(50)]),
                     np.column_stack([10 + 5.2 * np.cos(a),
                                      5 + 5.2 * np.sin(a), np.zeros(50)])])
    dev = mt.path_deviation(_trace(pts), prog)
    assert dev[:50] == pytest.approx(0.3, abs=1e-6)
    assert dev[60:] == pytest.approx(0.2, abs=1e-6)
    assert mt.program_length(prog) == pytest.approx(10 + 5 * math.pi,
                                                    rel=1e-6)
    # a 1 mm line: at rest, 3 cycles still, moving again -> one stop
    x = np.concatenate([np.linspace(0.1, 0.5, 5), [0.5] * 3,
                        np.linspace(0.6, 1.0, 5)])
    tr = _trace(np.column_stack([x, 0 * x, 0 * x]))
    assert mt.stops(tr) == [(5, 3)]
    assert mt.moving_time(tr) == pytest.approx(13e-3)
    ext = mt.axis_extremes(tr, "x")["x"]
    assert ext["vel"] == pytest.approx(100.0)       # 0.1 mm per ms
    # the time bound of a straight line: a triangle or a trapezoid
    line = np.column_stack([np.linspace(0, 10, 1001), np.zeros(1001),
                            np.zeros(1001)])
    t = mt.allowed_time(line, 1e9, [1e9] * 3, [100.0] * 3)
    assert t == pytest.approx(2 * math.sqrt(10 / 100), rel=1e-3)
    t = mt.allowed_time(line, 5.0, [1e9] * 3, [100.0] * 3)
    assert t == pytest.approx(10 / 5 + 5 / 100, rel=1e-3)


# ---------------------------------------------------------------- example


@pytest.fixture(scope="module")
def contour():
    spec = importlib.util.spec_from_file_location("contour_example",
                                                  CONTOUR)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_contour_example_writes_a_plot_and_a_summary(contour, tmp_path,
                                                     capsys):
    out = tmp_path / "contour.png"
    summary = contour.main(["--small", "--out", str(out),
                            "--instance", f"test-contour-{os.getpid()}"])
    text = capsys.readouterr().out
    assert isinstance(summary, dict)
    assert out.exists() and out.stat().st_size > 10_000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert summary["segments"] > 100
    assert 0 < summary["max_deviation"] <= summary["tolerance"] + EPS
    # overrides of 70 % and 120 % applied along the way
    assert 0.3 * summary["feed"] < summary["mean_feed"] <= \
        summary["feed"] * 1.2 + EPS
    assert summary["program_time"] > 0
    for a, acc in summary["max_acc"].items():
        assert acc <= summary["acc_limit"][a] * (1 + 1e-6)
    assert "program time" in text and "max deviation" in text
