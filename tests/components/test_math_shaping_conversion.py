"""Math components, second group: deadzone, minmax, sample_hold, offset,
weighted_sum, scaled_s32_sums, lincurve, updown, blend, knob2float,
constant, clarke2/3, clarkeinv, modmath, counter and the conv_* family.

The reference's exact outputs are checked by tests/data/complib/*.hal; these
tests state the rules in Python."""

from __future__ import annotations

import math

import numpy as np
import pytest

import halsdk

MS = 1_000_000
SQRT3 = math.sqrt(3.0)


def thread(hal, *functs, period=MS):
    hal.newthread("t", period, fp=True)
    for f in functs:
        hal.addf(f, "t")


def test_deadzone_removes_the_band_around_center(hal):
    hal.loadrt("deadzone")
    thread(hal, "deadzone.0")
    hal.setp("deadzone.0.center", 1.0)
    hal.setp("deadzone.0.threshold", 2.0)
    ins = [1.0, 1.5, 2.0, 3.0, 0.0, -2.0]
    tr = hal.run(len(ins), inputs={"deadzone.0.in": ins},
                 record=["deadzone.0.out"])
    assert tr["deadzone.0.out"].tolist() == pytest.approx(
        [1.0, 1.0, 1.0, 2.0, 1.0, -1.0])


def test_minmax_tracks_extremes_until_reset(hal):
    hal.loadrt("minmax")
    thread(hal, "minmax.0")
    tr = hal.run(6, inputs={"minmax.0.in": [3.0, -1.0, 5.0, 2.0, 2.0, 4.0],
                            "minmax.0.reset": [0, 0, 0, 0, 1, 0]},
                 record=["minmax.0.min", "minmax.0.max"])
    assert tr["minmax.0.max"][3] == 5.0
    assert tr["minmax.0.min"][3] == -1.0
    assert tr["minmax.0.min"][4] == tr["minmax.0.max"][4] == 2.0
    assert (tr["minmax.0.min"][5], tr["minmax.0.max"][5]) == (2.0, 4.0)


def test_sample_hold_freezes_while_hold(hal):
    hal.loadrt("sample_hold")
    thread(hal, "sample-hold.0")
    tr = hal.run(5, inputs={"sample-hold.0.in": [1, 2, 3, 4, -5],
                            "sample-hold.0.hold": [0, 1, 1, 0, 0]},
                 record=["sample-hold.0.out"])
    assert tr["sample-hold.0.out"].tolist() == [1, 1, 1, 4, -5]


def test_offset_adds_to_output_and_removes_from_feedback(hal):
    hal.loadrt("offset")
    thread(hal, "offset.0.update-output", "offset.0.update-feedback")
    hal.set({"offset.0.in": 2.5, "offset.0.fb-in": 10.0,
             "offset.0.offset": -1.25})
    hal.step(1)
    assert hal.getp("offset.0.out") == 1.25
    assert hal.getp("offset.0.fb-out") == 11.25


def test_weighted_sum_binary_weights_offset_and_hold(hal):
    hal.loadrt("weighted_sum", "wsum_sizes=3")
    thread(hal, "process_wsums")
    for n in range(8):
        hal.set({f"wsum.0.bit.{k}.in": bool(n >> k & 1) for k in range(3)})
        hal.step(1)
        assert hal.getp("wsum.0.sum") == n
    hal.set({"wsum.0.offset": 100, "wsum.0.bit.2.weight": -4,
             "wsum.0.hold": True})
    hal.step(1)
    assert hal.getp("wsum.0.sum") == 7
    hal.set({"wsum.0.hold": False})
    hal.step(1)
    assert hal.getp("wsum.0.sum") == 100 + 1 + 2 - 4


def test_weighted_sum_refuses_no_summers(hal):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("weighted_sum", "wsum_sizes=0")
    assert hal.components("weighted_sum") == []


def test_scaled_s32_sums_float_and_integer_sum(hal):
    hal.loadrt("scaled_s32_sums")
    thread(hal, "scaled-s32-sums.0")
    p = "scaled-s32-sums.0."
    hal.set({p + "in0": 3, p + "scale0": 0.5, p + "in1": -2,
             p + "scale1": 2.0, p + "in2": 7, p + "in3": 1})
    hal.step(1)
    assert hal.getp(p + "out-f") == pytest.approx(1.5 - 4.0 + 7 + 1)
    assert hal.getp(p + "out-s") == int(hal.getp(p + "out-f"))


