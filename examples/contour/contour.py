#!/usr/bin/env python3
"""Run a contour program on the simulated mill and plot path and velocity.

The machine is the three-axis mill of ``examples/motion`` (``mill3.hal``:
motion + trivkins, a first-order "drive" per joint, simulated home
switches; ``mill3.ini``: its limits).  The program is CAM-like: a rounded
five-pointed star whose sides are bulged curves made of many short lines,
with arcs at the tips and in the inner corners, cut at Z -1 after a rapid
lead-in and a plunge, then a retract.  It is written in a small G-code
subset (see :func:`parse`) and can be saved or replaced (``--program``).

The script enables and homes the mill, queues the program in coordinated
mode with blending (``G64 P``), changes the feed override twice while it
runs (``--override``), records the commanded axis positions and the path
velocity every servo cycle, and writes a PNG with

* the programmed path and the executed one in the XY plane (with a zoom
  on one tip), and
* the path velocity over time, with the programmed feed and the feed times
  the override marked,

and prints a summary: program time, mean feed, largest distance between
the executed and the programmed path, largest acceleration of each axis.

    python contour.py                       # deterministic (stepped)
    python contour.py --out star.png --tolerance 0.005
    python contour.py --small               # a smaller program (tests)
    python contour.py --save-program star.ngc
    python contour.py --program my.ngc

The G-code subset (one block per line; case-insensitive; comments in
parentheses or after ``;``):

==============  ==========================================================
``G0``          rapid to the X Y Z given (the others stay)
``G1``          feed move to X Y Z at the modal feed ``F`` (mm/min)
``G2`` / ``G3`` clockwise / counterclockwise arc in the XY plane to X Y
                (Z: a helix) around the center at offset ``I J`` from
                the start
``G61``         exact path; ``G61.1`` exact stop
``G64 P<tol>``  blend within ``tol`` mm (``G64`` alone: as fast as
                possible)
``F<feed>``     feed in mm/min (modal)
==============  ==========================================================
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
from typing import Optional

import numpy as np

import halsdk
from halsdk.motion import Motion, Rejected

HERE = os.path.dirname(os.path.abspath(__file__))
MILL = os.path.join(os.path.dirname(HERE), "motion")
HALFILE = os.path.join(MILL, "mill3.hal")
INI = os.path.join(MILL, "mill3.ini")
DT = 1e-3                                   # mill3.hal's servo period

# the star: centre, radii, feed
CENTER = (70.0, 50.0)


# ---------------------------------------------------------------- program


def star_program(points: int = 5, r_out: float = 40.0, r_in: float = 17.0,
                 tip_radius: float = 4.0, corner_radius: float = 2.0,
                 bulge: float = 1.5, seg: float = 0.1, feed: float = 2400,
                 tolerance: float = 0.01, depth: float = -1.0) -> str:
    """G-code of a rounded star: sides are curves bulging outwards by
    ``bulge`` mm (tangent to the arcs where they meet them), as lines
    about ``seg`` mm long; tips and inner corners are arcs of the given
    radii."""
    cx, cy = CENTER
    # the sharp star's vertices, alternating outer and inner
    verts = []
    for k in range(2 * points):
        r = r_out if k % 2 == 0 else r_in
        a = math.pi / 2 + math.pi * k / points
        verts.append(np.array([cx + r * math.cos(a), cy + r * math.sin(a)]))
    n = len(verts)
    # fillet each vertex: the points where the arc meets the sides
    fil = []
    for k in range(n):
        p, a, b = verts[k], verts[k - 1], verts[(k + 1) % n]
        din = (p - a) / np.linalg.norm(p - a)
        dout = (b - p) / np.linalg.norm(b - p)
        turn = math.atan2(din[0] * dout[1] - din[1] * dout[0], din @ dout)
        rad = tip_radius if k % 2 == 0 else corner_radius
        back = rad * math.tan(abs(turn) / 2)
        p_in, p_out = p - din * back, p + dout * back
        left = np.array([-din[1], din[0]])
        center = p_in + (left if turn > 0 else -left) * rad
        fil.append((p_in, p_out, center, turn > 0))
    out = ["(rounded star: CAM-like short lines and arcs)",
           f"G64 P{tolerance:g}", f"G0 X{fil[0][1][0]:.4f} "
           f"Y{fil[0][1][1]:.4f} Z2", f"G1 Z{depth:g} F{feed / 3:g}",
           f"F{feed:g}"]
    for k in range(n):
        a = fil[k][1]
        p_in, p_out, center, ccw = fil[(k + 1) % n]
        # the side from a to p_in: a bulged curve (a sine-squared arch
        # outwards, so that it leaves and meets the arcs tangentially)
        d = p_in - a
        length = float(np.linalg.norm(d))
        normal = np.array([d[1], -d[0]]) / length      # to the right
        m = max(2, int(math.ceil(length / seg)))
        for i in range(1, m + 1):
            t = i / m
            q = a + d * t + normal * bulge * math.sin(math.pi * t) ** 2
            out.append(f"G1 X{q[0]:.4f} Y{q[1]:.4f}")
        off = center - p_in
        out.append(f"{'G3' if ccw else 'G2'} X{p_out[0]:.4f} "
                   f"Y{p_out[1]:.4f} I{off[0]:.4f} J{off[1]:.4f}")
    out.append("G0 Z2")
    return "\n".join(out) + "\n"


_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")


def parse(text: str) -> list:
    """Parse the G-code subset into steps (tuples ending with the line
    number): ("mode", name, tolerance, n), ("line", end dict, feed mm/s,
    rapid, n), ("arc", end dict, center, normal, feed mm/s, n)."""
    steps: list = []
    pos = {"x": 0.0, "y": 0.0, "z": 0.0}
    motion, feed = None, None
    for no, raw in enumerate(text.splitlines(), 1):
        line = re.sub(r"\(.*?\)", "", raw.split(";")[0]).upper().strip()
        if not line:
            continue
        words = _WORD.findall(line)
        if "".join(f"{k}{v}" for k, v in words).replace(" ", "") != \
                line.replace(" ", ""):
            raise ValueError(f"line {no}: cannot read {raw.strip()!r}")
        w: dict = {}
        for k, v in words:
            if k == "G":
                g = float(v)
                if g in (0, 1, 2, 3):
                    motion = int(g)
                elif g == 61:
                    steps.append(("mode", "exact", 0.0, no))
                elif g == 61.1:
                    steps.append(("mode", "stop", 0.0, no))
                elif g == 64:
                    w["G64"] = True
                else:
                    raise ValueError(f"line {no}: G{v} is not supported")
            else:
                w[k] = float(v)
        if w.pop("G64", False):
            steps.append(("mode", "blend", w.pop("P", 0.0), no))
        if "F" in w:
            feed = w.pop("F") / 60.0
        target = {a: w[a.upper()] for a in "xyz" if a.upper() in w}
        if not target:
            continue
        if motion is None:
            raise ValueError(f"line {no}: a move without G0/G1/G2/G3")
        if motion != 0 and not feed:
            raise ValueError(f"line {no}: a feed move without F")
        end = dict(pos, **target)
        if motion in (0, 1):
            steps.append(("line", end, feed or 0.0, motion == 0, no))
        else:
            if "I" not in w and "J" not in w:
                raise ValueError(f"line {no}: an arc needs I and/or J")
            center = (pos["x"] + w.get("I", 0.0), pos["y"] + w.get("J", 0.0),
                      pos["z"])
            normal = (0.0, 0.0, 1.0 if motion == 3 else -1.0)
            steps.append(("arc", end, center, normal, feed, no))
        pos = end
    return steps


def sample_path(steps: list, start: np.ndarray,
                step: float = 0.005) -> np.ndarray:
    """The programmed XYZ path as a fine polyline."""
    p = np.asarray(start, float)[:3].copy()
    pts = [p]
    for s in steps:
        if s[0] == "mode":
            continue
        q = np.array([s[1]["x"], s[1]["y"], s[1]["z"]])
        if s[0] == "line":
            pts.append(q)
        else:
            c, n = np.array(s[2]), np.array(s[3])
            u0, u1 = (p - c)[:2], (q - c)[:2]
            a0 = math.atan2(u0[1], u0[0])
            a1 = math.atan2(u1[1], u1[0])
            sweep = (a1 - a0) * n[2]
            if sweep <= 1e-12:
                sweep += 2 * math.pi
            r0, r1 = np.linalg.norm(u0), np.linalg.norm(u1)
            k = max(2, int(math.ceil(sweep * max(r0, r1) / step)))
            for t in np.arange(1, k + 1) / k:
                a = a0 + n[2] * sweep * t
                r = r0 + (r1 - r0) * t
                pts.append(np.array([c[0] + r * math.cos(a),
                                     c[1] + r * math.sin(a),
                                     p[2] + (q[2] - p[2]) * t]))
            pts[-1] = q
        p = q
    return np.array(pts)


def deviation(executed: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Distance of each executed point from the programmed polyline,
    searched near the point's progress along the path."""
    A, D = path[:-1], np.diff(path, axis=0)
    L2 = np.einsum("ij,ij->i", D, D)
    s_cum = np.concatenate([[0.0], np.cumsum(np.sqrt(L2))])
    out = np.empty(len(executed))
    s_now = 0.0
    for i, q in enumerate(executed):
        lo = max(0, int(np.searchsorted(s_cum, s_now - 1.0)) - 1)
        hi = max(lo + 1, min(len(A), int(np.searchsorted(s_cum,
                                                          s_now + 3.0))))
        a, d, l2 = A[lo:hi], D[lo:hi], L2[lo:hi]
        t = np.clip(np.einsum("ij,ij->i", q - a, d)
                    / np.where(l2 > 0, l2, 1), 0, 1)
        e = a + d * t[:, None] - q
        dist = np.einsum("ij,ij->i", e, e)
        j = int(np.argmin(dist))
        out[i] = math.sqrt(dist[j])
        s_now = s_cum[lo + j] + t[j] * math.sqrt(L2[lo + j])
    return out


