"""The shipped math components (abs, abs_s32, sum2, scale, mult2, div2,
invert, ddt, integ, lowpass, ilowpass, biquad, limit1, limit2, limit3,
hypot, near, comp, wcomp): behaviour stated in Python, stepped
deterministically.  The numbers they must share with LinuxCNC 2.9 are
checked against its own runs in tests/data/complib
(golden/test_complib_golden.py); these tests state the rules those runs
showed."""

from __future__ import annotations

import math

import numpy as np
import pytest

import halsdk

PERIOD = 1_000_000          # 1 ms


def setup(hal, comp, *args, names=None, **kw):
    """Load comp, add its functions to a 1 ms thread; the instance names."""
    made = hal.loadrt(comp, *args, **kw)
    assert made == [comp]
    hal.newthread("t", PERIOD)
    insts = names or [f.name for f in hal.functions()]
    for inst in insts:
        hal.addf(inst, "t")
    return insts


def run(hal, n, inputs, record):
    return hal.run(n, inputs=inputs, record=record)


# ------------------------------------------------------------------ abs

def test_abs_magnitude_and_flags(hal):
    setup(hal, "abs")
    x = np.array([2.5, -3.0, 0.0, -0.0, 1e-6, -1e-6, 2e-6, -2e-6, -math.inf])
    tr = run(hal, len(x), {"abs.0.in": x},
             ["abs.0.out", "abs.0.sign", "abs.0.is-positive",
              "abs.0.is-negative"])
    assert tr["abs.0.out"].tolist() == [2.5, 3.0, 0, 0, 1e-6, 1e-6, 2e-6,
                                        2e-6, math.inf]
    assert tr["abs.0.sign"].tolist() == [False, True, False, False, False,
                                         True, False, True, True]
    # values within 1e-6 of zero count as zero for the two flags
    assert tr["abs.0.is-positive"].tolist() == [True, False, False, False,
                                                False, False, True, False,
                                                False]
    assert tr["abs.0.is-negative"].tolist() == [False, True, False, False,
                                                False, False, False, True,
                                                True]


def test_abs_s32_names_and_extremes(hal):
    setup(hal, "abs_s32", count=2)
    assert sorted(p.name for p in hal.pins("abs-s32.1.*")) == [
        "abs-s32.1.in", "abs-s32.1.is-negative", "abs-s32.1.is-positive",
        "abs-s32.1.out", "abs-s32.1.sign", "abs-s32.1.time"]
    [f] = [f for f in hal.functions() if f.name == "abs-s32.0"]
    assert f.uses_fp is False
    x = [0, 7, -7, 2**31 - 1, -2**31 + 1, -2**31]
    tr = run(hal, len(x), {"abs-s32.0.in": x},
             ["abs-s32.0.out", "abs-s32.0.is-positive", "abs-s32.0.sign"])
    # the most negative s32 has no positive counterpart: it wraps
    assert tr["abs-s32.0.out"].tolist() == [0, 7, 7, 2**31 - 1, 2**31 - 1,
                                            -2**31]
    assert tr["abs-s32.0.is-positive"].tolist() == [False, True, False,
                                                    True, False, False]
    assert tr["abs-s32.0.sign"].tolist() == [False, False, True, False,
                                             True, True]


def test_abs_s32_load_line(hal):
    assert hal.loadrt("abs_s32", names="x,y") == ["abs_s32"]
    assert hal.getp("y.out") == 0
    hal.unloadrt("abs_s32")
    with pytest.raises(halsdk.InvalidError, match="mutually exclusive"):
        hal.loadrt("abs_s32", count=2, names="a")
    assert hal.pins("a.*") == [] and hal.pins("abs-s32.*") == []


# ---------------------------------------------------- sum2, scale, mult2

def test_sum2_gains_and_offset(hal):
    setup(hal, "sum2")
    assert hal.getp("sum2.0.gain0") == 1.0 and hal.getp("sum2.0.gain1") == 1.0
    hal.set({"sum2.0.in0": 3.0, "sum2.0.in1": -1.5})
    hal.step(1)
    assert hal.getp("sum2.0.out") == 1.5
    hal.set({"sum2.0.gain0": -2.0, "sum2.0.gain1": 0.5, "sum2.0.offset": 10})
    hal.step(1)
    assert hal.getp("sum2.0.out") == -6.0 - 0.75 + 10


def test_scale_pins_change_each_cycle(hal):
    setup(hal, "scale")
    tr = run(hal, 4, {"scale.0.in": [2.0, 2.0, -2.0, 5.0],
                      "scale.0.gain": [3.0, 3.0, -3.0, 0.0],
                      "scale.0.offset": [0.0, 1.0, -1.0, -7.0]},
             ["scale.0.out"])
    assert tr["scale.0.out"].tolist() == [6.0, 7.0, 5.0, -7.0]