def test_lincurve_interpolates_and_clamps(hal):
    hal.loadrt("lincurve", "personality=3")
    thread(hal, "lincurve.0")
    for k, (x, y) in enumerate([(0.0, 0.0), (1.0, 10.0), (3.0, 0.0)]):
        hal.setp(f"lincurve.0.x-val-{k:02d}", x)
        hal.setp(f"lincurve.0.y-val-{k:02d}", y)
    ins = [-5.0, 0.5, 1.0, 2.0, 2.5, 9.0]
    tr = hal.run(len(ins), inputs={"lincurve.0.in": ins},
                 record=["lincurve.0.out"])
    assert tr["lincurve.0.out"].tolist() == pytest.approx(
        [0.0, 5.0, 10.0, 5.0, 2.5, 0.0])


def test_updown_counts_edges_and_clamps(hal):
    hal.loadrt("updown")
    thread(hal, "updown.0")
    hal.setp("updown.0.clamp", True)
    hal.setp("updown.0.min", -1)
    hal.setp("updown.0.max", 2)
    up = [0, 1, 0, 1, 1, 0, 1, 0, 1, 0, 0, 0, 0]
    dn = [0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 1, 0]
    tr = hal.run(len(up), inputs={"updown.0.countup": up,
                                  "updown.0.countdown": dn},
                 record=["updown.0.count"])
    # a held level counts once; the count stops at max
    assert tr["updown.0.count"].tolist() == [0, 1, 1, 2, 2, 2, 2, 2, 2, 1,
                                             1, 0, 0]
    hal.set({"updown.0.reset": True})
    hal.step(1)
    assert hal.getp("updown.0.count") == 0


def test_blend_mixes_and_limits_select_unless_open(hal):
    hal.loadrt("blend", "count=2")
    thread(hal, "blend.0", "blend.1")
    hal.setp("blend.1.open", True)
    for n in (0, 1):
        hal.set({f"blend.{n}.in1": 10.0, f"blend.{n}.in2": 2.0})
    hal.set({"blend.0.select": 0.25, "blend.1.select": 0.25})
    hal.step(1)
    assert hal.getp("blend.0.out") == pytest.approx(4.0)
    hal.set({"blend.0.select": 2.0, "blend.1.select": 2.0})
    hal.step(1)
    assert hal.getp("blend.0.out") == pytest.approx(10.0)
    assert hal.getp("blend.1.out") == pytest.approx(18.0)


def test_knob2float_accumulates_scaled_counts_within_limits(hal):
    hal.loadrt("knob2float")
    thread(hal, "knob2float.0")
    hal.setp("knob2float.0.max-out", 2.0)
    hal.set({"knob2float.0.scale": 0.25, "knob2float.0.enable": True})
    tr = hal.run(5, inputs={"knob2float.0.counts": [0, 2, 6, 20, 14]},
                 record=["knob2float.0.out"])
    assert tr["knob2float.0.out"].tolist() == pytest.approx(
        [0.0, 0.5, 1.5, 2.0, 0.5])


def test_constant_drives_its_value(hal):
    hal.loadrt("constant")
    thread(hal, "constant.0")
    hal.setp("constant.0.value", -3.5)
    hal.step(1)
    assert hal.getp("constant.0.out") == -3.5


def test_clarke3_then_clarkeinv_round_trip(hal):
    hal.loadrt("clarke3")
    hal.loadrt("clarkeinv")
    hal.loadrt("clarke2")
    thread(hal, "clarke3.0", "clarkeinv.0", "clarke2.0")
    for sig, src, dst in (("x", "clarke3.0.x", "clarkeinv.0.x"),
                          ("y", "clarke3.0.y", "clarkeinv.0.y"),
                          ("h", "clarke3.0.h", "clarkeinv.0.h")):
        hal.net(sig, src, dst)
    a, b, c = 1.0, -0.3, 0.5
    hal.set({"clarke3.0.a": a, "clarke3.0.b": b, "clarke3.0.c": c,
             "clarke2.0.a": a, "clarke2.0.b": b})
    hal.step(1)
    assert hal.getp("clarke3.0.x") == pytest.approx((2 * a - b - c) / 3)
    assert hal.getp("clarke3.0.y") == pytest.approx((b - c) / SQRT3)
    assert hal.getp("clarke3.0.h") == pytest.approx(
        (a + b + c) * math.sqrt(2.0) / 3)
    assert [hal.getp(f"clarkeinv.0.{p}") for p in "abc"] == pytest.approx(
        [a, b, c])
    # two phases of a balanced three-phase system
    assert hal.getp("clarke2.0.x") == pytest.approx(a)
    assert hal.getp("clarke2.0.y") == pytest.approx((a + 2 * b) / SQRT3)