# ---------------------------------------------------------------- running


def run(steps: list, overrides: list, instance: Optional[str] = None
        ) -> dict:
    """Build the mill, home it, run the steps; returns the recording."""
    with halsdk.Hal(instance=instance) as hal:
        if hal.source(HALFILE):
            raise SystemExit("mill3.hal failed")
        names = ["axis.x.pos-cmd", "axis.y.pos-cmd", "axis.z.pos-cmd",
                 "motion.current-vel"]
        hal.loadrt("sampler", depth="20000", cfg="ffff")
        for k, n in enumerate(names):
            hal.net(f"rec{k}", n, f"sampler.0.pin.{k}")
        hal.addf("sampler.0", "servo-thread")
        stream = hal.stream("sampler.0")
        motion = Motion.connect(hal, timeout=120)
        motion.configure_ini(INI)
        motion.enable()
        motion.home()
        motion.wait_homed()
        motion.coord()
        st = motion.status()
        start = np.array([st.carte_pos_cmd.x, st.carte_pos_cmd.y,
                          st.carte_pos_cmd.z])
        t0 = st.heartbeat
        fields = ["x", "y", "z", "vel"]
        if stream.depth:
            stream.read_many(stream.depth, fields)      # before the start
        chunks = []
        pending = sorted(overrides)
        applied = [(0.0, 1.0)]

        def tick():
            """Keep the recording and apply overrides that are due."""
            if stream.depth:
                chunks.append(stream.read_many(stream.depth, fields))
            now = (motion.status().heartbeat - t0) * DT
            while pending and pending[0][0] <= now:
                _, scale = pending.pop(0)
                motion.set_feed_scale(scale)
                applied.append((now, scale))

        vel_limit = st.vel_limit
        stream_moves = hasattr(motion, "queue_line")    # the move queue
        for s in steps:
            if stream_moves:
                # many moves per servo cycle, in order with G61/G64
                while motion.queue_free() == 0:
                    hal.step(1)
                    tick()
                if s[0] == "mode":
                    motion.queue_term_cond(
                        {"stop": 0, "exact": 1, "blend": 2}[s[1]], s[2])
                elif s[0] == "line":
                    motion.queue_line(s[1], vel=vel_limit if s[3] else s[2],
                                      rapid=s[3], line=s[-1])
                else:
                    motion.queue_circle(s[1], center=s[2], normal=s[3],
                                        vel=s[4], line=s[-1])
                tick()
                continue
            while True:             # one command per servo cycle
                try:
                    if s[0] == "mode":
                        motion.set_term_cond(
                            {"stop": 0, "exact": 1, "blend": 2}[s[1]], s[2])
                    elif s[0] == "line":
                        motion.set_line(s[1], vel=vel_limit if s[3]
                                        else s[2], rapid=s[3])
                    else:
                        motion.set_circle(s[1], center=s[2], normal=s[3],
                                          vel=s[4])
                    break
                except Rejected as r:
                    if "full" not in r.reason:
                        raise
                    hal.step(10)
                finally:
                    tick()
        while True:
            st = motion.status()
            if not st.enabled:
                raise SystemExit("motion disabled: "
                                 + "; ".join(motion.errors()))
            waiting = motion.queue_pending() if stream_moves else 0
            if st.in_position and st.queue_depth == 0 and not waiting:
                break
            hal.step(10)
            tick()
        tick()
        errors = motion.errors()
        motion.disable()
    pos = np.stack([np.concatenate([c[n] for c in chunks])
                    for n in ("x", "y", "z")], axis=1)
    vel = np.concatenate([c["vel"] for c in chunks])
    return {"start": start, "pos": pos, "vel": vel, "overrides": applied,
            "errors": errors}