def test_mult2(hal):
    setup(hal, "mult2")
    tr = run(hal, 4, {"mult2.0.in0": [3.0, -3.0, 0.0, 1e200],
                      "mult2.0.in1": [4.0, 4.0, -5.0, 1e200]},
             ["mult2.0.out"])
    assert tr["mult2.0.out"].tolist() == [12.0, -12.0, 0.0, math.inf]


# --------------------------------------------------------- div2, invert

def test_div2_deadband(hal, capfd):
    setup(hal, "div2", count=2)
    hal.setp("div2.1.deadband", 0.5)
    d = [2.0, 0.0, -0.0, 0.25, -0.25, 0.5, -1e-13]
    tr = run(hal, len(d), {"div2.0.in0": [3.0] * len(d),
                           "div2.1.in0": [3.0] * len(d),
                           "div2.0.in1": d, "div2.1.in1": d},
             ["div2.0.out", "div2.1.out"])
    # a deadband below 1e-12 (the default 0 too) is raised to 1e-12
    assert hal.getp("div2.0.deadband") == 1e-12
    assert tr["div2.0.out"].tolist() == pytest.approx(
        [1.5, 3e12, 3e12, 12.0, -12.0, 6.0, -3e12])
    # inside the deadband the divisor becomes +-deadband; -0.0 counts as +
    assert tr["div2.1.out"].tolist() == [1.5, 6.0, 6.0, 6.0, -6.0, 6.0,
                                         -6.0]
    assert "DIV2 DIVISOR IS TOO CLOSE TO +ZERO" in capfd.readouterr().err


def test_invert_deadband(hal):
    setup(hal, "invert", count=2)
    hal.setp("invert.0.deadband", -1.0)
    hal.setp("invert.1.deadband", 0.5)
    x = [4.0, -0.25, 0.0, 1e-9, -0.5]
    tr = run(hal, len(x), {"invert.0.in": x, "invert.1.in": x},
             ["invert.0.out", "invert.1.out"])
    assert hal.getp("invert.0.deadband") == 1e-12
    assert tr["invert.0.out"].tolist() == pytest.approx(
        [0.25, -4.0, 1e12, 1e9, -2.0])
    assert tr["invert.1.out"].tolist() == [0.25, -2.0, 2.0, 2.0, -2.0]


# ---------------------------------------------------------- ddt, integ

def test_ddt_uses_the_period(hal):
    setup(hal, "ddt")
    tr = run(hal, 5, {"ddt.0.in": [0.0, 0.5, 1.0, 1.0, -1.0]},
             ["ddt.0.out"])
    assert tr["ddt.0.out"].tolist() == pytest.approx(
        [0.0, 500.0, 500.0, 0.0, -2000.0])


def test_integ_gain_reset_and_windup(hal):
    setup(hal, "integ")
    assert hal.getp("integ.0.gain") == 1.0
    assert hal.getp("integ.0.max") == 1e20 and hal.getp("integ.0.min") == -1e20
    tr = run(hal, 6, {"integ.0.in": 1000.0,
                      "integ.0.gain": [1.0, 2.0, 2.0, 1.0, 1.0, 1.0],
                      "integ.0.reset": [0, 0, 0, 1, 0, 0],
                      "integ.0.max": [9.0, 9.0, 4.0, 9.0, 9.0, 9.0]},
             ["integ.0.out"])
    assert tr["integ.0.out"].tolist() == pytest.approx(
        [1.0, 3.0, 4.0, 0.0, 1.0, 2.0])
    # crossed limits: min is applied last and wins, also during reset
    hal.set({"integ.0.max": -3.0, "integ.0.min": -1.0, "integ.0.reset": True})
    hal.step(1)
    assert hal.getp("integ.0.out") == -1.0


# ------------------------------------------------------ lowpass filters

def test_lowpass_gain_is_live_and_load(hal):
    setup(hal, "lowpass")
    hal.set({"lowpass.0.in": 100.0})
    hal.step(3)
    assert hal.getp("lowpass.0.out") == 0.0        # default gain 0 holds
    hal.setp("lowpass.0.gain", 0.5)
    tr = run(hal, 3, {}, ["lowpass.0.out"])
    assert tr["lowpass.0.out"].tolist() == [50.0, 75.0, 87.5]
    hal.setp("lowpass.0.gain", 0.25)               # changed mid-run
    hal.step(1)
    assert hal.getp("lowpass.0.out") == 87.5 + 12.5 * 0.25
    hal.set({"lowpass.0.load": True, "lowpass.0.in": -3.0})
    hal.step(1)
    assert hal.getp("lowpass.0.out") == -3.0