CONV = [
    # name, inputs, outputs with clamp off (None: not stated)
    ("conv_bit_float", [0, 1], [0.0, 1.0]),
    ("conv_bit_s32", [0, 1], [0, 1]),
    ("conv_bit_u32", [0, 1], [0, 1]),
    ("conv_s32_float", [-7, 2**31 - 1], [-7.0, 2**31 - 1.0]),
    ("conv_u32_float", [0, 2**32 - 1], [0.0, 2**32 - 1.0]),
    ("conv_s32_bit", [0, 1, 2, -1], [0, 1, 1, 1]),
    ("conv_u32_bit", [0, 1, 5], [0, 1, 1]),
    ("conv_s32_u32", [5, -1], [5, 2**32 - 1]),
    ("conv_u32_s32", [5, 2**31], [5, -2**31]),
    ("conv_float_s32", [2.7, -2.7, 1e10], [2, -2, None]),
    ("conv_float_u32", [2.7, 0.2], [2, 0]),
]


@pytest.mark.parametrize("name,ins,outs", CONV, ids=[c[0] for c in CONV])
def test_conv_converts(hal, name, ins, outs):
    hal.loadrt(name)
    p = name.replace("_", "-") + ".0"
    thread(hal, p)
    tr = hal.run(len(ins), inputs={p + ".in": ins}, record=[p + ".out"])
    for k, want in enumerate(outs):
        if want is not None:
            assert tr[p + ".out"][k] == want, ins[k]


CLAMPED = [
    # name, inputs, clamped outputs, out-of-range
    ("conv_s32_bit", [0, 1, 2, -1], [0, 1, 1, 0], [0, 0, 1, 1]),
    ("conv_u32_bit", [0, 1, 5], [0, 1, 1], [0, 0, 1]),
    ("conv_s32_u32", [5, -5], [5, 0], [0, 1]),
    ("conv_u32_s32", [5, 2**32 - 1], [5, 2**31 - 1], [0, 1]),
    ("conv_float_s32", [2.7, -2.7, 1e10, -1e10],
     [2, -2, 2**31 - 1, -2**31], [0, 0, 1, 1]),
    ("conv_float_u32", [2.7, -1.0], [2, 0], [0, 1]),
]


@pytest.mark.parametrize("name,ins,outs,oor", CLAMPED,
                         ids=[c[0] for c in CLAMPED])
def test_conv_clamp_limits_and_flags(hal, name, ins, outs, oor):
    hal.loadrt(name)
    p = name.replace("_", "-") + ".0"
    thread(hal, p)
    hal.setp(p + ".clamp", True)
    tr = hal.run(len(ins), inputs={p + ".in": ins},
                 record=[p + ".out", p + ".out-of-range"])
    assert tr[p + ".out"].tolist() == outs
    assert tr[p + ".out-of-range"].tolist() == [bool(v) for v in oor]


# ---- modmath ---------------------------------------------------------------

def test_modmath_makes_mod_dir_instances(hal):
    hal.loadrt("modmath", "mod_dir=2")
    assert sorted(f.name for f in hal.functions()) == ["mod-dir.0",
                                                        "mod-dir.1"]
    assert hal.getp("mod-dir.1.max-num") == 15
    assert hal.getp("mod-dir.1.wrap") is True


def test_modmath_without_mod_dir_makes_nothing(hal):
    hal.loadrt("modmath")
    assert hal.components("modmath")
    assert hal.pins() == [] and hal.functions() == []


