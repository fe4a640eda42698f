"""NURBS curves of G5.2/G5.3 blocks, as straight segments for a machine.

A G5.2 ... G5.3 block gives the control points of a curve in the XY
plane, each with a weight (P), and the curve's order (L: degree + 1).
The curve is the rational B-spline with a clamped uniform knot vector:
it starts at the first control point (where the tool is), ends at the
last one and is tangent to the control polygon at both ends.
:func:`polyline` turns it into points on the curve whose chords stay
within a tolerance of it, for straight feeds.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["MAX_POINTS", "knot_vector", "point", "polyline"]

Point = tuple[float, float]

#: the most points one curve becomes (a finer tolerance is an error)
MAX_POINTS = 200_000
#: bisections of one knot span at most (2**20 chords) and at least
_MAX_DEPTH = 20
_MIN_DEPTH = 2
#: where a piece is sampled (fractions of its parameter range, besides
#: the middle), and the share of the tolerance the samples may use: the
#: curve between two samples may stray a little further (with weights,
#: the farthest point of a piece can be well off its middle)
_SAMPLES = (0.125, 0.25, 0.375, 0.625, 0.75, 0.875)
_MARGIN = 0.95


def knot_vector(count: int, order: int) -> list[float]:
    """The clamped uniform knots of ``count`` control points: ``order``
    zeros, the inner knots evenly spaced, ``order`` ones."""
    if not 2 <= order <= count:
        raise ValueError(f"order {order} needs 2..{count}")
    inner = count - order
    return ([0.0] * order + [i / (inner + 1) for i in range(1, inner + 1)]
            + [1.0] * order)


def _span(knots: Sequence[float], order: int, count: int, u: float) -> int:
    """The knot span ``s`` with knots[s] <= u < knots[s + 1] (the last
    non-empty one for u = 1)."""
    if u >= knots[count]:
        return count - 1
    low, high = order - 1, count
    while high - low > 1:           # knots[low] <= u < knots[high]
        mid = (low + high) // 2
        if u < knots[mid]:
            high = mid
        else:
            low = mid
    return low


def point(controls: Sequence[Point], weights: Sequence[float], order: int,
          knots: Sequence[float], u: float) -> Point:
    """The curve at parameter ``u`` (0..1), by de Boor's algorithm on
    the weighted (homogeneous) control points."""
    count = len(controls)
    s = _span(knots, order, count, u)
    degree = order - 1
    d = [(controls[j][0] * weights[j], controls[j][1] * weights[j],
          weights[j]) for j in range(s - degree, s + 1)]
    for r in range(1, order):
        for j in range(degree, r - 1, -1):
            i = j + s - degree
            left, right = knots[i], knots[i + order - r]
            a = 0.0 if right == left else (u - left) / (right - left)
            b = 1.0 - a
            p, q = d[j - 1], d[j]
            d[j] = (b * p[0] + a * q[0], b * p[1] + a * q[1],
                    b * p[2] + a * q[2])
    x, y, w = d[degree]
    return (x / w, y / w)


def _off_chord(p: Point, a: Point, b: Point) -> float:
    """Distance of ``p`` from the segment a-b."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    if length2 == 0.0:
        return math.dist(p, a)
    t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length2
    t = min(1.0, max(0.0, t))
    return math.dist(p, (a[0] + t * dx, a[1] + t * dy))


def polyline(controls: Sequence[Point], weights: Sequence[float],
             order: int, tolerance: float) -> list[Point]:
    """Points on the curve, from its start (excluded: where the tool is)
    to its end (the last control point), such that each chord stays
    within ``tolerance`` of the curve piece it replaces: every knot span
    is halved (twice at least) until the curve at every eighth of each
    piece lies within 95% of the tolerance of its chord (the margin is
    for the curve between the samples) and does not turn back against
    the chord at either end (a turn whose tip the samples could miss)."""
    if tolerance <= 0:
        raise ValueError("the tolerance must be above 0")
    if any(not w > 0 for w in weights):
        raise ValueError("every weight must be above 0")
    count = len(controls)
    knots = knot_vector(count, order)
    out: list[Point] = []

    def at(u: float) -> Point:
        return point(controls, weights, order, knots, u)

    def heads_back(u: float, h: float, a: Point, b: Point) -> bool:
        """Whether the curve at u (moving by h) goes against a->b: a
        turn inside a piece, whose tip the samples may miss."""
        p, q = at(u), at(u + h)
        return (q[0] - p[0]) * (b[0] - a[0]) + \
            (q[1] - p[1]) * (b[1] - a[1]) < 0

    def piece(u0: float, p0: Point, u1: float, p1: Point,
              depth: int) -> None:
        um = (u0 + u1) / 2
        pm = at(um)
        if depth < _MAX_DEPTH:
            h = (u1 - u0) * 1e-3
            split = depth < _MIN_DEPTH or max(
                _off_chord(pm, p0, p1), *(
                    _off_chord(at(u0 + f * (u1 - u0)), p0, p1)
                    for f in _SAMPLES)) > tolerance * _MARGIN or \
                heads_back(u0, h, p0, p1) or heads_back(u1 - h, h, p0, p1)
            if split:
                piece(u0, p0, um, pm, depth + 1)
                piece(um, pm, u1, p1, depth + 1)
                return
        if len(out) >= MAX_POINTS:
            raise ValueError(f"the curve needs more than {MAX_POINTS} "
                             "segments")
        out.append(p1)

    start = at(0.0)
    for s in range(order - 1, count):
        u0, u1 = knots[s], knots[s + 1]
        if u1 > u0:
            end = at(u1) if s < count - 1 else tuple(controls[-1])
            piece(u0, start, u1, end, 0)  # type: ignore[arg-type]
            start = end  # type: ignore[assignment]
    return out
