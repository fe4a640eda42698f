"""Cutter radius compensation (G41/G42) for straight moves in the XY plane
(G17) or the XZ plane (G18).

Supported: straight moves (G0/G1) in G17 or G18, with outside corners rounded by an
arc around the programmed corner and inside corners cut at the intersection
of the two offset lines; moves that leave X and Y unchanged (Z plunges) pass
through.  The first XY move after G41/G42 is the entry move: it runs straight
from where the tool is to the offset start of the next corner.  G40 ends the
offset after the last segment; the following move is the exit move.

Refused with :class:`CutterRadiusError`: arcs, canned cycles, probing and G33 while
compensation is on, G19, an inside corner right after a non-XY move,
and segments too short for the tool radius (they would gouge).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

from . import canon as C

#: plane -> (first, second) axis indices: the in-plane coordinates, in
#: the order that makes the plane's normal point towards the viewer
PLANE_AXES = {17: (0, 1), 18: (2, 0)}


class CutterRadiusError(Exception):
    """A program that cutter compensation cannot handle."""


@dataclass
class _Segment:
    start: tuple[float, float]       # programmed start (x, y)
    end: list[float]                 # programmed end, 9 axes
    direction: tuple[float, float]   # unit vector
    length: float
    feed: Optional[float]            # None: traverse
    line: int


class CutterComp:
    """Offsets a stream of programmed straight moves by the tool radius.

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
        self._last_dir: Optional[tuple[float, float]] = None
        self._at: Optional[tuple[float, float]] = None   # emitted XY
        self.plane = 17
        self._a1, self._a2 = PLANE_AXES[17]

    @property
    def active(self) -> bool:
        return self.side != 0

    def start(self, side: int, radius: float, plane: int = 17) -> None:
        if plane not in PLANE_AXES:
            raise CutterRadiusError("cutter compensation works in the XY "
                                    "and XZ planes (G17, G18) only")
        self.plane = plane
        self._a1, self._a2 = PLANE_AXES[plane]
        if self.active:
            raise CutterRadiusError("cutter compensation is already on (G40 first)")
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

    def _offset(self, d: tuple[float, float]) -> tuple[float, float]:
        r = self.radius * self.side
        return (-d[1] * r, d[0] * r)

    def _send(self, command: C.Command) -> None:
        self._emit(command)

    def _finish_pending(self, xy: tuple[float, float]) -> None:
        seg = self._pending
        assert seg is not None
        end = list(seg.end)
        end[self._a1], end[self._a2] = xy
        pose = tuple(end)
        if seg.feed is None:
            self._send(C.StraightTraverse(pose, seg.line))  # type: ignore
        else:
            self._send(C.StraightFeed(pose, seg.feed, seg.line))  # type: ignore
        self._pending = None
        self._at = xy
        self._last_dir = seg.direction
        queue, self._queue = self._queue, []
        for command in queue:
            self._send(command)

    def move(self, start: list[float], end: list[float],
             feed: Optional[float], line: int) -> None:
        """A programmed straight move from ``start`` to ``end`` (machine
        coordinates); ``feed`` None for a traverse."""
        a1, a2 = self._a1, self._a2
        dx, dy = end[a1] - start[a1], end[a2] - start[a2]
        length = math.hypot(dx, dy)
        if length < 1e-9:
            # no XY motion: release the held segment, move at its offset end
            if self._pending is not None:
                seg = self._pending
                off = self._offset(seg.direction)
                self._finish_pending((seg.end[a1] + off[0],
                                      seg.end[a2] + off[1]))
            pose = list(end)
            if self._at is not None:
                pose[a1], pose[a2] = self._at
            if feed is None:
                self._send(C.StraightTraverse(tuple(pose), line))  # type: ignore
            else:
                self._send(C.StraightFeed(tuple(pose), feed, line))  # type: ignore
            return
        d = (dx / length, dy / length)
        new = _Segment((start[a1], start[a2]), list(end), d, length, feed,
                       line)
        if self._pending is None and self._last_dir is None:
            self._pending = new            # entry move
            return
        prev = self._pending.direction if self._pending else self._last_dir
        assert prev is not None
        corner = (start[a1], start[a2])
        off_a, off_b = self._offset(prev), self._offset(d)
        cross = prev[0] * d[1] - prev[1] * d[0]
        dot = prev[0] * d[0] + prev[1] * d[1]
        b_start = (corner[0] + off_b[0], corner[1] + off_b[1])
        if abs(cross) < 1e-9 and dot > 0:           # straight on
            if self._pending is not None:
                self._finish_pending((corner[0] + off_a[0],
                                      corner[1] + off_a[1]))
        elif (cross * self.side < 0 or abs(cross) < 1e-9
              or self.radius == 0):                   # outside corner
            a_end = (corner[0] + off_a[0], corner[1] + off_a[1])
            if self._pending is not None:
                self._finish_pending(a_end)
            if self.radius > 0:
                pose = list(start)
                pose[a1], pose[a2] = b_start
                arc_feed = feed if feed is not None else None
                if arc_feed is None:
                    self._send(C.StraightTraverse(tuple(pose), line))  # type: ignore
                else:
                    self._send(C.ArcFeed(tuple(pose), corner,  # type: ignore
                                         self.plane,
                                         -self.side, arc_feed, line))
            self._at = b_start
        else:                                         # inside corner
            if self._pending is None:
                raise CutterRadiusError("inside corner right after a non-XY move "
                                "under cutter compensation is not supported")
            # a_off + t*prev == b_off + s*d
            ax, ay = corner[0] + off_a[0], corner[1] + off_a[1]
            rx, ry = b_start[0] - ax, b_start[1] - ay
            t = (rx * d[1] - ry * d[0]) / cross
            s = (rx * prev[1] - ry * prev[0]) / cross
            if -t > self._pending.length + 1e-9 or s > new.length + 1e-9:
                raise CutterRadiusError("segment too short for the tool radius "
                                "(cutter compensation would gouge)")
            point = (ax + t * prev[0], ay + t * prev[1])
            self._finish_pending(point)
        self._pending = new

    def stop(self) -> None:
        """G40 (or program end): emit the held segment to its offset end."""
        if self._pending is not None:
            seg = self._pending
            off = self._offset(seg.direction)
            self._finish_pending((seg.end[self._a1] + off[0],
                                  seg.end[self._a2] + off[1]))
        self.side = 0
        self._last_dir = None
        self._at = None
