"""Cutter radius compensation (G41/G42) in the XY plane (G17) or the XZ
plane (G18), for straight moves and arcs.

Each programmed segment is held back until the next one is known, so the
corner between them can be made: an outside (convex) corner gets an arc
around the programmed corner point, an inside (concave) corner ends both
offset paths at their intersection (line with line, line with circle or
circle with circle). An arc's offset path is the concentric arc whose
radius is the programmed one plus or minus the tool radius. The first
in-plane move after G41/G42 is the entry move: a straight line from
where the tool is to the offset start of the corner with the next
segment. G40 ends the offset after the last segment; the following move
is the exit move. Moves that leave the plane's two axes unchanged (Z
plunges in G17) pass through.

Refused with :class:`CutterRadiusError`: canned cycles, probing and G33
while compensation is on, G19, an arc as the entry move, an inside corner
right after a move out of the plane, an arc too small for the tool and
segments too short for the tool radius (they would gouge).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

from . import canon as C

#: plane -> (first, second) axis indices: the in-plane coordinates, in
#: the order that makes the plane's normal point towards the viewer
PLANE_AXES = {17: (0, 1), 18: (2, 0)}

Vec = tuple[float, float]


class CutterRadiusError(Exception):
    """A program that cutter compensation cannot handle."""


@dataclass
class _Segment:
    start: Vec                      # programmed start in the plane
    end: list[float]                # programmed end, 9 axes
    t0: Vec                         # unit tangent at the start
    t1: Vec                         # unit tangent at the end
    length: float                   # in-plane length (lines)
    feed: Optional[float]           # None: traverse
    line: int
    centre: Optional[Vec] = None    # arcs: the centre in the plane
    turn: int = 0                   # arcs: +n counter-clockwise, -n clockwise
    radius: float = 0.0             # arcs: the programmed radius
    start_pose: Optional[list[float]] = None   # programmed start, 9 axes
    path_end: Optional[Vec] = None  # an entry arc: where its path ends

    @property
    def is_arc(self) -> bool:
        return self.centre is not None


def _cross(a: Vec, b: Vec) -> float:
    return a[0] * b[1] - a[1] * b[0]


def _line_circle(p: Vec, d: Vec, c: Vec, r: float) -> list[Vec]:
    """Where the line p + t*d (d a unit vector) meets the circle (c, r)."""
    fx, fy = p[0] - c[0], p[1] - c[1]
    b = fx * d[0] + fy * d[1]
    disc = b * b - (fx * fx + fy * fy - r * r)
    if disc < -1e-12:
        return []
    root = math.sqrt(max(disc, 0.0))
    return [(p[0] + t * d[0], p[1] + t * d[1]) for t in (-b - root, -b + root)]


def _circle_circle(c1: Vec, r1: float, c2: Vec, r2: float) -> list[Vec]:
    """Where two circles meet."""
    dx, dy = c2[0] - c1[0], c2[1] - c1[1]
    dist = math.hypot(dx, dy)
    if dist < 1e-12 or dist > r1 + r2 + 1e-9 or dist < abs(r1 - r2) - 1e-9:
        return []
    a = (r1 * r1 - r2 * r2 + dist * dist) / (2 * dist)
    h = math.sqrt(max(r1 * r1 - a * a, 0.0))
    mx, my = c1[0] + a * dx / dist, c1[1] + a * dy / dist
    return [(mx - h * dy / dist, my + h * dx / dist),
            (mx + h * dy / dist, my - h * dx / dist)]


class CutterComp:
    """Offsets a stream of programmed moves by the tool radius.

    ``emit`` receives the compensated canonical commands.  Other commands
    produced while a segment is held back are queued with :meth:`hold` so
    the output keeps the program's order.
    """

    def __init__(self, emit: Callable[[C.Command], None]) -> None:
        self._emit = emit
        self.side = 0                     # +1 G41 (left), -1 G42 (right)
        self.radius = 0.0
        self._pending: Optional[_Segment] = None
        self._queue: list[C.Command] = []
        self._last_dir: Optional[Vec] = None
        self._at: Optional[Vec] = None    # emitted in-plane position
        self.plane = 17
        self._a1, self._a2 = PLANE_AXES[17]

    @property
    def active(self) -> bool:
        return self.side != 0

    def start(self, side: int, radius: float, plane: int = 17) -> None:
        if plane not in PLANE_AXES:
            raise CutterRadiusError("Cutter radius compensation allowed "
                                    "only in XY, XZ planes")
        self.plane = plane
        self._a1, self._a2 = PLANE_AXES[plane]
        if self.active:
            raise CutterRadiusError("Cannot turn cutter radius comp on when "
                                    "on")
        if radius < 0:
            raise CutterRadiusError("negative tool radius for cutter compensation")
        self.side, self.radius = side, radius
        self._last_dir = None
        self._at = None

    def hold(self, command: C.Command) -> bool:
        """Queue ``command`` if a segment is held back; True if queued."""
        if self._pending is None:
            return False
        self._queue.append(command)
        return True

    # -- geometry ----------------------------------------------------------
    def _offset(self, d: Vec) -> Vec:
        """The offset vector of the tool beside a move along ``d``."""
        r = self.radius * self.side
        return (-d[1] * r, d[0] * r)

    def _offset_radius(self, seg: _Segment) -> float:
        """The radius of an arc's offset path (the left side of a
        counter-clockwise arc is towards the centre)."""
        turn = 1 if seg.turn > 0 else -1
        return seg.radius - self.side * turn * self.radius

    def _offset_end(self, seg: _Segment) -> Vec:
        if seg.path_end is not None:
            return seg.path_end
        off = self._offset(seg.t1)
        p = (seg.end[self._a1], seg.end[self._a2])
        return (p[0] + off[0], p[1] + off[1])

    def _inside_point(self, prev: _Segment, new: _Segment,
                      corner: Vec) -> Vec:
        """Where the offset paths of ``prev`` and ``new`` meet, nearest
        their offset ends at ``corner``."""
        a_end = self._offset_end(prev)
        b_start = (corner[0] + self._offset(new.t0)[0],
                   corner[1] + self._offset(new.t0)[1])
        if not prev.is_arc and not new.is_arc:
            # a_end + t*prev == b_start + s*new
            cross = _cross(prev.t1, new.t0)
            rx, ry = b_start[0] - a_end[0], b_start[1] - a_end[1]
            t = (rx * new.t0[1] - ry * new.t0[0]) / cross
            s = (rx * prev.t1[1] - ry * prev.t1[0]) / cross
            if -t > prev.length + 1e-9 or s > new.length + 1e-9:
                raise CutterRadiusError("Straight feed in concave corner "
                                        "cannot be reached by the tool "
                                        "without gouging")
            return (a_end[0] + t * prev.t1[0], a_end[1] + t * prev.t1[1])
        if prev.is_arc and new.is_arc:
            assert prev.centre is not None and new.centre is not None
            points = _circle_circle(prev.centre, self._offset_radius(prev),
                                    new.centre, self._offset_radius(new))
        elif prev.is_arc:
            assert prev.centre is not None
            points = _line_circle(b_start, new.t0, prev.centre,
                                  self._offset_radius(prev))
        else:
            assert new.centre is not None
            points = _line_circle(a_end, prev.t1, new.centre,
                                  self._offset_radius(new))
        if not points:
            raise CutterRadiusError("the offset paths do not meet at an inside "
                                    "corner (tool radius too big for the "
                                    "program)")
        return min(points, key=lambda q: math.dist(q, a_end)
                   + math.dist(q, b_start))

    def _cusp_inside(self, new: _Segment) -> bool:
        """At a reversal (the tangents opposite) next to an arc, the
        corner is an inside one when the offset paths meet."""
        prev = self._pending
        if prev is None or not (prev.is_arc or new.is_arc):
            return False
        try:
            self._inside_point(prev, new, new.start)
        except (CutterRadiusError, ZeroDivisionError):
            return False
        return True

    # -- output ------------------------------------------------------------
    def _send(self, command: C.Command) -> None:
        self._emit(command)

    def _pose(self, base: list[float], xy: Vec) -> C.Pose:
        pose = list(base)
        pose[self._a1], pose[self._a2] = xy
        return tuple(pose)  # type: ignore[return-value]

    def _finish_pending(self, xy: Vec) -> None:
        seg = self._pending
        assert seg is not None
        pose = self._pose(seg.end, xy)
        if seg.centre is not None:
            assert seg.feed is not None
            self._send(C.ArcFeed(pose, seg.centre, self.plane, seg.turn,
                                 seg.feed, seg.line))
        elif seg.feed is None:
            self._send(C.StraightTraverse(pose, seg.line))
        else:
            self._send(C.StraightFeed(pose, seg.feed, seg.line))
        self._pending = None
        self._at = xy
        self._last_dir = seg.t1
        queue, self._queue = self._queue, []
        for command in queue:
            self._send(command)

    # -- moves -------------------------------------------------------------
    def move(self, start: list[float], end: list[float],
             feed: Optional[float], line: int) -> None:
        """A programmed straight move from ``start`` to ``end`` (machine
        coordinates); ``feed`` None for a traverse."""
        a1, a2 = self._a1, self._a2
        dx, dy = end[a1] - start[a1], end[a2] - start[a2]
        length = math.hypot(dx, dy)
        if self._pending is None and self._last_dir is None and \
                length <= self.radius:
            raise CutterRadiusError("Length of cutter compensation entry "
                                    "move is not greater than the tool "
                                    "radius")
        if length < 1e-9:
            # no motion in the plane: release the held segment, move at
            # its offset end
            if self._pending is not None:
                self._finish_pending(self._offset_end(self._pending))
            pose = list(end)
            if self._at is not None:
                pose[a1], pose[a2] = self._at
            if feed is None:
                self._send(C.StraightTraverse(tuple(pose), line))  # type: ignore
            else:
                self._send(C.StraightFeed(tuple(pose), feed, line))  # type: ignore
            return
        d = (dx / length, dy / length)
        self._add(_Segment((start[a1], start[a2]), list(end), d, d, length,
                           feed, line, start_pose=list(start)))

    def arc(self, start: list[float], end: list[float], centre: Vec,
            turn: int, feed: float, line: int) -> None:
        """A programmed arc (machine coordinates) about ``centre`` (the two
        in-plane coordinates), ``turn`` as in :class:`~.canon.ArcFeed`."""
        a1, a2 = self._a1, self._a2
        s = (start[a1], start[a2])
        e = (end[a1], end[a2])
        radius = math.dist(s, centre)
        seg = _Segment(s, list(end), self._tangent(s, centre, turn),
                       self._tangent(e, centre, turn), 0.0, feed, line,
                       centre, turn, radius, list(start))
        if self._offset_radius(seg) <= 1e-9:
            raise CutterRadiusError("Tool radius not less than arc radius "
                                    "with comp")
        if self._pending is None and self._last_dir is None:
            self._entry_arc(seg)
        self._add(seg)

    def _entry_arc(self, seg: _Segment) -> None:
        """An arc as the entry move: it runs from where the tool is to the
        offset end, about a centre moved along the line from the start to
        the programmed centre, so that it leaves the start on the
        programmed arc's tangent."""
        assert seg.centre is not None
        s, c = seg.start, seg.centre
        e = self._offset_end(seg)
        ux, uy = c[0] - s[0], c[1] - s[1]
        norm = math.hypot(ux, uy)
        ex, ey = e[0] - s[0], e[1] - s[1]
        den = 2 * (ex * ux + ey * uy) / norm if norm else 0.0
        if den <= 1e-12:
            raise CutterRadiusError("cannot make the entry arc of cutter "
                                    "compensation (tool radius too big?)")
        t = (ex * ex + ey * ey) / den
        centre = (s[0] + ux / norm * t, s[1] + uy / norm * t)
        turn = 1 if seg.turn > 0 else -1
        seg.centre = centre
        seg.radius = t + self.side * turn * self.radius   # offset path: t
        seg.path_end = e
        seg.t0 = self._tangent(s, centre, seg.turn)
        seg.t1 = self._tangent(e, centre, seg.turn)

    @staticmethod
    def _tangent(p: Vec, centre: Vec, turn: int) -> Vec:
        rx, ry = p[0] - centre[0], p[1] - centre[1]
        r = math.hypot(rx, ry) or 1.0
        return (-ry / r, rx / r) if turn > 0 else (ry / r, -rx / r)

    def _add(self, new: _Segment) -> None:
        if self._pending is None and self._last_dir is None:
            self._pending = new            # entry move
            return
        prev_dir = self._pending.t1 if self._pending else self._last_dir
        assert prev_dir is not None
        corner = new.start
        off_a, off_b = self._offset(prev_dir), self._offset(new.t0)
        cross = _cross(prev_dir, new.t0)
        dot = prev_dir[0] * new.t0[0] + prev_dir[1] * new.t0[1]
        b_start = (corner[0] + off_b[0], corner[1] + off_b[1])
        if abs(cross) < 1e-9 and dot > 0:           # straight on
            if self._pending is not None:
                self._finish_pending(self._offset_end(self._pending))
        elif (cross * self.side < 0 or self.radius == 0 or (
                abs(cross) < 1e-9 and not self._cusp_inside(new))):
            # outside corner (a reversal is one unless the offset paths
            # of a curved segment cross: see _cusp_inside)
            a_end = (self._offset_end(self._pending) if self._pending
                     else (corner[0] + off_a[0], corner[1] + off_a[1]))
            if self._pending is not None:
                self._finish_pending(a_end)
            if self.radius > 0:
                start = self._pose(new.start_pose or new.end, b_start)
                if new.feed is None:
                    self._send(C.StraightTraverse(start, new.line))
                else:
                    self._send(C.ArcFeed(start, corner, self.plane,
                                         -self.side, new.feed, new.line))
            self._at = b_start
        else:                                         # inside corner
            if self._pending is None:
                raise CutterRadiusError("inside corner right after a move out "
                                        "of the plane under cutter "
                                        "compensation is not supported")
            point = self._inside_point(self._pending, new, corner)
            self._finish_pending(point)
        self._pending = new

    def stop(self) -> None:
        """G40 (or program end): emit the held segment to its offset end."""
        if self._pending is not None:
            self._finish_pending(self._offset_end(self._pending))
        self.side = 0
        self._last_dir = None
        self._at = None