def summarize(steps: list, rec: dict, limits: dict) -> dict:
    pos, start = rec["pos"], rec["start"]
    path = sample_path(steps, start)
    dev = deviation(pos, path)
    p = np.vstack([start, start, pos])
    v = np.diff(p, axis=0) / DT
    a = np.diff(v, axis=0) / DT
    speed = np.linalg.norm(v[1:], axis=1)
    moving = np.flatnonzero(speed > 1e-9)
    t_prog = (moving[-1] - moving[0] + 1) * DT if len(moving) else 0.0
    # mean feed over the feed moves: their length over their time (the
    # samples between the plunge's end and the retract's start at depth)
    feeds = [s for s in steps if s[0] in ("line", "arc") and
             not (s[0] == "line" and s[3])]
    feed = max(s[2] if s[0] == "line" else s[4] for s in feeds)
    depth = min(s[1]["z"] for s in feeds)
    at_depth = np.flatnonzero(np.abs(pos[:, 2] - depth) < 1e-9)
    cut = path[np.abs(path[:, 2] - depth) < 1e-9]
    cut_len = float(np.linalg.norm(np.diff(cut, axis=0), axis=1).sum())
    t_cut = (at_depth[-1] - at_depth[0]) * DT if len(at_depth) > 1 else 0
    tol = max([s[2] for s in steps if s[0] == "mode"] + [0.0])
    return {"segments": sum(1 for s in steps if s[0] != "mode"),
            "program_time": t_prog,
            "cut_time": t_cut,
            "cut_length": cut_len,
            "feed": feed,
            "mean_feed": cut_len / t_cut if t_cut else 0.0,
            "max_deviation": float(dev.max()),
            "tolerance": tol,
            "max_acc": {ax: float(np.abs(a[:, k]).max())
                        for k, ax in enumerate("xyz")},
            "acc_limit": limits,
            "deviation": dev}


