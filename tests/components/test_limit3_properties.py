"""Property tests of limit3: whatever the input does, out stays within
[min, max] and, once started from rest, never moves faster than maxv nor
accelerates harder than maxa (rounding aside). The reference's output on
a runaway input is compared in tests/data/complib/limit3-runaway.*."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from helpers import data_path
from helpers.components import setup
from helpers.halrun import tools_env
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

DT = 1e-3
STEPS = 150

#: one segment of input: a hold, a jump, or a ramp (speeds up to 1e6/s,
#: far beyond maxv), each a few periods long
segment = st.tuples(st.sampled_from(["hold", "jump", "ramp", "accel"]),
                    st.floats(-1e6, 1e6), st.integers(1, 40))


def input_signal(segments, start: float) -> np.ndarray:
    x, out = start, []
    for kind, value, n in segments:
        for k in range(n):
            if kind == "jump":
                x = value
            elif kind == "ramp":
                x += value * DT
            elif kind == "accel":
                x += value * DT * DT * (k + 1) * 50
            out.append(x)
    while len(out) < STEPS:
        out.append(x)
    return np.array(out[:STEPS])


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lo=st.floats(-1000, 1000), span=st.floats(0.01, 2000),
       maxv=st.floats(0.1, 1e5), maxa=st.floats(1.0, 1e7),
       smooth=st.integers(0, 4), start=st.floats(0, 1),
       segments=st.lists(segment, min_size=1, max_size=8),
       enable=st.lists(st.booleans(), min_size=STEPS, max_size=STEPS))
def test_limit3_never_leaves_its_limits(hal, lo, span, maxv, maxa, smooth,
                                        start, segments, enable):
    if not hal.components("limit3"):
        setup(hal, "limit3", "limit3.0")
    hi = lo + span
    x0 = lo + start * span
    hal.set({"limit3.0.min": lo, "limit3.0.max": hi, "limit3.0.maxv": maxv,
             "limit3.0.maxa": maxa, "limit3.0.smooth-steps": smooth,
             "limit3.0.enable": True, "limit3.0.in": x0,
             "limit3.0.load": True})
    hal.step(1)                     # at rest at x0
    hal.setp("limit3.0.load", False)
    # enable mostly TRUE, with a few stretches FALSE (goal 0)
    en = np.array(enable) | (np.arange(STEPS) % 50 < 35)
    tr = hal.run(STEPS, inputs={"limit3.0.in": input_signal(segments, x0),
                                "limit3.0.enable": en},
                 record=["limit3.0.out"])
    out = np.concatenate([[x0], tr["limit3.0.out"]])
    assert out.min() >= lo and out.max() <= hi
    scale = max(abs(lo), abs(hi))
    eps = 8 * np.finfo(float).eps * scale      # rounding of out
    vel = np.diff(out) / DT
    acc = np.diff(np.concatenate([[0.0], vel])) / DT
    assert np.abs(vel).max() <= maxv * (1 + 1e-9) + eps / DT
    assert np.abs(acc).max() <= maxa * (1 + 1e-9) + eps / DT ** 2


def test_limit3_runaway_input_stops_at_max(hal):
    """An input running away at 1e6 units/s: out stops at max without
    overshoot, then comes back when the input does."""
    setup(hal, "limit3", "limit3.0")
    hal.set({"limit3.0.min": -50.0, "limit3.0.max": 100.0,
             "limit3.0.maxv": 1e5, "limit3.0.maxa": 1e6})
    x = np.concatenate([np.arange(1, 301) * 1000.0,
                        300000.0 - np.arange(1, 301) * 2000.0])
    out = hal.run(len(x), inputs={"limit3.0.in": x},
                  record=["limit3.0.out"])["limit3.0.out"]
    assert out.max() == 100.0 and out.min() == -50.0
    assert out[250] == 100.0 and out[-1] == -50.0


def test_limit3_runaway_against_the_reference(tmp_path: Path):
    """limit3-runaway.hal through our halrun, against the reference's
    recorded run (tests/data/complib/limit3-runaway.*, made by
    limit3-runaway.py and golden.py). Both hold every limit; the
    braking profiles differ by a few units (ours brakes at the last
    period that still stops at the bound, and follows the input's turn
    a little later), so the comparison is of the limits, the bounds
    reached and the end state, with a bounded gap."""
    complib = data_path("complib")
    for name in ("limit3-runaway.hal", "limit3-runaway.txt"):
        shutil.copy(complib / name, tmp_path / name)
    proc = subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-f",
         "limit3-runaway.hal"], cwd=tmp_path,
        env=tools_env("limit3-runaway", tmp_path / "bin"),
        capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    ours = np.loadtxt(proc.stdout.splitlines())
    ref = np.loadtxt(complib / "limit3-runaway.out")
    assert ours.shape == ref.shape == (600, 4)
    assert (ours[:, 0] == ref[:, 0]).all()          # the same input
    limits = [(-50, 100, 1000, 1e5), (-50, 100, 200, 5000),
              (-1000, 1000, 1e5, 1e6)]
    # the printed values have 6 decimals: allow that in v and a
    for col, (lo, hi, maxv, maxa) in enumerate(limits, 1):
        for run in (ours, ref):
            x = run[:, col]
            v = np.diff(np.concatenate([[0.0], x])) / DT
            a = np.diff(np.concatenate([[0.0], v])) / DT
            assert lo <= x.min() and x.max() <= hi
            assert np.abs(v).max() <= maxv + 1e-3
            assert np.abs(a).max() <= maxa * (1 + 1e-5) + 2
    # identical until the first braking, the same bounds reached
    assert (ours[:32] == ref[:32]).all()
    for col in (1, 3):
        assert ours[:, col].max() == ref[:, col].max() == limits[col - 1][1]
        assert ours[-1, col] == ref[-1, col] == limits[col - 1][0]
    gap = np.abs(ours - ref).max(axis=0)
    assert (gap[1:] <= [6, 5, 20]).all(), gap


def test_limit3_extreme_limits_do_not_hang(hal):
    """A huge maxv (or room to a bound) made the braking solver loop for
    ever (n + 1 == n for such n), hanging the thread; found by the
    differential fuzz.  Every cycle must now return."""
    setup(hal, "limit3", "limit3.0")
    hal.set({"limit3.0.min": 0.0, "limit3.0.max": -1.719,
             "limit3.0.maxa": 5.834, "limit3.0.maxv": -1e300,
             "limit3.0.in": 17.436})
    hal.step(3)
    for maxv, maxa, lo, hi in [(1e300, 1e300, -1e300, 1e300),
                               (float("inf"), 1.0, -1e300, 1e300),
                               (1.0, float("inf"), -float("inf"), 0.0)]:
        hal.set({"limit3.0.min": lo, "limit3.0.max": hi,
                 "limit3.0.maxv": maxv, "limit3.0.maxa": maxa,
                 "limit3.0.in": 1e299})
        hal.step(3)
