"""siggen, encoder, charge_pump and encoder_ratio: behaviour stated in
Python (the byte-for-byte comparisons with the reference are the
tests/data/complib files of the same names)."""

from __future__ import annotations

import numpy as np
import pytest

import halsdk

MS = 1_000_000
#: quadrature states (A, B) in counting-up order
QUAD = [(0, 0), (1, 0), (1, 1), (0, 1)]


def quadrature(positions):
    """A and B arrays for a sequence of positions in counts."""
    a = np.array([QUAD[p % 4][0] for p in positions], dtype=bool)
    b = np.array([QUAD[p % 4][1] for p in positions], dtype=bool)
    return a, b


# ---------------------------------------------------------------- siggen

def siggen_run(hal, cycles, period=MS, **pins):
    hal.loadrt("siggen")
    hal.newthread("t", period)
    hal.addf("siggen.0.update", "t")
    hal.set({f"siggen.0.{k}": v for k, v in pins.items()})
    outs = ["sine", "cosine", "triangle", "sawtooth", "square", "clock"]
    tr = hal.run(cycles, record=[f"siggen.0.{o}" for o in outs])
    return {o: tr[f"siggen.0.{o}"] for o in outs}


def test_siggen_quarter_cycles(hal):
    """At 250 Hz and 1 ms the phase visits 1/4, 1/2, 3/4 and 0."""
    w = siggen_run(hal, 4, frequency=250.0, amplitude=2.0, offset=0.5)
    assert w["sine"] == pytest.approx([2.5, 0.5, -1.5, 0.5], abs=1e-6)
    assert w["cosine"] == pytest.approx([0.5, -1.5, 0.5, 2.5], abs=1e-6)
    assert w["triangle"] == pytest.approx([0.5, -1.5, 0.5, 2.5])
    assert w["sawtooth"] == pytest.approx([-0.5, 0.5, 1.5, -1.5])
    assert w["square"] == pytest.approx([-1.5, -1.5, 2.5, -1.5])
    assert list(w["clock"]) == [False, False, True, False]


def test_siggen_frequency_limited_to_half_sample_rate(hal):
    """Above 1 / (2 * period) the frequency is clamped, and the pin shows
    the clamped value; a negative frequency is not clamped."""
    w = siggen_run(hal, 3, frequency=1500.0)
    assert hal.getp("siggen.0.frequency") == 500.0
    assert w["sawtooth"] == pytest.approx([0.0, -1.0, 0.0])


def test_siggen_negative_frequency_is_not_wrapped(hal):
    w = siggen_run(hal, 10, frequency=-250.0)
    # the phase runs down from 0 without wrapping: sawtooth keeps falling
    assert w["sawtooth"] == pytest.approx(-1.0 - 0.5 * np.arange(1, 11))
    assert hal.getp("siggen.0.frequency") == -250.0


def test_siggen_reset_holds_half_cycle(hal):
    w = siggen_run(hal, 3, frequency=100.0, amplitude=3.0, reset=True)
    assert w["sine"] == pytest.approx([0.0] * 3, abs=1e-6)
    assert w["sawtooth"] == pytest.approx([0.0] * 3)
    assert w["cosine"] == pytest.approx([-3.0] * 3)
    assert w["triangle"] == pytest.approx([-3.0] * 3)
    assert w["square"] == pytest.approx([-3.0] * 3)
    assert not w["clock"].any()


def test_siggen_load_lines(hal):
    assert hal.loadrt("siggen", "num_chan=0") == ["siggen"]
    assert [f.name for f in hal.functions()] == ["siggen.0.update"]
    hal.unloadrt("siggen")
    hal.loadrt("siggen", "names=x,y")
    assert sorted(f.name for f in hal.functions()) == ["x.update",
                                                       "y.update"]
    hal.unloadrt("siggen")
    for bad in ("num_chan=17", "num_chan=-1", "num_chan=1 names=a"):
        with pytest.raises(halsdk.HalError):
            hal.loadrt("siggen", bad)
        assert hal.components("siggen") == []


# ----------------------------------------------------------- charge_pump