def plot(steps: list, rec: dict, summary: dict, out: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pos, start = rec["pos"], rec["start"]
    path = sample_path(steps, start)
    fig = plt.figure(figsize=(15, 5.8))
    grid = fig.add_gridspec(1, 3, width_ratios=[1.25, 0.75, 1.5])
    ax = fig.add_subplot(grid[0])
    cut = np.abs(path[:, 2] - path[:, 2].min()) < 1e-9
    c = path[cut]
    ax.plot(path[:, 0], path[:, 1], color="0.6", lw=3,
            label="programmed")
    ax.plot(pos[:, 0], pos[:, 1], color="C3", lw=0.8, label="executed")
    span = max(np.ptp(c[:, 0]), np.ptp(c[:, 1])) * 0.6 + 3
    mid = 0.5 * (c.min(axis=0) + c.max(axis=0))
    ax.set_xlim(mid[0] - span, mid[0] + span)
    ax.set_ylim(mid[1] - span, mid[1] + span)
    ax.set_aspect("equal")
    ax.set_xlabel("X (mm)")
    ax.set_ylabel("Y (mm)")
    ax.set_title(f"XY path (G64 P{summary['tolerance']:g}): max "
                 f"deviation {summary['max_deviation']:.4f} mm", fontsize=10)
    ax.legend(loc="lower left", fontsize=8)
    # zoom on the top tip, where the path turns fastest
    tip = c[np.argmax(c[:, 1])]
    zx = fig.add_subplot(grid[1])
    zx.plot(path[:, 0], path[:, 1], color="0.6", lw=4, label="programmed")
    zx.plot(pos[:, 0], pos[:, 1], ".-", color="C3", lw=0.6, ms=2,
            label="executed, one dot per servo cycle")
    zx.set_xlim(tip[0] - 4, tip[0] + 4)
    zx.set_ylim(tip[1] - 9, tip[1] + 1)
    zx.set_aspect("equal")
    zx.set_title("zoom: the top tip", fontsize=10)
    zx.legend(loc="lower center", fontsize=7)
    ax.add_patch(plt.Rectangle((tip[0] - 4, tip[1] - 9), 8, 10, fill=False,
                               ec="0.3", lw=0.8, ls="--"))

    bx = fig.add_subplot(grid[2])
    t = np.arange(1, len(pos) + 1) * DT
    speed = np.linalg.norm(np.diff(np.vstack([start, pos]), axis=0),
                           axis=1) / DT
    bx.plot(t, speed * 60, color="C0", lw=0.8, label="path velocity")
    feed = summary["feed"] * 60
    bx.axhline(feed, color="k", ls="--", lw=1, label=f"F{feed:g}")
    ov = rec["overrides"] + [(t[-1], rec["overrides"][-1][1])]
    tt = [x for x, _ in ov]
    ss = [s * feed for _, s in ov]
    bx.step(tt, ss, where="post", color="C2", lw=1.2,
            label="F x feed override")
    for x, s in rec["overrides"][1:]:
        bx.annotate(f"override {s:.0%}", (x, s * feed),
                    textcoords="offset points", xytext=(4, 6), fontsize=8,
                    color="C2")
    bx.set_xlabel("time (s)")
    bx.set_ylabel("mm/min")
    bx.set_title(f"path velocity: program {summary['program_time']:.2f} s, "
                 f"mean cutting feed {summary['mean_feed'] * 60:.0f} "
                 "mm/min", fontsize=10)
    bx.legend(loc="lower center", fontsize=8)
    bx.set_ylim(0, max(speed.max() * 60, feed * 1.3) * 1.05)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def parse_overrides(text: str) -> list:
    out = []
    for part in filter(None, text.split(",")):
        t, s = part.split(":")
        out.append((float(t), float(s)))
    return out


def main(argv: Optional[list[str]] = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="contour.png", help="PNG to write")
    p.add_argument("--program", help="run this G-code file instead of "
                   "the star")
    p.add_argument("--save-program", metavar="FILE",
                   help="write the star program to FILE")
    p.add_argument("--small", action="store_true",
                   help="a smaller, coarser star (quick)")
    p.add_argument("--tolerance", type=float, default=0.01,
                   help="G64 P of the star, mm (default 0.01)")
    p.add_argument("--feed", type=float, default=2400,
                   help="feed of the star, mm/min (default 2400)")
    p.add_argument("--override", default=None, metavar="T:S,...",
                   help="feed override S from T seconds after the start "
                   "(default: 70%% at 40%% of the expected time, 120%% at "
                   "70%%)")
    p.add_argument("--instance", help=argparse.SUPPRESS)
    a = p.parse_args(argv)

    if a.program:
        with open(a.program) as f:
            text = f.read()
    elif a.small:
        text = star_program(r_out=20, r_in=8.5, seg=0.25, bulge=0.8,
                            feed=a.feed, tolerance=a.tolerance)
    else:
        text = star_program(feed=a.feed, tolerance=a.tolerance)
    if a.save_program:
        with open(a.save_program, "w") as f:
            f.write(text)
    steps = parse(text)
    if a.override is None:
        length = float(np.linalg.norm(np.diff(sample_path(
            steps, np.zeros(3), 0.05), axis=0), axis=1).sum())
        expect = length / (a.feed / 60)
        overrides = [(0.4 * expect, 0.7), (0.7 * expect, 1.2)]
    else:
        overrides = parse_overrides(a.override)
    rec = run(steps, overrides, a.instance)
    from halsdk.motion.ini import read_motion_ini
    axes = read_motion_ini(INI).axes
    limits = {ax: float({k.upper(): v for k, v in axes[ax].items()}
                        ["MAX_ACCELERATION"]) for ax in "xyz"}
    summary = summarize(steps, rec, limits)
    plot(steps, rec, summary, a.out)
    print(f"segments        {summary['segments']}")
    print(f"program time    {summary['program_time']:.3f} s")
    print(f"mean feed       {summary['mean_feed'] * 60:.0f} mm/min while "
          f"cutting (F{summary['feed'] * 60:g}, overrides "
          + ", ".join(f"{s:.0%} at {t:.2f} s"
                      for t, s in rec["overrides"][1:]) + ")")
    print(f"max deviation   {summary['max_deviation']:.5f} mm "
          f"(G64 P{summary['tolerance']:g})")
    print("max accel       " + ", ".join(
        f"{ax.upper()} {summary['max_acc'][ax]:.1f}/{limits[ax]:g}"
        for ax in "xyz") + " mm/s^2")
    for e in rec["errors"]:
        print("motion:", e)
    print(f"plot            {a.out}")
    return summary


if __name__ == "__main__":
    main()
    sys.exit(0)