def test_ilowpass_rounds_halves_up_and_wraps(hal):
    setup(hal, "ilowpass", count=2)
    assert hal.getp("ilowpass.0.scale") == 1024
    assert hal.getp("ilowpass.0.gain") == 0.5
    tr = run(hal, 3, {"ilowpass.0.in": 1}, ["ilowpass.0.out"])
    assert tr["ilowpass.0.out"].tolist() == [512, 768, 896]
    hal.setp("ilowpass.1.scale", 0.5)
    hal.setp("ilowpass.1.gain", 1.0)
    x = [1, 3, 5, -1, -3, -5]
    tr = run(hal, len(x), {"ilowpass.1.in": x}, ["ilowpass.1.out"])
    assert tr["ilowpass.1.out"].tolist() == [1, 2, 3, 0, -1, -2]
    # beyond the s32 range the output keeps the low 32 bits
    hal.setp("ilowpass.1.scale", 1024)
    hal.set({"ilowpass.1.in": 3_000_000})
    hal.step(1)
    assert hal.getp("ilowpass.1.out") == 3_072_000_000 - 2**32


def test_biquad_designs_on_enable_edge(hal):
    setup(hal, "biquad", count=2)
    assert hal.getp("biquad.0.f0") == 250.0
    assert hal.getp("biquad.0.Q") == pytest.approx(0.7071)
    # disabled: out follows in
    hal.set({"biquad.0.in": 3.0, "biquad.0.type": 1})
    hal.step(1)
    assert hal.getp("biquad.0.out") == 3.0 and not hal.getp("biquad.0.valid")
    # enabling designs a low-pass filter for the 1 ms period
    hal.set({"biquad.0.enable": True})
    tr = run(hal, 400, {"biquad.0.in": 1.0}, ["biquad.0.out"])
    assert hal.getp("biquad.0.valid")
    n0, n1, n2 = (hal.getp(f"biquad.0.{c}") for c in ("n0", "n1", "n2"))
    d1, d2 = hal.getp("biquad.0.d1"), hal.getp("biquad.0.d2")
    assert n0 == pytest.approx(0.2928921) and n1 == pytest.approx(2 * n0)
    assert n2 == n0 and abs(d1) < 1e-12 and d2 == pytest.approx(0.1715682)
    assert tr["biquad.0.out"][0] == pytest.approx(n0)
    assert tr["biquad.0.out"][-1] == pytest.approx(1.0)       # unity DC gain
    # a new f0 only takes effect on the next rising edge of enable
    hal.set({"biquad.0.f0": 20.0})
    hal.step(1)
    assert hal.getp("biquad.0.n0") == n0
    hal.set({"biquad.0.enable": False})
    hal.step(1)
    hal.set({"biquad.0.enable": True})
    hal.step(1)
    assert hal.getp("biquad.0.n0") < n0 / 10
    # type 0 uses the params as they are, and they are read live
    hal.set({"biquad.1.type": 0, "biquad.1.enable": True, "biquad.1.in": 2.0})
    hal.step(1)
    assert hal.getp("biquad.1.valid") and hal.getp("biquad.1.out") == 2.0
    hal.setp("biquad.1.n0", 0.5)
    hal.step(1)
    assert hal.getp("biquad.1.out") == 1.0


@pytest.mark.parametrize("typ, f0, q, valid", [
    (1, 250.0, 0.5, True), (1, 250.0, 0.4999, False), (2, 250.0, 2.0, True),
    (2, 250.0, 2.0001, False), (1, 500.0, 0.7, True), (1, 501.0, 0.7, False),
    (3, 250.0, 0.7, False)])
def test_biquad_validity(hal, typ, f0, q, valid):
    setup(hal, "biquad")
    hal.set({"biquad.0.type": typ, "biquad.0.f0": f0, "biquad.0.Q": q,
             "biquad.0.in": 5.0, "biquad.0.enable": True})
    hal.step(1)
    assert hal.getp("biquad.0.valid") is valid
    if not valid:
        assert hal.getp("biquad.0.out") == 5.0     # unfiltered


# ---------------------------------------------------------------- limits