def test_charge_pump_counts_in_binary_and_holds_when_disabled(hal):
    hal.loadrt("charge_pump")
    hal.newthread("t", 100_000)
    hal.addf("charge-pump", "t")
    enable = [True] * 9 + [False] * 2 + [True] * 2
    tr = hal.run(13, inputs={"charge-pump.enable": enable},
                 record=["charge-pump.out", "charge-pump.out-2",
                         "charge-pump.out-4"])
    value = (tr["charge-pump.out"].astype(int)
             + 2 * tr["charge-pump.out-2"] + 4 * tr["charge-pump.out-4"])
    assert list(value) == [1, 2, 3, 4, 5, 6, 7, 0, 1, 0, 0, 2, 3]


def test_charge_pump_is_a_singleton(hal):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("charge_pump", "count=2")
    assert hal.components("charge_pump") == []


# --------------------------------------------------------------- encoder

def encoder_setup(hal, period=50_000, capture_period=None, **pins):
    hal.loadrt("encoder", "num_chan=1")
    hal.newthread("fast", period)
    hal.addf("encoder.update-counters", "fast")
    if capture_period:
        hal.newthread("slow", capture_period)
        hal.addf("encoder.capture-position", "slow")
    else:
        hal.addf("encoder.capture-position", "fast")
    hal.set({f"encoder.0.{k}": v for k, v in pins.items()})


def encoder_run(hal, positions, record=("counts",), **inputs):
    a, b = quadrature(positions)
    ins = {"encoder.0.phase-A": a, "encoder.0.phase-B": b}
    ins.update({f"encoder.0.{k}": v for k, v in inputs.items()})
    tr = hal.run(len(positions), inputs=ins,
                 record=[f"encoder.0.{r}" for r in record])
    return {r: tr[f"encoder.0.{r}"] for r in record}


def test_encoder_x4_counts_every_edge(hal):
    encoder_setup(hal)
    pos = list(range(9)) + list(range(7, -5, -1))
    got = encoder_run(hal, pos)["counts"]
    assert list(got) == pos


def test_encoder_x1_counts_once_a_cycle_without_creeping(hal):
    encoder_setup(hal, **{"x4-mode": False})
    pos = list(range(13)) + list(range(11, -1, -1))
    got = encoder_run(hal, pos)["counts"]
    # up on 00 -> A (positions 1, 5, 9), down on A -> 00 (back to 8, 4, 0)
    assert list(got[:13]) == [0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3]
    assert list(got[13:]) == [3, 3, 3, 2, 2, 2, 2, 1, 1, 1, 1, 0]
    # a jittering edge goes up and back down again
    got = encoder_run(hal, [1, 0, 1, 0, 1, 0])["counts"]
    assert list(got) == [1, 0, 1, 0, 1, 0]


def test_encoder_counter_mode_counts_rising_a_only(hal):
    encoder_setup(hal, **{"counter-mode": True})
    a = np.array([0, 1, 1, 0, 1, 0, 0, 1, 0, 1], dtype=bool)
    b = np.array([0, 1, 0, 1, 1, 0, 1, 0, 1, 1], dtype=bool)
    tr = hal.run(10, inputs={"encoder.0.phase-A": a, "encoder.0.phase-B": b},
                 record=["encoder.0.counts"])
    assert list(tr["encoder.0.counts"]) == [0, 1, 1, 1, 2, 2, 2, 3, 3, 4]


