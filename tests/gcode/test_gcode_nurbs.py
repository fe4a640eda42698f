"""G5.2/G5.3 NURBS blocks on a machine: straight feeds whose points lie
on the curve and whose chords stay within the tolerance, checked
against the curve computed here independently (Cox-de Boor basis
functions, not the de Boor recursion of halsdk.gcode.nurbs). rs274's
output is compared with the reference's in tests/gcode/programs/nurbs/.
"""

from __future__ import annotations

import ast
import math

import pytest
from helpers import repo_path
from hypothesis import example, given, settings
from hypothesis import strategies as st

from halsdk.gcode import GCodeError, Parameters, Program
from halsdk.gcode import canon as C
from halsdk.gcode.interp import Interpreter
from halsdk.gcode.nurbs import knot_vector, polyline
from halsdk.machine.tooltable import ToolTable

TOL_MM = 0.001


def run(text: str, units: str = "mm") -> list[C.Command]:
    params = Parameters()
    rec = C.RecordingCanon()
    tools = ToolTable.parse("T1 P1 Z0 D2\n")
    interp = Interpreter(params, tools, rec, units=units)
    interp.run(Program(text, "n.ngc", params))
    return rec.commands


def feeds(commands: list[C.Command]) -> list[C.StraightFeed]:
    return [c for c in commands if isinstance(c, C.StraightFeed)]


# -- the curve, computed independently --------------------------------------

def basis(i: int, k: int, u: float, knots: list[float], last: bool) -> float:
    """Cox-de Boor: the i-th B-spline basis function of order k."""
    if k == 1:
        if knots[i] <= u < knots[i + 1]:
            return 1.0
        # the closed end: u = 1 belongs to the last non-empty span
        return 1.0 if last and u == knots[i + 1] and knots[i] < u else 0.0
    out = 0.0
    if knots[i + k - 1] > knots[i]:
        out += (u - knots[i]) / (knots[i + k - 1] - knots[i]) * \
            basis(i, k - 1, u, knots, last)
    if knots[i + k] > knots[i + 1]:
        out += (knots[i + k] - u) / (knots[i + k] - knots[i + 1]) * \
            basis(i + 1, k - 1, u, knots, last)
    return out


def curve(ctrl, weights, order, u):
    n = len(ctrl)
    knots = [0.0] * order + [j / (n - order + 1)
                             for j in range(1, n - order + 1)] + [1.0] * order
    last = u >= 1.0
    b = [basis(i, order, u, knots, last) * weights[i] for i in range(n)]
    total = sum(b)
    return (sum(b[i] * ctrl[i][0] for i in range(n)) / total,
            sum(b[i] * ctrl[i][1] for i in range(n)) / total)


def distance_to_curve(p, ctrl, weights, order):
    """Closest distance of p to the curve, searched with 1,000 samples of
    the parameter and, when p seems off the curve, with 30,000: where the
    curve moves very fast (a heavy weight beside repeated control points)
    the first samples may all lie far from p."""
    best = _distance_to_curve(p, ctrl, weights, order, 1000)
    if best >= 1e-7:
        best = min(best, _distance_to_curve(p, ctrl, weights, order, 30000,
                                            minima=10))
    return best


def _distance_to_curve(p, ctrl, weights, order, samples, minima=None):
    """Closest distance of p to the curve: a dense search, then, around
    each local minimum of the samples, a search that samples its bracket
    densely again and narrows it to the best sample's neighbours (a loop
    or a sharp turn may put other pieces of the curve nearer p than the
    samples beside it, where the curve moves fast; the distance need not
    have one minimum in a bracket, so no ternary search).  With
    ``minima``, only that many of the nearest local minima are searched."""
    def dist(u):
        return math.dist(p, curve(ctrl, weights, order, u))

    near = [dist(j / samples) for j in range(samples + 1)]
    best = math.inf
    found = [j for j, d in enumerate(near)
             if d <= min(near[max(0, j - 1):j + 2])]     # local minima
    if minima is not None:
        found = sorted(found, key=near.__getitem__)[:minima]
    for j in found:
        lo, hi = max(0.0, (j - 1) / samples), min(1.0, (j + 1) / samples)
        for _ in range(12):
            us = [lo + (hi - lo) * k / 20 for k in range(21)]
            ds = [dist(u) for u in us]
            k = ds.index(min(ds))
            best = min(best, ds[k])
            lo, hi = us[max(0, k - 1)], us[min(20, k + 1)]
    return best