def test_limit1_max_wins_when_limits_cross(hal):
    setup(hal, "limit1")
    tr = run(hal, 5, {"limit1.0.in": [5.0, -5.0, 0.5, 3.0, -3.0],
                      "limit1.0.min": [-1.0, -1.0, -1.0, 2.0, 2.0],
                      "limit1.0.max": [1.0, 1.0, 1.0, -2.0, -2.0]},
             ["limit1.0.out"])
    assert tr["limit1.0.out"].tolist() == [1.0, -1.0, 0.5, -2.0, -2.0]


def test_limit2_slew_load_and_limits(hal):
    setup(hal, "limit2")
    hal.set({"limit2.0.maxv": 1000.0, "limit2.0.in": 3.5})
    tr = run(hal, 5, {}, ["limit2.0.out"])
    assert tr["limit2.0.out"].tolist() == [1.0, 2.0, 3.0, 3.5, 3.5]
    hal.set({"limit2.0.load": True, "limit2.0.in": -8.0,
             "limit2.0.min": -2.0})
    hal.step(1)
    assert hal.getp("limit2.0.out") == -2.0        # load still clamps
    # crossed limits: min wins; maxv 0 freezes out
    hal.set({"limit2.0.load": False, "limit2.0.min": 2.0,
             "limit2.0.max": -2.0, "limit2.0.in": 0.0, "limit2.0.maxv": 0})
    hal.step(2)
    assert hal.getp("limit2.0.out") == -2.0
    hal.setp("limit2.0.maxv", 1e20)
    hal.step(1)
    assert hal.getp("limit2.0.out") == 2.0


def test_limit3_trapezoid_lands_exactly(hal):
    setup(hal, "limit3")
    hal.set({"limit3.0.maxv": 100.0, "limit3.0.maxa": 10000.0,
             "limit3.0.in": 5.0})
    tr = run(hal, 70, {}, ["limit3.0.out"])
    x = tr["limit3.0.out"]
    v = np.diff(np.concatenate([[0.0], x])) / 1e-3
    a = np.diff(np.concatenate([[0.0], v])) / 1e-3
    assert np.all(np.abs(v) <= 100.0 + 1e-9)
    assert np.all(np.abs(a) <= 10000.0 + 1e-6)
    assert v[:10] == pytest.approx(np.arange(1, 11) * 10.0)  # full accel
    assert x[-1] == 5.0 and np.all(x <= 5.0 + 1e-12)        # no overshoot
    assert np.count_nonzero(np.abs(v - 100.0) < 1e-9) >= 30  # cruise


def test_limit3_last_steps_halve_then_land(hal):
    """From one period of braking left (0.5 units/s, 0.5 mm to go), the
    default smoothing halves the speed each period, then out lands on the
    goal exactly once within rounding of it."""
    setup(hal, "limit3")
    hal.set({"limit3.0.maxv": 50.0, "limit3.0.maxa": 500.0,
             "limit3.0.in": 1.0})
    x = run(hal, 130, {}, ["limit3.0.out"])["limit3.0.out"]
    v = np.diff(x) / 1e-3
    assert v[88] == pytest.approx(0.25) and v[89] == pytest.approx(0.125)
    assert x[-1] == 1.0 and 1.0 - x[110] > 0


@pytest.mark.parametrize("smooth", [0, 1, 2, 3, 5])
def test_limit3_limits_hold_for_any_smoothing(hal, smooth):
    setup(hal, "limit3")
    hal.set({"limit3.0.maxv": 100.0, "limit3.0.maxa": 10000.0,
             "limit3.0.smooth-steps": smooth})
    goal = np.concatenate([np.full(60, 1.234567), np.full(80, -2.0003),
                           np.linspace(-2.0, 1.0, 100)])
    tr = run(hal, len(goal), {"limit3.0.in": goal}, ["limit3.0.out"])
    x = tr["limit3.0.out"]
    v = np.diff(np.concatenate([[0.0], x])) / 1e-3
    a = np.diff(np.concatenate([[0.0], v])) / 1e-3
    assert np.all(np.abs(v) <= 100.0 + 1e-6)
    assert np.all(np.abs(a) <= 10000.0 * (1 + 1e-6))
    assert x[59] == 1.234567 and x[139] == -2.0003
    assert x[-1] == pytest.approx(1.0)              # tracks the ramp


def test_limit3_smoothing_brakes_gradually(hal):
    """Near the goal the last braking is spread over smooth-steps periods:
    from 10 units/period with 7.3 units to go, smooth-steps 0 stops and
    starts again, 2 halves the speed."""
    setup(hal, "limit3", count=2)
    for i, s in enumerate((0, 2)):
        hal.set({f"limit3.{i}.maxv": 1e5, f"limit3.{i}.maxa": 1e7,
                 f"limit3.{i}.smooth-steps": s, f"limit3.{i}.in": 57.3})
    tr = run(hal, 9, {}, ["limit3.0.out", "limit3.1.out"])
    assert tr["limit3.0.out"].tolist() == pytest.approx(
        [10, 30, 40, 40, 50, 50, 57.3, 57.3, 57.3])
    assert tr["limit3.1.out"].tolist() == pytest.approx(
        [10, 30, 40, 40, 50, 55, 57.3, 57.3, 57.3])