def _direction(actual, desired, lo, hi, wrap):
    # the reference's rule: each position reduced to the range on its own
    # (C's remainder, counted from min-num), the difference then turned
    # at most once by a whole range
    m = hi - lo + 1
    d = int(math.fmod(desired - lo, m)) - int(math.fmod(actual - lo, m))
    if wrap and d > m // 2:
        d -= m
    elif wrap and d < -(m // 2):
        d += m
    return (d > 0, d < 0, d == 0)


@pytest.mark.parametrize("wrap", [True, False])
def test_modmath_picks_the_shorter_way(hal, wrap):
    hal.loadrt("modmath", "mod_dir=1")
    thread(hal, "mod-dir.0")
    hal.set({"mod-dir.0.min-num": 1, "mod-dir.0.max-num": 8,
             "mod-dir.0.wrap": wrap})
    rng = np.random.default_rng(5)
    acts = rng.integers(-3, 12, 60)
    dess = rng.integers(-3, 12, 60)
    p = "mod-dir.0."
    tr = hal.run(60, inputs={p + "actual": acts, p + "desired": dess},
                 record=[p + "up", p + "down", p + "on-target"])
    for k in range(60):
        want = _direction(int(acts[k]), int(dess[k]), 1, 8, wrap)
        got = (tr[p + "up"][k], tr[p + "down"][k], tr[p + "on-target"][k])
        assert got == want, (acts[k], dess[k])
    # from pocket 7 to pocket 2 of 8 the short way is up through 8 and 1
    hal.set({p + "actual": 7, p + "desired": 2})
    hal.step(1)
    assert hal.getp(p + "up") is wrap
    assert hal.getp(p + "down") is not wrap


# ---- counter ---------------------------------------------------------------

def counter_thread(hal, period=MS):
    thread(hal, "counter.update-counters", "counter.capture-position",
           period=period)


def test_counter_counts_rising_edges_and_velocity(hal):
    hal.loadrt("counter", "num_chan=2")
    counter_thread(hal)
    hal.setp("counter.1.position-scale", 4.0)
    a = [1, 1, 0, 1, 0, 0, 1, 0]
    rec = ["counter.0.counts", "counter.0.velocity", "counter.1.position",
           "counter.1.velocity"]
    tr = hal.run(len(a), inputs={"counter.0.phase-A": a,
                                 "counter.1.phase-A": a}, record=rec)
    assert tr["counter.0.counts"].tolist() == [1, 1, 1, 2, 2, 2, 3, 3]
    assert tr["counter.0.velocity"].tolist() == [1000.0, 0, 0, 1000.0, 0,
                                                 0, 1000.0, 0]
    assert tr["counter.1.position"][-1] == 0.75
    assert tr["counter.1.velocity"][0] == 250.0


def test_counter_index_zeroes_counts_not_rawcounts(hal):
    hal.loadrt("counter")
    counter_thread(hal)
    a = [1, 0, 1, 0, 1, 0, 1, 0]
    z = [0, 0, 0, 1, 1, 0, 0, 1]
    hal.setp("counter.0.index-enable", True)
    tr = hal.run(len(a), inputs={"counter.0.phase-A": a,
                                 "counter.0.phase-Z": z},
                 record=["counter.0.counts", "counter.0.rawcounts",
                         "counter.0.index-enable", "counter.0.velocity"])
    assert tr["counter.0.rawcounts"].tolist() == [1, 1, 2, 2, 3, 3, 4, 4]
    assert tr["counter.0.counts"].tolist() == [1, 1, 2, 0, 1, 1, 2, 2]
    assert tr["counter.0.index-enable"].tolist() == [True] * 3 + [False] * 5
    # the velocity follows rawcounts: no jump at the index
    assert tr["counter.0.velocity"][3] == 0.0


def test_counter_reset_holds_everything_at_zero(hal):
    hal.loadrt("counter")
    counter_thread(hal)
    a = [1, 0, 1, 0, 1, 0, 1]
    r = [0, 0, 0, 1, 1, 0, 0]
    tr = hal.run(len(a), inputs={"counter.0.phase-A": a,
                                 "counter.0.reset": r},
                 record=["counter.0.counts", "counter.0.rawcounts",
                         "counter.0.velocity"])
    assert tr["counter.0.rawcounts"].tolist() == [1, 1, 2, 0, 0, 0, 1]
    assert tr["counter.0.counts"].tolist() == [1, 1, 2, 0, 0, 0, 1]
    assert tr["counter.0.velocity"][3] == 0.0


def test_counter_replaces_a_zero_scale_by_one(hal):
    hal.loadrt("counter")
    counter_thread(hal)
    hal.setp("counter.0.position-scale", 1e-21)
    hal.set({"counter.0.phase-A": True})
    hal.step(1)
    assert hal.getp("counter.0.position-scale") == 1.0
    assert hal.getp("counter.0.position") == 1.0


@pytest.mark.parametrize("arg", ["num_chan=0", "num_chan=9", "count=2"])
def test_counter_refuses_bad_load_lines(hal, arg):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("counter", arg)
    assert hal.components("counter") == []
