"""Unit tests of the shipped components differential, filter_kalman and
histobins: behaviour stated in Python, with numbers observed on the LinuxCNC
2.9 reference (the differential tests in tests/data/complib compare whole
runs)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.components import setup

import halsdk
from halsdk.core import _core

PERIOD = 1_000_000


# differential ------------------------------------------------------------

def test_differential_motor_commands_and_feedback(hal):
    setup(hal, "differential", "differential.0")
    hal.set({"differential.0.roll-cmd": 10.0,
             "differential.0.pitch-cmd": 3.0,
             "differential.0.motor0-fb": 5.0,
             "differential.0.motor1-fb": 1.0})
    hal.step(1)
    assert hal.getp("differential.0.motor0-cmd") == 13.0
    assert hal.getp("differential.0.motor1-cmd") == 7.0
    assert hal.getp("differential.0.roll-fb") == 3.0
    assert hal.getp("differential.0.pitch-fb") == 2.0


def test_differential_feedback_inverts_command(hal):
    """Feeding the motor commands back gives the roll and pitch commands."""
    setup(hal, "differential", "differential.0")
    hal.net("m0", "differential.0.motor0-cmd", "differential.0.motor0-fb")
    hal.net("m1", "differential.0.motor1-cmd", "differential.0.motor1-fb")
    roll = np.array([0.0, 12.5, -30.0, 90.0])
    pitch = np.array([0.0, -2.25, 45.0, 90.0])
    tr = hal.run(4, inputs={"differential.0.roll-cmd": roll,
                            "differential.0.pitch-cmd": pitch},
                 record=["differential.0.roll-fb", "differential.0.pitch-fb"])
    # the commands are computed first, so the loop closes in one cycle
    assert list(tr["differential.0.roll-fb"]) == list(roll)
    assert list(tr["differential.0.pitch-fb"]) == list(pitch)


def test_differential_interface(hal):
    hal.loadrt("differential", "names=wrist")
    pins = {(p.name, p.type, p.direction) for p in hal.pins("wrist.*")}
    assert ("wrist.roll-cmd", _core.FLOAT, _core.IN) in pins
    assert ("wrist.motor1-cmd", _core.FLOAT, _core.OUT) in pins
    assert ("wrist.pitch-fb", _core.FLOAT, _core.OUT) in pins
    [f] = hal.functions()
    assert f.name == "wrist" and f.uses_fp is True


# filter_kalman -----------------------------------------------------------

def kalman_model(zs, rk, qk):
    """The filter as observed on the reference: single-precision state,
    one cycle in double."""
    x, p, out = np.float32(0), np.float32(1), []
    for z in zs:
        pred = float(p) + qk
        gain = pred / (pred + rk)
        o = float(x) + gain * (z - float(x))
        x, p = np.float32(o), np.float32((1.0 - gain) * pred)
        out.append(o)
    return out


def test_filter_kalman_names_and_defaults(hal):
    assert hal.loadrt("filter_kalman", "count=2") == ["filter_kalman"]
    names = [p.name for p in hal.pins()]
    assert "filter-kalman.1.xk-out" in names
    assert hal.getp("filter-kalman.0.Rk") == pytest.approx(1.17549e-38)
    assert hal.getp("filter-kalman.0.Qk") == pytest.approx(1.17549e-38)
    assert [f.name for f in hal.functions()] == ["filter-kalman.0",
                                                  "filter-kalman.1"]


def test_filter_kalman_first_steps(hal):
    """With Rk = Qk = 1 the gain starts at 2/3 then 5/8."""
    setup(hal, "filter_kalman", "filter-kalman.0")
    hal.set({"filter-kalman.0.Rk": 1.0, "filter-kalman.0.Qk": 1.0})
    tr = hal.run(2, inputs={"filter-kalman.0.zk": 10.0},
                 record=["filter-kalman.0.xk-out"])
    assert tr["filter-kalman.0.xk-out"][0] == pytest.approx(20 / 3)
    assert tr["filter-kalman.0.xk-out"][1] == pytest.approx(8.75)


def test_filter_kalman_matches_model_exactly(hal):
    rng = np.random.default_rng(5)
    zs = 20.0 + rng.normal(0.0, 0.3, 200)
    setup(hal, "filter_kalman", "filter-kalman.0")
    hal.set({"filter-kalman.0.Rk": 0.09, "filter-kalman.0.Qk": 1e-4})
    tr = hal.run(200, inputs={"filter-kalman.0.zk": zs},
                 record=["filter-kalman.0.xk-out"])
    assert list(tr["filter-kalman.0.xk-out"]) == kalman_model(zs, 0.09, 1e-4)
    # and it smooths: the tail is much less noisy than the input
    assert np.std(tr["filter-kalman.0.xk-out"][100:]) < np.std(zs) / 3


def test_filter_kalman_passthrough_keeps_state_reset_clears_it(hal):
    setup(hal, "filter_kalman", "filter-kalman.0")
    hal.set({"filter-kalman.0.Rk": 1.0, "filter-kalman.0.Qk": 1.0})
    z = [10.0, 10.0, -4.0, 0.0, 0.0, 1.0]
    pt = [False, False, True, False, False, False]
    rs = [False, False, False, False, True, False]
    tr = hal.run(6, inputs={"filter-kalman.0.zk": z,
                            "filter-kalman.0.passthrough": pt,
                            "filter-kalman.0.reset": rs},
                 record=["filter-kalman.0.xk-out"])
    out = tr["filter-kalman.0.xk-out"]
    assert out[2] == -4.0                       # passthrough
    # the filter resumes from 8.75 as if the passthrough cycle was not there
    assert out[3] == pytest.approx(kalman_model([10.0, 10.0, 0.0], 1, 1)[2])
    assert out[4] == 0.0                        # reset
    assert out[5] == pytest.approx(2 / 3)       # starts afresh


def test_filter_kalman_reset_wins_over_passthrough(hal):
    setup(hal, "filter_kalman", "filter-kalman.0")
    hal.set({"filter-kalman.0.zk": 7.0, "filter-kalman.0.reset": True,
             "filter-kalman.0.passthrough": True})
    hal.step(1)
    assert hal.getp("filter-kalman.0.xk-out") == 0.0


def test_filter_kalman_debug_prints(hal, capfd):
    setup(hal, "filter_kalman", "filter-kalman.0")
    hal.set({"filter-kalman.0.zk": 2.5, "filter-kalman.0.debug": True})
    hal.step(1)
    assert "filter-kalman.0 2.500000 2.500000" in capfd.readouterr().err


def test_filter_kalman_refuses_count_and_names(hal):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("filter_kalman", "count=1", "names=a")
    assert hal.pins() == []


# histobins ---------------------------------------------------------------

def histo(hal, **pins):
    setup(hal, "histobins", "histobins.0")
    hal.set({f"histobins.0.{k.replace('_', '-')}": v
             for k, v in pins.items()})


def bin_counts(hal, nbins):
    counts = []
    for i in range(nbins):
        hal.set({"histobins.0.index": i, "histobins.0.input": -1e9})
        hal.step(1)
        assert hal.getp("histobins.0.check") == i
        counts.append(hal.getp("histobins.0.binvalue"))
    return counts


def test_histobins_counts_bins_and_extras(hal):
    histo(hal, nbins=4, binsize=0.5, minvalue=1.0)
    values = [9.0, 1.0, 1.2, 1.5, 2.49, 2.5, 3.0, 3.1, 0.99]
    hal.run(len(values), inputs={"histobins.0.input": values})
    # the first sample only starts the histogram; 3.0 (the upper edge)
    # goes into no visible bin
    assert bin_counts(hal, 4) == [2.0, 1.0, 1.0, 1.0]
    assert hal.getp("histobins.0.pextra") == 1.0      # 3.1
    # 0.99 plus the -1e9 fed while reading 4 bins
    assert hal.getp("histobins.0.nextra") == 5.0
    assert hal.getp("histobins.0.input-error") is False


def test_histobins_statistics_welford_and_sums(hal):
    histo(hal, nbins=10)
    xs = [7.0, 2.0, 3.0, 4.0, 5.0]
    tr = hal.run(5, inputs={"histobins.0.input": xs},
                 record=["histobins.0.mean", "histobins.0.variance",
                         "histobins.0.nsamples", "histobins.0.input-min",
                         "histobins.0.input-max"])
    # the first sample counts as 0 in mean and variance
    seen = [0.0] + xs[1:]
    assert tr["histobins.0.mean"][-1] == pytest.approx(np.mean(seen))
    assert tr["histobins.0.variance"][-1] == pytest.approx(
        np.var(seen, ddof=1))
    assert list(tr["histobins.0.nsamples"]) == [1, 2, 3, 4, 5]
    assert tr["histobins.0.input-min"][-1] == 2.0
    assert tr["histobins.0.input-max"][-1] == 7.0
    hal.set({"histobins.0.reset": True})
    hal.step(1)
    hal.set({"histobins.0.reset": False, "histobins.0.method": True})
    tr = hal.run(3, inputs={"histobins.0.input": [1.0, 2.0, 6.0]},
                 record=["histobins.0.mean", "histobins.0.variance"])
    # the sums hold the samples taken with method TRUE (not the restart's)
    assert tr["histobins.0.mean"][-1] == pytest.approx(9.0 / 4)
    assert tr["histobins.0.variance"][-1] == pytest.approx(
        (41.0 - 81.0 / 4) / 3)


def test_histobins_pintype_selects_input(hal):
    histo(hal, nbins=10, pintype=1, input_s32=3, input_u32=5,
          input_bit=True, input=7.5, index=3)
    hal.step(3)
    assert hal.getp("histobins.0.binvalue") == 2.0      # 3 twice
    seen = [3.0]
    for pintype, want in ((2, 5.0), (3, 1.0), (0, 7.5), (9, 7.5)):
        hal.set({"histobins.0.pintype": pintype})
        hal.step(1)
        seen.append(want)
        assert hal.getp("histobins.0.input-max") == max(seen)
        assert hal.getp("histobins.0.input-min") == min(seen)


@pytest.mark.parametrize("nbins", [0, 201])
def test_histobins_bad_nbins_freezes(hal, nbins):
    histo(hal, nbins=5)
    hal.run(3, inputs={"histobins.0.input": 1.0})
    hal.set({"histobins.0.nbins": nbins, "histobins.0.index": 4})
    hal.step(3)
    assert hal.getp("histobins.0.input-error") is True
    assert hal.getp("histobins.0.nsamples") == 3
    assert hal.getp("histobins.0.check") == 4
    # back to the same nbins: carries on without a restart
    hal.set({"histobins.0.nbins": 5})
    hal.step(1)
    assert hal.getp("histobins.0.input-error") is False
    assert hal.getp("histobins.0.nsamples") == 4


def test_histobins_new_geometry_restarts(hal):
    histo(hal, nbins=5)
    hal.run(4, inputs={"histobins.0.input": 1.0})
    assert hal.getp("histobins.0.nsamples") == 4
    hal.set({"histobins.0.minvalue": -1.0})
    hal.step(1)
    assert hal.getp("histobins.0.nsamples") == 1
    assert bin_counts(hal, 5) == [0.0] * 5


def test_histobins_index_out_of_range(hal):
    histo(hal, nbins=5)
    for index in (-1, 5, 199, 200):
        hal.set({"histobins.0.index": index})
        hal.step(1)
        assert hal.getp("histobins.0.binvalue") == -1.0
        assert hal.getp("histobins.0.check") == index
    assert hal.getp("histobins.0.availablebins") == 200