def test_encoder_velocity_with_capture_in_a_slower_thread(hal):
    """One count every 4 fast periods (5000 counts/s) at 100 counts a
    unit is 50 units/s; counts and position follow the slow thread, raw
    counts the fast one."""
    encoder_setup(hal, capture_period=MS, **{"position-scale": 100.0})
    pos = [k // 4 for k in range(400)]
    got = encoder_run(hal, pos, record=("rawcounts", "counts", "position",
                                        "velocity", "velocity-rpm"))
    assert list(got["rawcounts"]) == pos
    # counts and position change only when the slow thread runs
    steps = np.nonzero(np.diff(got["counts"]))[0]
    assert len(steps) > 10 and np.all(np.diff(steps) == 20)
    assert got["position"][-1] == pytest.approx(got["counts"][-1] / 100.0)
    assert got["velocity"][-1] == pytest.approx(50.0)
    assert got["velocity-rpm"][-1] == pytest.approx(3000.0)


def test_encoder_velocity_decays_then_times_out(hal):
    encoder_setup(hal, **{"min-speed-estimate": 200.0})
    pos = [k // 2 for k in range(40)] + [19] * 150
    got = encoder_run(hal, pos, record=("velocity",))["velocity"]
    assert got[39] == pytest.approx(10000.0)
    # falls as 1 / (time since the last count) ...
    assert got[79] == pytest.approx(1.0 / (42 * 50e-6))
    assert np.all(np.diff(got[40:130]) <= 0)
    # ... and is 0 once that is 100 periods (1 / 200 s)
    assert got[-1] == 0.0


def test_encoder_index_enable(hal):
    encoder_setup(hal, **{"index-enable": True})
    pos = list(range(30))
    z = np.array([p == 10 for p in pos])
    got = encoder_run(hal, pos, record=("counts", "rawcounts",
                                        "index-enable"), **{"phase-Z": z})
    assert list(got["index-enable"][:10]) == [True] * 10
    assert not got["index-enable"][10:].any()
    assert got["counts"][10] == 0 and got["counts"][-1] == 19
    assert got["rawcounts"][-1] == 29


def test_encoder_latch_and_reset(hal):
    encoder_setup(hal, **{"latch-falling": False, "position-scale": 4.0})
    pos = list(range(40))
    latch = np.array([10 <= k < 20 or 30 <= k for k in range(40)])
    reset = np.array([k == 35 for k in range(40)])
    got = encoder_run(hal, pos, record=("counts-latched", "position-latched",
                                        "counts"),
                      **{"latch-input": latch, "reset": reset})
    assert got["counts-latched"][25] == 10      # rising edge only
    assert got["position-latched"][25] == pytest.approx(2.5)
    assert got["counts-latched"][32] == 30
    # reset zeroes counts and the latched values; counting goes on from 0
    assert got["counts"][35] == 0 and got["counts-latched"][35] == 0
    assert got["counts"][39] == 4


def test_encoder_zero_scale_is_replaced_by_one(hal):
    encoder_setup(hal, **{"position-scale": 0.0})
    got = encoder_run(hal, list(range(5)), record=("position",))
    assert hal.getp("encoder.0.position-scale") == 1.0
    assert got["position"][-1] == 4.0


def test_encoder_functions_and_errors(hal):
    hal.loadrt("encoder", "names=sp,x")
    assert sorted(f.name for f in hal.functions()) == [
        "encoder.capture-position", "encoder.update-counters"]
    assert hal.getp("sp.x4-mode") is True or hal.getp("sp.x4-mode") == 1
    hal.unloadrt("encoder")
    assert hal.loadrt("encoder") == ["encoder"]
    assert len(hal.pins("encoder.*.counts")) == 3
    hal.unloadrt("encoder")
    for bad in ("num_chan=9", "num_chan=2 names=a,b"):
        with pytest.raises(halsdk.HalError):
            hal.loadrt("encoder", bad)
        assert hal.components("encoder") == []


# --------------------------------------------------------- encoder_ratio

def test_encoder_ratio(hal):
    hal.loadrt("encoder_ratio")
    hal.newthread("t", MS)
    hal.addf("encoder-ratio.sample", "t")
    hal.addf("encoder-ratio.update", "t")
    hal.set({"encoder-ratio.0.master-ppr": 100, "encoder-ratio.0.slave-ppr": 40,
             "encoder-ratio.0.master-teeth": 2,
             "encoder-ratio.0.slave-teeth": 1})
    n = 80
    ma, mb = quadrature([k // 2 for k in range(n)])
    sa, sb = quadrature([k // 4 for k in range(n)])
    ins = {"encoder-ratio.0.master-A": ma, "encoder-ratio.0.master-B": mb,
           "encoder-ratio.0.slave-A": sa, "encoder-ratio.0.slave-B": sb}
    tr = hal.run(n, inputs=ins, record=["encoder-ratio.0.error"])
    # disabled: the slave position in revolutions (19 counts of 40)
    assert tr["encoder-ratio.0.error"][-1] == pytest.approx(19 / 40)
    hal.set({"encoder-ratio.0.enable": True})
    # enabled: 40 master counts (0.4 rev) want 0.8 slave rev; the slave
    # moved 20 counts (0.5 rev): error 0.5 - 0.8 behind the start
    ma, mb = quadrature([39 + k // 2 for k in range(1, n + 1)])
    sa, sb = quadrature([19 + k // 4 for k in range(1, n + 1)])
    ins = {"encoder-ratio.0.master-A": ma, "encoder-ratio.0.master-B": mb,
           "encoder-ratio.0.slave-A": sa, "encoder-ratio.0.slave-B": sb}
    tr = hal.run(n, inputs=ins, record=["encoder-ratio.0.error"])
    assert tr["encoder-ratio.0.error"][-1] == pytest.approx(
        39 / 40 - 40 * 2 / 100)


def test_encoder_ratio_zero_ppr_gives_zero_error(hal):
    hal.loadrt("encoder_ratio", "names=g")
    hal.newthread("t", MS)
    hal.addf("encoder-ratio.sample", "t")
    hal.addf("encoder-ratio.update", "t")
    sa, sb = quadrature(list(range(10)))
    tr = hal.run(10, inputs={"g.slave-A": sa, "g.slave-B": sb},
                 record=["g.error"])
    assert not tr["g.error"].any()


def tooth_train(intervals, lead=10):
    """phase-A for teeth one period wide; intervals[k] periods from tooth k
    to tooth k + 1 (the first tooth comes after lead periods)."""
    a = [0] * lead
    for n in intervals:
        a += [1] + [0] * (n - 1)
    return np.array(a, dtype=bool)


def tooth_counts(hal, a, **pins):
    """count added by each tooth (rising edge of phase-A)."""
    encoder_setup(hal, **{"counter-mode": True, **pins})
    tr = hal.run(len(a), inputs={"encoder.0.phase-A": a},
                 record=["encoder.0.rawcounts", "encoder.0.counts",
                         "encoder.0.index-enable"])
    raw = tr["encoder.0.rawcounts"]
    rises = np.flatnonzero(a & ~np.concatenate(([False], a[:-1])))
    steps = [int(raw[k] - (raw[k - 1] if k else 0)) for k in rises]
    return steps, tr


def test_encoder_missing_teeth_first_teeth_all_count_as_the_gap(hal):
    # the limit starts at zero, so until it has been learnt every tooth
    # counts missing-teeth + 1
    steps, _ = tooth_counts(hal, tooth_train([6] * 8), **{"missing-teeth": 2})
    assert steps == [3] * 8


def test_encoder_missing_teeth_locks_on_a_toothed_wheel(hal):
    # 12-tooth wheel with 2 teeth missing: 9 intervals of 6 periods and a
    # gap of 18; after about three turns only the tooth after the gap
    # counts 3
    wheel = [6] * 9 + [18]
    steps, _ = tooth_counts(hal, tooth_train(wheel * 6), **{"missing-teeth": 2})
    assert steps[:30] == [3] * 30
    assert steps[-20:] == ([3] + [1] * 9) * 2
    assert sum(steps[-10:]) == 12     # one turn counts all 12 teeth


def test_encoder_missing_teeth_limit_is_missing_teeth_and_a_half_teeth(hal):
    # once locked on teeth 4 periods apart, with missing-teeth 1 an
    # interval of 6 (1.5 teeth) is a gap, one of 5 is not
    head = [6] * 30 + [4] * 10
    steps, _ = tooth_counts(hal, tooth_train(head + [5] + [4] * 3),
                            **{"missing-teeth": 1})
    assert steps[31:41] == [1] * 10
    assert steps[41] == 1


def test_encoder_missing_teeth_long_interval_after_lock_is_a_gap(hal):
    head = [6] * 30 + [4] * 10
    steps, _ = tooth_counts(hal, tooth_train(head + [6] + [4] * 3),
                            **{"missing-teeth": 1})
    assert steps[31:41] == [1] * 10
    assert steps[41] == 2
    assert steps[42] == 1


def test_encoder_missing_teeth_gap_is_the_index(hal):
    # with index-enable set the first gap makes the tooth after it zero
    a = tooth_train([6] * 4)
    steps, tr = tooth_counts(hal, a, **{"missing-teeth": 2,
                                        "index-enable": True})
    first = int(np.flatnonzero(a)[0])
    assert tr["encoder.0.rawcounts"][first] == 3
    assert tr["encoder.0.counts"][first] == 0
    assert not tr["encoder.0.index-enable"][first]
    assert tr["encoder.0.counts"][-1] == 9


def test_encoder_missing_teeth_zero_counts_each_tooth_once(hal):
    steps, tr = tooth_counts(hal, tooth_train([6] * 5 + [18] + [6] * 4),
                             **{"index-enable": True})
    assert steps == [1] * 10
    assert tr["encoder.0.index-enable"][-1]