def distance_to_polyline(p, points):
    best = math.inf
    for a, b in zip(points, points[1:]):
        dx, dy = b[0] - a[0], b[1] - a[1]
        l2 = dx * dx + dy * dy
        t = 0.0 if l2 == 0 else max(0.0, min(1.0, (
            (p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2))
        best = min(best, math.dist(p, (a[0] + t * dx, a[1] + t * dy)))
    return best


def program(ctrl, weights, order) -> str:
    lines = [f"G21 G17 G90 G94 F600\nG0 X{ctrl[0][0]:.4f} Y{ctrl[0][1]:.4f}"]
    x, y = ctrl[1]
    lines.append(f"G5.2 X{x:.4f} Y{y:.4f} P{weights[1]:.4f} L{order}")
    for (x, y), w in zip(ctrl[2:], weights[2:]):
        lines.append(f"X{x:.4f} Y{y:.4f} P{w:.4f}")
    lines.append("G5.3\nM2\n")
    return "\n".join(lines)


coord = st.floats(-50, 50, allow_nan=False).map(lambda v: round(v, 4))
polygons = st.integers(3, 7).flatmap(lambda n: st.tuples(
    st.lists(st.tuples(coord, coord), min_size=n, max_size=n),
    st.lists(st.floats(0.25, 4).map(lambda v: round(v, 4)),
             min_size=n, max_size=n),
    st.integers(2, min(n, 5))))


@pytest.mark.slow
@settings(max_examples=20, deadline=None)
@given(polygons)
@example(([(-0.0, 0.5), (0.375, 0.005), (-18.4253, 0.0), (0.0, 0.0),
           (0.0, 0.0), (0.0, 0.0), (0.0, 0.0)],
          [3.6181, 1.9152, 1.0, 0.5, 2.5515, 0.25, 0.25], 5))
def test_feeds_lie_on_the_curve_within_the_tolerance(case):
    ctrl, weights, order = case
    # the first control point is where the tool is; its weight is 1
    # when the first line gives a point (and its weight) of its own
    weights = [1.0] + weights[1:]
    out = feeds(run(program(ctrl, weights, order)))
    points = [c.end[:2] for c in out]
    assert points, "no feed"
    # it ends exactly on the last control point, at the program's feed
    assert points[-1] == pytest.approx(ctrl[-1], abs=1e-9)
    assert all(c.feed == 600 for c in out)
    assert all(c.end[2:] == (0.0,) * 7 for c in out)
    # every point (a dozen of them, spread) is on the curve
    for p in points[::max(1, len(points) // 12)]:
        assert distance_to_curve(p, ctrl, weights, order) < 1e-6
    # and the curve never strays from the chords by more than 1 um (a
    # weighted piece may have its farthest point well off its middle)
    path = [tuple(ctrl[0])] + points
    for j in range(151):
        q = curve(ctrl, weights, order, j / 150)
        assert distance_to_polyline(q, path) <= TOL_MM


def test_the_manual_example_and_the_position_after_it():
    text = ("G21 G0 X0 Y0\nF10\nG5.2 P1 L3\nX0 Y1 P1\nX2 Y2 P1\n"
            "X2 Y0 P1\nX0 Y0 P2\nG5.3\nG1 X5\nM2\n")
    out = feeds(run(text))
    ctrl = [(0, 0), (0, 1), (2, 2), (2, 0), (0, 0)]
    weights = [1, 1, 1, 1, 2]
    for c in out[:-1]:
        assert distance_to_curve(c.end[:2], ctrl, weights, 3) < 1e-6
    assert out[-2].end[:2] == pytest.approx((0, 0))
    assert out[-1].end[:2] == pytest.approx((5, 0))     # G1 X5 after it
    # the curve bends away from the straight line: it reaches x > 1.2
    assert max(c.end[0] for c in out[:-1]) > 1.2
    # the finer the tolerance, the more chords (1 um in mm)
    assert len(out) > 20


def test_incremental_points_are_from_where_the_block_started():
    # as the reference: in G91 every point is relative to the position
    # before the G5.2 block (the position moves only at G5.3)
    out = feeds(run("G21 G0 X1 Y1\nG91 F10\nG5.2 X1 Y1 P1\nX2 Y1 P1\n"
                    "X3 Y4 P1\nG5.3\nG1 X1\nM2\n"))
    assert out[-2].end[:2] == pytest.approx((4, 5))
    assert out[-1].end[:2] == pytest.approx((5, 5))


def test_inch_program_on_a_metric_machine():
    out = feeds(run("G20\nF10\nG5.2 X1 Y0 P1 L2\nX1 Y1 P1\nG5.3\nM2\n"))
    # order 2: the control polygon itself, in mm
    points = [c.end[:2] for c in out]
    assert (25.4, 0.0) in points
    assert points[-1] == (25.4, 25.4)
    assert all(y == 0 or x == pytest.approx(25.4) for x, y in points)
    assert out[0].feed == pytest.approx(254)


@pytest.mark.parametrize("text, message", [
    ("G18 F10\nG5.2 X1 Y1 P1\nX2 Y2 P1\nG5.3\n", "XY plane"),
    ("F10\nG5.2 X1 Y1 Z1 P1\nX2 Y2 P1\nG5.3\n", "may not move Z"),
    ("G93\nG5.2 X1 Y1 P1 F1\nX2 Y2 P1 F1\nG5.3\n", "inverse time"),
    ("F10\nG5.2 X1 Y1 P0\nX2 Y2 P1\nG5.3\n", "weights P must be above 0"),
    ("F10\nG5.2 X1 Y1 P1 L1\nX2 Y2 P1\nG5.3\n", "at least 2"),
    ("F10\nG5.2 X1 Y1 P1 L2.5\n", "Non integer value for integer"),
    ("F10\nG5.2 X1 Y1 P1\nX2 Y2\nG5.3\n", "positive weight P"),
    ("F10\nG5.2 X1 Y1 L2\nX2 Y2 P1\nG5.3\n", "needs its weight P"),
    ("F10\nG5.2 X1 Y1 P1\nG5.3\n", "at least equal to the order L = 3"),
    ("F10\nG5.3\n", "without G5.2 first"),
    ("G5.2 X1 Y1 P1\n", "0 feedrate"),
    ("F10 T1 M6\nG41 D1 G1 X1\nG5.2 X1 Y1 P1\n", "cutter compensation"),
])
def test_what_a_machine_refuses(text, message):
    with pytest.raises(GCodeError, match=message) as e:
        run("G21 " + text + "M2\n")
    assert str(e.value).startswith("n.ngc:")


def test_polyline_module_checks_and_the_order_2_case():
    assert knot_vector(4, 3) == [0, 0, 0, 0.5, 1, 1, 1]
    with pytest.raises(ValueError):
        knot_vector(2, 3)
    with pytest.raises(ValueError):
        polyline([(0, 0), (1, 1)], [1, 0], 2, 0.001)
    with pytest.raises(ValueError):
        polyline([(0, 0), (1, 1)], [1, 1], 2, 0)
    # order 2: the polygon, each span halved twice at least
    points = polyline([(0, 0), (1, 1), (2, 0)], [1, 1, 1], 2, 0.001)
    assert points == [(0.25, 0.25), (0.5, 0.5), (0.75, 0.75), (1.0, 1.0),
                      (1.25, 0.75), (1.5, 0.5), (1.75, 0.25), (2, 0)]


PREVIEW = repo_path("tests", "data", "gcode", "nurbs-preview")


@pytest.mark.parametrize("name", ["manual", "first_point_weighted",
                                  "start_weight", "start_without_weight"])
def test_the_curve_is_the_reference_preview_s(name):
    # the reference's preview interpreter cuts the curve into straight
    # feeds on it: each of them lies within our tolerance of our chords
    # (so the knots, the weights and the start point's weight agree)
    ref = []
    for line in (PREVIEW / f"{name}.reference").read_text().splitlines():
        if line.startswith("straight_feed"):
            x, y, _ = ast.literal_eval(line.split(" ", 1)[1])
            ref.append((x * 25.4, y * 25.4))
    text = (PREVIEW / f"{name}.ngc").read_text()
    ours = [c.end[:2] for c in feeds(run(text))]
    start = next(c.end[:2] for c in run(text)
                 if isinstance(c, C.StraightTraverse))
    assert ours[-1] == pytest.approx(ref[-1], abs=1e-9)
    path = [start] + ours
    worst = max(distance_to_polyline(p, path) for p in ref)
    assert worst <= TOL_MM * 1.01
