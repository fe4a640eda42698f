"""Run part programs on a simulated machine and check the traces.

Shared by tests/motion/test_part_programs.py and bench/tp.py (the example
examples/contour/ carries its own small copy, so that it stands alone).

* :class:`Line`, :class:`Arc`, :class:`PathMode`, :class:`Probe`: the
  steps of a program (a plain list).  Ends are mappings of axis letters;
  the axes not named stay where the previous move ended.
* :func:`build_machine`: motmod + trivkins + homemod + tpmod with each
  joint's motor-pos-cmd looped to its motor-pos-fb, configured from an
  INI-like dict (sections ``TRAJ``, ``AXIS_X``, ``JOINT_0`` ...), enabled,
  homed on the spot (zero search velocity) and put in coordinated mode.
  A ``sampler`` at the end of the servo thread records every cycle.
* :meth:`Machine.run`: queue a program (through the client's move queue,
  ``queue_line`` ..., when it has one, else one command per cycle;
  waiting for room when the queue is full, recording meanwhile) and step
  until it is done; returns a :class:`Trace`.
* Checkers: :func:`path_deviation` (distance from the programmed lines
  and arcs), :func:`axis_extremes` and :func:`limit_violations` (per-axis
  velocity, acceleration, jerk by finite differences against the
  [AXIS_L] limits), :func:`stops`, :func:`moving_time`,
  :func:`mean_feed`, :func:`allowed_time` (what the limits allow).

All positions are the nine axes X Y Z A B C U V W (machine units).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Optional, Union

import numpy as np

AXES = "xyzabcuvw"
DT = 1e-3                       # servo period of the machines built here


# ---------------------------------------------------------------- programs


@dataclass
class Line:
    """A straight move to ``end`` at ``feed`` (a traverse with rapid)."""
    end: Mapping[str, float]
    feed: float
    rapid: bool = False


@dataclass
class Arc:
    """An arc or helix to ``end`` around the axis through ``center`` along
    ``normal`` (counterclockwise seen from the tip of normal), with
    ``turn`` extra full turns."""
    end: Mapping[str, float]
    center: Sequence[float]
    feed: float
    normal: Sequence[float] = (0.0, 0.0, 1.0)
    turn: int = 0


@dataclass
class PathMode:
    """The path control mode of the moves that follow: ``"stop"`` (exact
    stop, G61.1), ``"exact"`` (exact path, G61) or ``"blend"`` (G64 P
    tolerance; 0: as fast as the limits allow)."""
    mode: str
    tolerance: float = 0.0


@dataclass
class Probe:
    """A probe move toward ``end`` (G38.2-like)."""
    end: Mapping[str, float]
    feed: float
    away: bool = False
    error_if_no_contact: bool = True


Step = Union[Line, Arc, PathMode, Probe]

_MODES = {"stop": 0, "exact": 1, "blend": 2}


def _pose(prev: np.ndarray, end: Mapping[str, float]) -> np.ndarray:
    p = prev.copy()
    for k, v in end.items():
        p[AXES.index(k.lower())] = float(v)
    return p


def program_end(program: Iterable[Step], start=None) -> np.ndarray:
    """The nine coordinates where a program ends."""
    p = np.zeros(9) if start is None else np.asarray(start, float).copy()
    for s in program:
        if isinstance(s, (Line, Arc, Probe)):
            p = _pose(p, s.end)
    return p


def _arc_points(p0: np.ndarray, p1: np.ndarray, arc: Arc,
                step: float) -> np.ndarray:
    """Points of an arc/helix/spiral from p0 to p1, about ``step`` apart
    (the first point excluded, the last one exactly p1)."""
    n = np.asarray(arc.normal, float)
    n = n / np.linalg.norm(n)
    c = np.asarray(arc.center, float)
    r0v = p0[:3] - c
    r1v = p1[:3] - c
    h0, h1 = r0v @ n, r1v @ n
    r0v = r0v - h0 * n
    r1v = r1v - h1 * n
    r0, r1 = np.linalg.norm(r0v), np.linalg.norm(r1v)
    u = r0v / r0
    w = np.cross(n, u)
    ang = math.atan2(r1v @ w, r1v @ u)
    if ang <= 1e-12:
        ang += 2 * math.pi
    ang += 2 * math.pi * arc.turn
    length = math.hypot(ang * max(r0, r1), h1 - h0) + \
        float(np.linalg.norm(p1[3:] - p0[3:]))
    k = max(2, int(math.ceil(length / step)))
    t = np.arange(1, k + 1) / k
    r = r0 + (r1 - r0) * t
    a = ang * t
    xyz = (c + np.outer(r * np.cos(a), u) + np.outer(r * np.sin(a), w)
           + np.outer(h0 + (h1 - h0) * t, n))
    rest = p0[3:] + np.outer(t, p1[3:] - p0[3:])
    pts = np.hstack([xyz, rest])
    pts[-1] = p1
    return pts


def program_path(program: Iterable[Step], start=None,
                 step: float = 0.01) -> tuple[np.ndarray, np.ndarray]:
    """The programmed geometry as a dense polyline of nine coordinates
    (arcs sampled about ``step`` apart), and for each vertex the index of
    the move it ends (0 for the start point)."""
    p = np.zeros(9) if start is None else np.asarray(start, float).copy()
    pts = [p[None, :]]
    owner = [np.zeros(1, int)]
    k = 0
    for s in program:
        if isinstance(s, PathMode):
            continue
        k += 1
        q = _pose(p, s.end)
        if isinstance(s, Arc):
            seg = _arc_points(p, q, s, step)
        else:
            seg = q[None, :]
        pts.append(seg)
        owner.append(np.full(len(seg), k))
        p = q
    return np.vstack(pts), np.concatenate(owner)


def program_length(program: Iterable[Step], start=None) -> float:
    """Length of the programmed path (XYZ and the other axes together,
    arcs as sampled)."""
    pts, _ = program_path(program, start, step=0.001)
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


# ---------------------------------------------------------------- machine


@dataclass
class Trace:
    """Samples of one run, one row per servo cycle."""
    pos: np.ndarray                 # (n, 9) axis positions (axis.L.pos-cmd)
    joints: np.ndarray              # (n, joints) joint.N.pos-cmd
    vel: np.ndarray                 # motion.current-vel
    line: np.ndarray                # motion.program-line
    dt: float = DT
    start: np.ndarray = field(default_factory=lambda: np.zeros(9))
    extra: dict = field(default_factory=dict)   # build_machine(record=)

    def __len__(self) -> int:
        return len(self.pos)

    @property
    def time(self) -> np.ndarray:
        return np.arange(1, len(self.pos) + 1) * self.dt

    def path_speed(self, axes: str = AXES) -> np.ndarray:
        """Speed along the path from one sample to the next (the start
        position before the first)."""
        idx = [AXES.index(a) for a in axes]
        p = np.vstack([self.start[None, idx], self.pos[:, idx]])
        return np.linalg.norm(np.diff(p, axis=0), axis=1) / self.dt


def machine_ini(coordinates: str = "xyz", vel: Any = 100.0,
                acc: Any = 1000.0, jerk: Any = None,
                traj_vel: Optional[float] = None,
                traj_acc: Optional[float] = None,
                travel: float = 1000.0) -> dict:
    """An INI-like dict for a machine with one joint per letter of
    ``coordinates``; vel/acc/jerk: one number for all axes or a mapping
    letter -> number."""
    def get(v, a):
        return v.get(a) if isinstance(v, Mapping) else v
    ini: dict = {"TRAJ": {
        "MAX_LINEAR_VELOCITY": traj_vel or 1e4,
        "MAX_LINEAR_ACCELERATION": traj_acc or 1e6}}
    for j, a in enumerate(coordinates):
        keys = {"MIN_LIMIT": -travel, "MAX_LIMIT": travel,
                "MAX_VELOCITY": get(vel, a), "MAX_ACCELERATION": get(acc, a)}
        if jerk is not None and get(jerk, a):
            keys["MAX_JERK"] = get(jerk, a)
        ini[f"AXIS_{a.upper()}"] = dict(keys)
        # the joints a little more generous than the axes: the planner
        # must hold the axis limits, motmod would clamp joint overshoots
        jk = dict(keys, MAX_VELOCITY=get(vel, a) * 1.5,
                  MAX_ACCELERATION=get(acc, a) * 1.5,
                  FERROR=1e9, MIN_FERROR=1e9, HOME_SEARCH_VEL=0,
                  HOME_LATCH_VEL=0, HOME_SEQUENCE=0)
        jk.pop("MAX_JERK", None)
        ini[f"JOINT_{j}"] = jk
    return ini


class Machine:
    """A simulated machine in coordinated mode (see build_machine)."""

    def __init__(self, hal: Any, motion: Any, coordinates: str,
                 ini: Mapping[str, Mapping[str, Any]], sampler: str,
                 extra: Sequence[str] = ()):
        self.hal = hal
        self.motion = motion
        self.coordinates = coordinates
        self.ini = ini
        self._stream = hal.stream(sampler)
        self._names = ([f"p{k}" for k in range(9)]
                       + [f"j{k}" for k in range(len(coordinates))]
                       + ["vel", "id"] + list(extra))
        self._extra = list(extra)
        self._chunks: list[dict] = []
        self.errors: list[str] = []

    # limits of the axes (INI values)
    def axis_limit(self, letter: str, key: str) -> Optional[float]:
        sec = self.ini.get(f"AXIS_{letter.upper()}", {})
        v = sec.get(key)
        return None if v is None else float(v)

    def position(self) -> np.ndarray:
        s = self.motion.status()
        c = s.carte_pos_cmd
        return np.array([c.x, c.y, c.z, c.a, c.b, c.c, c.u, c.v, c.w])

    # recording
    def drain(self) -> None:
        d = self._stream.depth
        if d:
            self._chunks.append(self._stream.read_many(d, self._names))

    def start_recording(self) -> np.ndarray:
        """Forget what was recorded; returns the position now."""
        self.drain()
        self._chunks = []
        return self.position()

    def trace(self, start: np.ndarray) -> Trace:
        self.drain()
        if not self._chunks:
            z = np.zeros((0, 9))
            return Trace(z, np.zeros((0, len(self.coordinates))),
                         np.zeros(0), np.zeros(0, int), start=start)
        cat = {n: np.concatenate([c[n] for c in self._chunks])
               for n in self._names}
        pos = np.stack([cat[f"p{k}"] for k in range(9)], axis=1)
        joints = np.stack([cat[f"j{k}"] for k in range(len(self.coordinates))],
                          axis=1)
        return Trace(pos, joints, cat["vel"], cat["id"].astype(int),
                     start=start, extra={n: cat[n] for n in self._extra})

    def step(self, n: int) -> None:
        """Step n servo cycles, recording."""
        while n > 0:
            k = min(n, 2000)
            self.hal.step(k)
            self.drain()
            n -= k

    # queueing
    @property
    def streaming(self) -> bool:
        """The client has the move queue (queue_line ...): many moves
        per servo cycle, in order with the path mode changes."""
        return hasattr(self.motion, "queue_line")

    def queue(self, step: Step, line: int = 0,
              retry: int = 100_000) -> Optional[int]:
        """Queue one program step (waiting while the queue is full, and
        recording meanwhile); returns the motion id of a move.  ``line``:
        the program line shown on motion.program-line (move queue only)."""
        if self.streaming:
            return self._queue_streaming(step, line)
        from halsdk.motion import Rejected
        m = self.motion
        for _ in range(retry):
            try:
                if isinstance(step, PathMode):
                    m.set_term_cond(_MODES[step.mode], step.tolerance)
                    return None
                if isinstance(step, Line):
                    return m.set_line(dict(step.end), vel=step.feed,
                                      rapid=step.rapid)
                if isinstance(step, Arc):
                    return m.set_circle(dict(step.end),
                                        center=tuple(step.center),
                                        normal=tuple(step.normal),
                                        vel=step.feed, turn=step.turn)
                if isinstance(step, Probe):
                    return m.probe(dict(step.end), vel=step.feed,
                                   away=step.away,
                                   error_if_no_contact=step.error_if_no_contact)
                raise TypeError(f"not a program step: {step!r}")
            except Rejected as r:
                if "full" not in r.reason:
                    raise
                self.step(5)
            finally:
                self.drain()
        raise RuntimeError("the motion queue stayed full")

    def _queue_streaming(self, step: Step, line: int) -> Optional[int]:
        m = self.motion
        while m.queue_free() == 0:
            self.step(1)
        try:
            if isinstance(step, PathMode):
                m.queue_term_cond(_MODES[step.mode], step.tolerance)
                return None
            if isinstance(step, Line):
                return m.queue_line(dict(step.end), vel=step.feed,
                                    rapid=step.rapid, line=line)
            if isinstance(step, Arc):
                return m.queue_circle(dict(step.end),
                                      center=tuple(step.center),
                                      normal=tuple(step.normal),
                                      vel=step.feed, turn=step.turn,
                                      line=line)
            if isinstance(step, Probe):
                return m.queue_probe(
                    dict(step.end), vel=step.feed, away=step.away,
                    error_if_no_contact=step.error_if_no_contact, line=line)
            raise TypeError(f"not a program step: {step!r}")
        finally:
            self.drain()

    def queue_program(self, program: Iterable[Step]) -> list:
        """Queue every step; step k gets program line k + 1."""
        return [self.queue(s, k + 1) for k, s in enumerate(program)]

    def run_until_done(self, timeout: float = 120.0,
                       chunk: int = 200) -> None:
        """Step until the queue is empty and motion at rest."""
        cycles = 0
        while True:
            st = self.motion.status()
            if not st.enabled:
                raise RuntimeError("motion got disabled: "
                                   + "; ".join(self.motion.errors()))
            pending = (self.motion.queue_pending() if self.streaming
                       else 0)
            if st.in_position and st.queue_depth == 0 and not pending:
                return
            if cycles * DT > timeout:
                raise TimeoutError(f"program not done after {timeout} s")
            self.step(chunk)
            cycles += chunk

    def run(self, program: Sequence[Step], timeout: float = 120.0,
            settle: int = 0, prequeue: bool = False) -> Trace:
        """Queue a program, run it to its end (plus ``settle`` cycles)
        and return the trace (from the cycle after the first command).
        ``prequeue``: queue it all while the planner is paused, then
        resume (the run is not limited by the rate of queueing; the
        program must fit in the queue)."""
        start = self.start_recording()
        if prequeue:
            self.motion.pause()
        self.queue_program(program)
        if prequeue:
            self.motion.resume()
        self.run_until_done(timeout)
        if settle:
            self.step(settle)
        t = self.trace(start)
        # drop the samples after the end (run_until_done steps in chunks)
        return trim_rest(t)


def trim_rest(t: Trace, keep: int = 1) -> Trace:
    """The trace without the samples at rest after the last motion
    (keeping ``keep`` of them)."""
    if len(t) < 2:
        return t
    moving = np.flatnonzero(np.any(np.diff(t.pos, axis=0) != 0, axis=1))
    last = (moving[-1] + 1) if len(moving) else 0
    n = min(len(t), last + 1 + keep)
    return Trace(t.pos[:n], t.joints[:n], t.vel[:n], t.line[:n],
                 t.dt, t.start, {k: v[:n] for k, v in t.extra.items()})


def build_machine(hal: Any, coordinates: str = "xyz",
                  ini: Optional[Mapping[str, Mapping[str, Any]]] = None,
                  queue_size: Optional[int] = None,
                  sampler_depth: int = 4096,
                  timing_every: Optional[int] = None,
                  home: bool = True,
                  record: Sequence[tuple[str, str]] = ()) -> Machine:
    """Load and set up a machine (see the module's docstring).  ``ini``
    defaults to :func:`machine_ini` of the coordinates.  ``timing_every``
    (e.g. 1): replace motmod's servo thread by one whose functions are
    timed every that many cycles.  ``record``: more (pin, sampler type
    letter) pairs to record; they are in Trace.extra by pin name."""
    from halsdk.motion import Motion

    ini = machine_ini(coordinates) if ini is None else ini
    n = len(coordinates)
    hal.loadrt("trivkins", coordinates=coordinates)
    hal.loadrt("homemod")
    if queue_size:
        hal.loadrt("tpmod", queue_size=queue_size)
    else:
        hal.loadrt("tpmod")
    hal.loadrt("motmod", servo_period_nsec=1_000_000, num_joints=n)
    if timing_every is not None:
        hal.delthread("servo-thread")
        hal.newthread("servo-thread", 1_000_000, timing_every=timing_every)
    hal.addf("motion-command-handler", "servo-thread")
    hal.addf("motion-controller", "servo-thread")
    for j in range(n):
        hal.net(f"mt-fb{j}", f"joint.{j}.motor-pos-cmd",
                f"joint.{j}.motor-pos-fb")
    cfg = "f" * (9 + n) + "f" + "s" + "".join(t for _, t in record)
    hal.loadrt("sampler", depth=str(sampler_depth), cfg=cfg)
    pins = ([f"axis.{a}.pos-cmd" for a in AXES]
            + [f"joint.{j}.pos-cmd" for j in range(n)]
            + ["motion.current-vel", "motion.program-line"]
            + [name for name, _ in record])
    for k, name in enumerate(pins):
        hal.net(f"mt-rec{k}", name, f"sampler.0.pin.{k}")
    hal.addf("sampler.0", "servo-thread")

    m = Motion.connect(hal)
    joints = [ini.get(f"JOINT_{j}", {}) for j in range(n)]
    axes = {k[5:].lower(): v for k, v in ini.items()
            if k.upper().startswith("AXIS_")}
    m.configure(joints, axes, ini.get("TRAJ", {}))
    m.enable()
    if home:
        m.home(-1)
        m.wait_homed(timeout=5)
    m.coord()
    mach = Machine(hal, m, coordinates, ini, "sampler.0",
                   [name for name, _ in record])
    mach.start_recording()
    return mach


# ---------------------------------------------------------------- checkers


def path_deviation(trace: Trace, program: Sequence[Step],
                   start=None, axes: str = "xyz",
                   step: float = 0.005) -> np.ndarray:
    """For every sample, its distance (in the coordinates ``axes``) from
    the programmed path.  The search follows the progress along the path
    (a window of path length around the last match), so a point is
    compared with the part of the path it is on, not with another part
    that happens to pass near it."""
    start = trace.start if start is None else start
    pts, _ = program_path(program, start, step=step)
    idx = [AXES.index(a) for a in axes]
    P = pts[:, idx]
    if len(P) < 2:
        return np.linalg.norm(trace.pos[:, idx] - P[0], axis=1)
    A, B = P[:-1], P[1:]
    D = B - A
    L2 = np.einsum("ij,ij->i", D, D)
    seglen = np.sqrt(L2)
    s_cum = np.concatenate([[0.0], np.cumsum(seglen)])
    Q = trace.pos[:, idx]
    out = np.empty(len(Q))
    s_now = 0.0                             # path length of the last match
    vmax = float(np.max(trace.path_speed(axes))) if len(Q) else 0.0
    ahead = 4.0 * vmax * trace.dt + 2.0     # path length searched ahead
    behind = 1.0
    last = len(A) - 1
    for i, q in enumerate(Q):
        lo = int(np.searchsorted(s_cum, s_now - behind, side="right")) - 1
        hi = int(np.searchsorted(s_cum, s_now + ahead, side="right"))
        lo = max(0, min(lo, last))
        hi = max(lo + 1, min(hi, len(A)))
        a, d, l2 = A[lo:hi], D[lo:hi], L2[lo:hi]
        t = np.einsum("ij,ij->i", q - a, d)
        t = np.where(l2 > 0, np.clip(t / np.where(l2 > 0, l2, 1), 0, 1), 0)
        diff = a + d * t[:, None] - q
        dist = np.einsum("ij,ij->i", diff, diff)
        j = int(np.argmin(dist))
        out[i] = math.sqrt(dist[j])
        s_now = s_cum[lo + j] + t[j] * seglen[lo + j]
    return out


def axis_extremes(trace: Trace, axes: str = AXES) -> dict:
    """Per axis letter: max |v|, max |a| and max |jerk| by finite
    differences of the sampled positions (the start position before the
    first sample, at rest)."""
    out = {}
    for a in axes:
        i = AXES.index(a)
        p = np.concatenate([[trace.start[i]] * 2, trace.pos[:, i]])
        v = np.diff(p) / trace.dt
        acc = np.diff(v) / trace.dt
        j = np.diff(acc) / trace.dt
        out[a] = {"vel": float(np.abs(v).max(initial=0)),
                  "acc": float(np.abs(acc).max(initial=0)),
                  "jerk": float(np.abs(j).max(initial=0))}
    return out


def limit_violations(trace: Trace, machine: Machine, rel: float = 1e-6,
                     jerk: bool = False) -> list[str]:
    """Texts of the per-axis limits (the machine's [AXIS_L] velocity,
    acceleration and, with jerk, jerk) that the trace exceeds by more than
    ``rel`` relative."""
    bad = []
    ext = axis_extremes(trace, machine.coordinates)
    for a, e in ext.items():
        for key, ini in (("vel", "MAX_VELOCITY"), ("acc", "MAX_ACCELERATION"),
                         ("jerk", "MAX_JERK")):
            if key == "jerk" and not jerk:
                continue
            lim = machine.axis_limit(a, ini)
            if lim and e[key] > lim * (1 + rel) + 1e-9:
                bad.append(f"{a} {key} {e[key]:.6g} > {lim:g}")
    return bad


def stops(trace: Trace, eps: float = 1e-9) -> list[tuple[int, int]]:
    """(first sample, length) of each run of samples at rest between the
    first motion and the last one: the stops along the program."""
    v = trace.path_speed()
    moving = v > eps
    if not moving.any():
        return []
    first = int(np.argmax(moving))
    last = len(moving) - int(np.argmax(moving[::-1])) - 1
    out = []
    k = first
    while k <= last:
        if not moving[k]:
            j = k
            while j <= last and not moving[j]:
                j += 1
            out.append((k, j - k))
            k = j
        else:
            k += 1
    return out


def moving_time(trace: Trace, eps: float = 1e-9) -> float:
    """Time from the first cycle that moves to the last one."""
    moving = np.flatnonzero(trace.path_speed() > eps)
    if not len(moving):
        return 0.0
    return (moving[-1] - moving[0] + 1) * trace.dt


def mean_feed(trace: Trace, program: Sequence[Step], start=None) -> float:
    """Programmed path length over the time in motion."""
    start = trace.start if start is None else start
    t = moving_time(trace)
    return program_length(program, start) / t if t > 0 else 0.0


def allowed_time(points: np.ndarray, feed: float, vel: Sequence[float],
                 acc: Sequence[float]) -> float:
    """An estimate (on the fast side) of the time a smooth path (a fine
    polyline of XYZ points, treated as a smooth curve) needs from rest to
    rest at ``feed`` with per-axis velocity ``vel`` and acceleration
    ``acc`` limits: at every vertex the speed is at most the feed, at
    most what each axis' velocity allows along the tangent, and at most
    sqrt(a / curvature) with a the normal acceleration that every axis
    allows along the turning direction; along the path the speed changes
    with the tangential acceleration each axis allows, less what the
    normal acceleration uses (an ellipse of the two; forward and backward
    passes).  The per-axis sum of the two is not checked, which is why
    the estimate errs on the fast side."""
    P = np.asarray(points, float)[:, :3]
    d = np.diff(P, axis=0)
    ds = np.linalg.norm(d, axis=1)
    keep = ds > 1e-12
    d, ds = d[keep], ds[keep]
    t = d / ds[:, None]
    vel = np.asarray(vel, float)
    acc = np.asarray(acc, float)
    # speed limit of each segment from axis velocities, and the path
    # acceleration each axis allows along it
    with np.errstate(divide="ignore"):
        vseg = np.min(np.where(np.abs(t) > 1e-12, vel / np.abs(t), np.inf),
                      axis=1)
        aseg = np.min(np.where(np.abs(t) > 1e-12, acc / np.abs(t), np.inf),
                      axis=1)
    vseg = np.minimum(vseg, feed)
    # curvature at inner vertices: turning angle / mean segment length;
    # the normal acceleration v^2 kappa along the turning direction n may
    # be at most what every axis allows: acc_i / |n_i|
    dt_ = t[1:] - t[:-1]
    turn = np.linalg.norm(dt_, axis=1)
    cosang = np.clip(np.einsum("ij,ij->i", t[:-1], t[1:]), -1, 1)
    ang = np.arccos(cosang)
    kappa = ang / (0.5 * (ds[:-1] + ds[1:]))
    nrm = dt_ / np.where(turn > 0, turn, 1)[:, None]
    with np.errstate(divide="ignore"):
        an = np.min(np.where(np.abs(nrm) > 1e-12, acc / np.abs(nrm),
                             np.inf), axis=1)
        vk = np.where(kappa > 1e-12, np.sqrt(an / kappa), np.inf)
    # vertex limits: 0 at both ends
    vv = np.empty(len(ds) + 1)
    vv[0] = vv[-1] = 0.0
    vv[1:-1] = np.minimum(np.minimum(vseg[:-1], vseg[1:]), vk)
    # forward / backward passes; where the path turns, the tangential
    # acceleration is what the normal one leaves (an ellipse:
    # (a_t / aseg)^2 + (a_n / an)^2 <= 1)
    kv = np.zeros(len(ds) + 1)
    kv[1:-1] = kappa
    anv = np.full(len(ds) + 1, np.inf)
    anv[1:-1] = an

    def tangential(k: int, v: float, seg: int) -> float:
        u = v * v * kv[k] / anv[k] if kv[k] > 0 else 0.0
        return aseg[seg] * math.sqrt(max(0.0, 1.0 - u * u))

    for k in range(len(ds)):
        at = tangential(k, vv[k], k)
        vv[k + 1] = min(vv[k + 1], math.sqrt(vv[k] ** 2 + 2 * at * ds[k]))
    for k in range(len(ds) - 1, -1, -1):
        at = tangential(k + 1, vv[k + 1], k)
        vv[k] = min(vv[k], math.sqrt(vv[k + 1] ** 2 + 2 * at * ds[k]))
    vmean = np.maximum(0.5 * (vv[:-1] + vv[1:]), 1e-12)
    vmean = np.minimum(vmean, vseg)
    return float(np.sum(ds / vmean))


def looped_machine(hal: Any, vmax: float, amax: float, travel: float,
                   timeout: float = 30.0, setup: Any = None,
                   **modparams: Any):
    """A three-joint trivkins machine whose feedback is its command,
    configured with the same limits on every joint and axis, enabled and
    in coordinated mode; setup(hal) adds to it before the client
    connects.  Returns the connected halsdk.motion.Motion."""
    from halsdk.motion import Motion
    hal.loadrt("trivkins")
    hal.loadrt("homemod")
    hal.loadrt("tpmod")
    hal.loadrt("motmod", servo_period_nsec=1_000_000, num_joints=3,
               **modparams)
    hal.addf("motion-command-handler", "servo-thread")
    hal.addf("motion-controller", "servo-thread")
    for j in range(3):
        hal.net(f"fb{j}", f"joint.{j}.motor-pos-cmd",
                f"joint.{j}.motor-pos-fb")
    if setup is not None:
        setup(hal)
    m = Motion.connect(hal, timeout=timeout)
    m.configure(
        joints=[dict(MIN_LIMIT=-travel, MAX_LIMIT=travel, MAX_VELOCITY=vmax,
                     MAX_ACCELERATION=amax, FERROR=1, MIN_FERROR=0.5)] * 3,
        axes={a: dict(MIN_LIMIT=-travel, MAX_LIMIT=travel,
                      MAX_VELOCITY=vmax, MAX_ACCELERATION=amax)
              for a in "xyz"},
        traj=dict(MAX_LINEAR_VELOCITY=vmax, MAX_LINEAR_ACCELERATION=amax))
    m.enable()
    m.coord()
    return m