def test_limit3_min_max_enable_load(hal):
    setup(hal, "limit3")
    assert hal.getp("limit3.0.enable") is True
    assert hal.getp("limit3.0.smooth-steps") == 2
    hal.set({"limit3.0.maxv": 100.0, "limit3.0.maxa": 10000.0,
             "limit3.0.max": 0.5, "limit3.0.in": 3.0})
    hal.step(100)
    assert hal.getp("limit3.0.out") == 0.5
    hal.set({"limit3.0.enable": False})
    hal.step(100)
    assert hal.getp("limit3.0.out") == 0.0
    hal.set({"limit3.0.enable": True, "limit3.0.load": True,
             "limit3.0.in": -7.0})
    hal.step(1)
    assert hal.getp("limit3.0.out") == -7.0        # no limits but min/max
    hal.set({"limit3.0.load": False, "limit3.0.in": -6.0})
    hal.step(1)
    assert hal.getp("limit3.0.out") == pytest.approx(-7.0 + 0.01)  # at rest


# ------------------------------------------------ hypot and comparators

def test_hypot(hal):
    setup(hal, "hypot")
    tr = run(hal, 3, {"hypot.0.in0": [3.0, -1.0, 1e200],
                      "hypot.0.in1": [-4.0, 2.0, 0.0],
                      "hypot.0.in2": [0.0, -2.0, 0.0]}, ["hypot.0.out"])
    assert tr["hypot.0.out"].tolist() == [5.0, 3.0, math.inf]


def test_near_ratio_and_difference(hal):
    setup(hal, "near", count=3)
    hal.setp("near.1.scale", 1.1)
    hal.setp("near.2.difference", 0.1)
    pairs = [(1.0, 1.0), (1.0, 1.1), (1.0, 0.9), (-1.0, -1.05), (-1.0, 1.0),
             (0.1, 0.0), (0.0, -0.11)]
    a, b = zip(*pairs)
    rec = [f"near.{i}.out" for i in range(3)]
    tr = run(hal, len(pairs), {f"near.{i}.in1": list(a) for i in range(3)}
             | {f"near.{i}.in2": list(b) for i in range(3)}, rec)
    assert tr["near.0.out"].tolist() == [1, 0, 0, 0, 0, 0, 0]
    assert tr["near.1.out"].tolist() == [1, 1, 0, 1, 0, 0, 0]
    # 1.1 - 1.0 is a hair above 0.1 in binary floating point
    assert tr["near.2.out"].tolist() == [1, 0, 1, 1, 0, 1, 0]


def test_comp_hysteresis(hal):
    setup(hal, "comp", count=2)
    hal.setp("comp.1.hyst", 1.0)
    d = [0.0, 0.4, 0.6, 0.4, -0.5, -0.6, 0.0]
    tr = run(hal, len(d), {"comp.0.in1": d, "comp.1.in1": d},
             ["comp.0.out", "comp.0.equal", "comp.1.out", "comp.1.equal"])
    # zero hysteresis: exact equality keeps the previous state
    assert tr["comp.0.out"].tolist() == [0, 1, 1, 1, 0, 0, 0]
    assert tr["comp.0.equal"].tolist() == [1, 0, 0, 0, 0, 0, 1]
    assert tr["comp.1.out"].tolist() == [0, 0, 1, 1, 1, 0, 0]
    assert tr["comp.1.equal"].tolist() == [1, 1, 0, 1, 1, 0, 1]


def test_wcomp_edges(hal):
    setup(hal, "wcomp")
    x = [0.0, -1.0, 1.0, 2.0, 0.0]
    tr = run(hal, len(x), {"wcomp.0.in": x,
                           "wcomp.0.min": [-1.0] * 4 + [1.0],
                           "wcomp.0.max": [1.0] * 4 + [-1.0]},
             ["wcomp.0.out", "wcomp.0.under", "wcomp.0.over"])
    assert tr["wcomp.0.out"].tolist() == [1, 0, 0, 0, 0]
    assert tr["wcomp.0.under"].tolist() == [0, 1, 0, 0, 1]
    assert tr["wcomp.0.over"].tolist() == [0, 0, 1, 1, 1]
