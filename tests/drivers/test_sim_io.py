"""Unit tests of the simulated I/O board driver (drivers/sim_io.comp)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import repo_path
from helpers.environment import on_halsdk_path

import halsdk
from halcompile.cli import process
from halsdk.core import _core

P = "sim-io.0."
SOURCE = str(repo_path("drivers", "sim_io.comp"))


@pytest.fixture(scope="module", autouse=True)
def sim_io_from_source(tmp_path_factory: pytest.TempPathFactory):
    """Build drivers/sim_io.comp into a folder first on HALSDK_PATH, so
    these tests load the source and not the installed module."""
    folder = str(tmp_path_factory.mktemp("sim-io-build"))
    process(SOURCE, "compile", folder)
    with on_halsdk_path(folder):
        yield folder


def board(hal, **counts):
    """Load sim_io with small channel counts, add both functions of board
    0 to a 1 ms thread (write first, then read: outputs loop back in the
    same cycle)."""
    opts = dict(num_digin=2, num_digout=2, num_adcin=1, num_dacout=1,
                num_encoder=1, num_switch=1)
    opts.update(counts)
    hal.loadrt("sim_io", **opts)
    hal.newthread("t", 1_000_000)
    hal.addf(P + "write", "t")
    hal.addf(P + "read", "t")


def kinds(items):
    return {x.name: (x.type, x.direction) for x in items}


def test_names_types_directions(hal):
    board(hal, num_boards=2)
    pins = kinds(hal.pins(P + "*"))
    assert pins[P + "digin.00.in"] == (_core.BIT, _core.OUT)
    assert pins[P + "digin.01.in-not"] == (_core.BIT, _core.OUT)
    assert pins[P + "digin.00.sim-in"] == (_core.BIT, _core.IN)
    assert pins[P + "digout.01.out"] == (_core.BIT, _core.IN)
    assert pins[P + "adcin.00.value"] == (_core.FLOAT, _core.OUT)
    assert pins[P + "dacout.00.value"] == (_core.FLOAT, _core.IN)
    assert pins[P + "dacout.00.enable"] == (_core.BIT, _core.IN)
    assert pins[P + "encoder.00.count"] == (_core.S32, _core.OUT)
    assert pins[P + "encoder.00.position"] == (_core.FLOAT, _core.OUT)
    assert pins[P + "encoder.00.velocity"] == (_core.FLOAT, _core.OUT)
    assert pins[P + "encoder.00.reset"] == (_core.BIT, _core.IN)
    assert pins[P + "encoder.00.index-enable"] == (_core.BIT, _core.IO)
    assert pins[P + "encoder.00.sim-position"] == (_core.FLOAT, _core.IN)
    assert pins[P + "encoder.00.phase-A"] == (_core.BIT, _core.IN)
    assert pins[P + "encoder.00.phase-B"] == (_core.BIT, _core.IN)
    assert pins[P + "switch.00.position"] == (_core.FLOAT, _core.IN)
    for s in ("home", "pos-limit", "neg-limit"):
        assert pins[P + "switch.00." + s] == (_core.BIT, _core.OUT)
    assert P + "digin.02.in" not in pins
    params = kinds(hal.params(P + "*"))
    for name in ("digout.00.invert", "adcin.00.scale", "adcin.00.offset",
                 "dacout.00.scale", "dacout.00.offset",
                 "dacout.00.high_limit", "dacout.00.low_limit",
                 "adcin.00.bit_weight", "adcin.00.hw_offset",
                 "dacout.00.bit_weight", "dacout.00.hw_offset",
                 "encoder.00.position-scale", "encoder.00.sim-source",
                 "encoder.00.sim-counts-per-rev", "switch.00.home-pos",
                 "switch.00.pos-limit-pos", "switch.00.neg-limit-pos",
                 "switch.00.hysteresis"):
        assert params[P + name][1] == _core.RW, name
    assert hal.getp(P + "dacout.00.high_limit") == 10.0
    assert hal.getp(P + "dacout.00.low_limit") == -10.0
    assert hal.getp(P + "encoder.00.position-scale") == 1.0
    assert hal.getp(P + "encoder.00.sim-source") == 0
    functs = sorted(f.name for f in hal.functions())
    assert functs == ["sim-io.0.read", "sim-io.0.write",
                      "sim-io.1.read", "sim-io.1.write"]
    assert hal.pins("sim-io.1.digin.00.in")


def test_default_counts(hal):
    hal.loadrt("sim_io")
    names = [x.name for x in hal.pins("sim-io.0.*")]
    assert sum(n.endswith(".in-not") for n in names) == 8
    assert sum(n.endswith(".out") for n in names) == 8
    assert sum(".adcin." in n and n.endswith(".value") for n in names) == 4
    assert sum(n.endswith(".count") for n in names) == 3
    assert hal.pins("sim-io.1.*") == []


def test_digital_loopback_and_invert(hal):
    board(hal)
    tr = hal.run(4, inputs={P + "digout.00.out": [0, 1, 1, 0],
                            P + "digout.01.out": 1},
                 record=[P + "digin.00.in", P + "digin.00.in-not",
                         P + "digin.01.in"])
    assert list(tr[P + "digin.00.in"]) == [0, 1, 1, 0]
    assert list(tr[P + "digin.00.in-not"]) == [1, 0, 0, 1]
    assert list(tr[P + "digin.01.in"]) == [1, 1, 1, 1]
    hal.setp(P + "digout.01.invert", 1)
    tr = hal.run(1, record=[P + "digin.01.in", P + "digin.01.in-not"])
    assert tr[P + "digin.01.in"][0] == 0 and tr[P + "digin.01.in-not"][0] == 1


def test_digital_sim_inputs_without_loopback(hal):
    board(hal, num_digin=3)
    hal.set({P + "loopback": 0, P + "digout.00.out": 1,
             P + "digin.00.sim-in": 0, P + "digin.02.sim-in": 1})
    hal.step(1)
    assert hal.getp(P + "digin.00.in") == 0
    assert hal.getp(P + "digin.00.in-not") == 1
    assert hal.getp(P + "digin.02.in") == 1
    # channel 2 has no digout: it follows sim-in even with loopback on
    hal.set({P + "loopback": 1})
    hal.step(1)
    assert hal.getp(P + "digin.00.in") == 1
    assert hal.getp(P + "digin.02.in") == 1


def test_analog_loopback_scale_offset_limits(hal):
    board(hal)
    hal.setp(P + "dacout.00.scale", 2.0)
    hal.setp(P + "dacout.00.offset", 1.0)
    hal.setp(P + "dacout.00.high_limit", 8.0)
    hal.setp(P + "dacout.00.low_limit", -4.0)
    hal.setp(P + "adcin.00.scale", 0.5)
    hal.setp(P + "adcin.00.offset", 0.25)
    tr = hal.run(5, inputs={P + "dacout.00.value":
                            [2.0, 0.0, 2.0, 10.0, -10.0],
                            P + "dacout.00.enable": [0, 1, 1, 1, 1]},
                 record=[P + "adcin.00.value"])
    # terminal: 0 (disabled), 1, 5, 8 (clamped from 21), -4 (from -19)
    expect = [v * 0.5 - 0.25 for v in (0.0, 1.0, 5.0, 8.0, -4.0)]
    assert list(tr[P + "adcin.00.value"]) == pytest.approx(expect)
    hal.set({P + "adc-loopback": 0, P + "adcin.00.sim-in": 3.0})
    hal.step(1)
    assert hal.getp(P + "adcin.00.value") == pytest.approx(1.25)


def test_encoder_counts_moving_position(hal):
    board(hal)
    hal.setp(P + "encoder.00.position-scale", 100.0)
    hal.setp(P + "encoder.00.sim-counts-per-rev", 0)
    # 0.5 units/s: 0.0005 units (0.05 counts) each 1 ms cycle
    pos = 0.2 + np.arange(400) * 0.0005
    tr = hal.run(400, inputs={P + "encoder.00.sim-position": pos},
                 record=[P + "encoder.00.count", P + "encoder.00.position",
                         P + "encoder.00.velocity"])
    raw = np.floor(pos * 100.0 + 0.5).astype(int)     # nearest count
    assert list(tr[P + "encoder.00.count"]) == list(raw - raw[0])
    assert tr[P + "encoder.00.position"][-1] == pytest.approx(
        (raw[-1] - raw[0]) / 100.0)
    # counts arrive in quanta: the velocity averaged over the run is right
    assert np.mean(tr[P + "encoder.00.velocity"][1:]) == pytest.approx(
        (raw[-1] - raw[0]) / 100.0 / 0.399, rel=1e-6)
    # backwards
    tr = hal.run(3, inputs={P + "encoder.00.sim-position": [0.0, -0.1, -0.1]},
                 record=[P + "encoder.00.count"])
    assert list(tr[P + "encoder.00.count"]) == [-20, -30, -30]
    hal.set({P + "encoder.00.reset": 1})
    hal.step(1)
    assert hal.getp(P + "encoder.00.count") == 0
    hal.set({P + "encoder.00.reset": 0, P + "encoder.00.sim-position": 0.0})
    hal.step(1)
    assert hal.getp(P + "encoder.00.count") == 10
    # a NaN position leaves the counter where it was
    hal.set({P + "encoder.00.sim-position": float("nan")})
    hal.step(1)
    assert hal.getp(P + "encoder.00.count") == 10


def test_encoder_counts_stepgen_steps(hal):
    hal.loadrt("stepgen", "step_type=0")
    hal.loadrt("sim_io", num_encoder=1)
    hal.newthread("base", 25_000, fp=False)
    hal.newthread("servo", 1_000_000)
    hal.addf("stepgen.make-pulses", "base")
    hal.addf("stepgen.update-freq", "servo")
    hal.addf("stepgen.capture-position", "servo")
    hal.addf(P + "read", "servo")
    hal.net("fb", "stepgen.0.position-fb", P + "encoder.00.sim-position")
    hal.set({"stepgen.0.position-scale": 1000.0, "stepgen.0.maxvel": 10.0,
             "stepgen.0.maxaccel": 200.0, "stepgen.0.enable": True,
             "stepgen.0.position-cmd": 0.537,
             P + "encoder.00.position-scale": 1000.0})
    rec = ["stepgen.0.counts", "stepgen.0.position-fb",
           P + "encoder.00.count", P + "encoder.00.position"]
    tr = hal.run(12000, record=rec)
    assert tr["stepgen.0.counts"][-1] == 537
    assert tr[P + "encoder.00.count"][-1] == 537
    # position-fb is captured each servo period: the count follows it exactly
    steps = np.rint(tr["stepgen.0.position-fb"] * 1000).astype(int)
    assert list(tr[P + "encoder.00.count"]) == list(steps)
    assert tr[P + "encoder.00.position"][-1] == pytest.approx(0.537)
    hal.set({"stepgen.0.position-cmd": -0.25})
    tr = hal.run(12000, record=rec)
    assert tr["stepgen.0.counts"][-1] == -250
    assert tr[P + "encoder.00.count"][-1] == -250
    steps = np.rint(tr["stepgen.0.position-fb"] * 1000).astype(int)
    assert list(tr[P + "encoder.00.count"]) == list(steps)


def test_index_enable_zeroes_at_index(hal):
    board(hal)
    hal.setp(P + "encoder.00.sim-counts-per-rev", 100)
    hal.set({P + "encoder.00.sim-position": 30.0})
    hal.step(1)
    # no index-enable: passing 100 does nothing
    tr = hal.run(2, inputs={P + "encoder.00.sim-position": [90.0, 120.0]},
                 record=[P + "encoder.00.count"])
    assert list(tr[P + "encoder.00.count"]) == [60, 90]
    hal.set({P + "encoder.00.index-enable": 1})
    tr = hal.run(4, inputs={P + "encoder.00.sim-position":
                            [150.0, 199.0, 203.0, 310.0]},
                 record=[P + "encoder.00.count",
                         P + "encoder.00.index-enable"])
    assert list(tr[P + "encoder.00.index-enable"]) == [1, 1, 0, 0]
    # zeroed at raw 200: 203 reads 3, later indexes are ignored
    assert list(tr[P + "encoder.00.count"]) == [120, 169, 3, 110]
    # moving down from 310 to 95: the first index met is the one at 300
    hal.set({P + "encoder.00.index-enable": 1})
    tr = hal.run(1, inputs={P + "encoder.00.sim-position": 95.0},
                 record=[P + "encoder.00.count",
                         P + "encoder.00.index-enable"])
    assert tr[P + "encoder.00.count"][0] == -205
    assert tr[P + "encoder.00.index-enable"][0] == 0
    # index exactly on a multiple, negative side: -1 -> -100 meets -100
    hal.set({P + "encoder.00.sim-position": -1.0})
    hal.step(1)
    hal.set({P + "encoder.00.index-enable": 1,
             P + "encoder.00.sim-position": -100.0})
    hal.step(1)
    assert hal.getp(P + "encoder.00.count") == 0
    assert hal.getp(P + "encoder.00.index-enable") == 0


def test_step_dir_inputs_count_rising_edges(hal):
    board(hal)
    e = P + "encoder.00."
    hal.setp(e + "sim-source", 1)
    hal.setp(e + "position-scale", 4.0)
    hal.setp(e + "sim-counts-per-rev", 0)
    # phase-A is the step, phase-B the direction (high: down); the first
    # read only takes the levels, so the step high there is not a count
    step = [1, 0, 1, 1, 0, 1, 0, 1, 0, 0, 1, 0, 1]
    dirn = [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 0, 0]
    tr = hal.run(len(step), inputs={e + "phase-A": step, e + "phase-B": dirn},
                 record=[e + "count", e + "position"])
    assert list(tr[e + "count"]) == [0, 0, 1, 1, 1, 2, 2, 1, 1, 1, 0, 0, 1]
    assert tr[e + "position"][-1] == 0.25
    # sim-position is ignored in this mode
    hal.set({e + "sim-position": 50.0})
    hal.step(1)
    assert hal.getp(e + "count") == 1


def test_quadrature_inputs_count_every_edge(hal):
    board(hal)
    e = P + "encoder.00."
    hal.setp(e + "sim-source", 2)
    hal.setp(e + "sim-counts-per-rev", 0)
    # up: A leads B; then down; then a jump over two states (both inputs
    # changed in one read), which has no direction and is not counted
    ab = [(1, 0), (1, 1), (0, 1), (0, 0), (1, 0), (1, 0),
          (0, 0), (0, 1), (1, 1), (0, 0), (1, 0)]
    tr = hal.run(len(ab), inputs={e + "phase-A": [a for a, _ in ab],
                                  e + "phase-B": [b for _, b in ab]},
                 record=[e + "count"])
    assert list(tr[e + "count"]) == [0, 1, 2, 3, 4, 4, 3, 2, 1, 1, 2]


def test_up_down_inputs_count_rising_edges(hal):
    board(hal)
    e = P + "encoder.00."
    hal.setp(e + "sim-source", 3)
    hal.setp(e + "sim-counts-per-rev", 0)
    # phase-A pulses count up, phase-B pulses down; the first read only
    # takes the levels
    up = [1, 0, 1, 0, 1, 1, 0, 0, 0, 0, 1]
    down = [0, 0, 0, 0, 0, 0, 1, 0, 1, 1, 1]
    tr = hal.run(len(up), inputs={e + "phase-A": up, e + "phase-B": down},
                 record=[e + "count"])
    assert list(tr[e + "count"]) == [0, 0, 1, 1, 2, 2, 1, 1, 0, 0, 1]


def test_source_change_keeps_count_and_bad_source_stands_still(hal):
    board(hal)
    e = P + "encoder.00."
    hal.setp(e + "sim-counts-per-rev", 0)
    hal.set({e + "sim-position": 7.0})
    hal.step(1)
    hal.set({e + "sim-position": 12.0})
    hal.step(1)
    assert hal.getp(e + "count") == 5
    # to step/dir: the step already high is not a count, the next one is
    hal.setp(e + "sim-source", 1)
    hal.run(3, inputs={e + "phase-A": [1, 0, 1]})
    assert hal.getp(e + "count") == 6
    # back to the position: the count carries on from 6, not from 12 - 7
    hal.setp(e + "sim-source", 0)
    hal.set({e + "sim-position": 40.0})
    hal.step(1)
    assert hal.getp(e + "count") == 6
    hal.set({e + "sim-position": 43.0})
    hal.step(1)
    assert hal.getp(e + "count") == 9
    # an unknown source: nothing counts until it is valid again
    hal.setp(e + "sim-source", 4)
    hal.run(4, inputs={e + "sim-position": [50.0, 60.0, 70.0, 80.0],
                       e + "phase-A": [0, 1, 0, 1]})
    assert hal.getp(e + "count") == 9
    hal.setp(e + "sim-source", 0)
    hal.step(1)
    hal.set({e + "sim-position": 81.0})
    hal.step(1)
    assert hal.getp(e + "count") == 10


def stepgen_loopback(hal, step_type: int) -> str:
    """A stepgen channel of step_type whose outputs drive the phase-A/B
    inputs of encoder 00, both in a 25 us base thread (make-pulses, then
    read; read uses floating point, so the thread has it); the slow parts
    of stepgen in a 1 ms servo thread."""
    outs = {0: ("step", "dir"), 1: ("up", "down")}.get(
        step_type, ("phase-A", "phase-B"))
    e = P + "encoder.00."
    hal.loadrt("stepgen", f"step_type={step_type}")
    hal.loadrt("sim_io", num_encoder=1)
    hal.newthread("base", 25_000)
    hal.newthread("servo", 1_000_000)
    hal.addf("stepgen.make-pulses", "base")
    hal.addf(P + "read", "base")
    hal.addf("stepgen.update-freq", "servo")
    hal.addf("stepgen.capture-position", "servo")
    hal.net("sa", "stepgen.0." + outs[0], e + "phase-A")
    hal.net("sb", "stepgen.0." + outs[1], e + "phase-B")
    hal.set({"stepgen.0.position-scale": 1000.0, "stepgen.0.maxvel": 10.0,
             "stepgen.0.maxaccel": 200.0, "stepgen.0.enable": True,
             e + "sim-source": {0: 1, 1: 3}.get(step_type, 2),
             e + "position-scale": 1000.0, e + "sim-counts-per-rev": 100})
    return e


@pytest.mark.parametrize("step_type", [0, 1, 2])
def test_stepgen_pulses_counted(hal, step_type):
    e = stepgen_loopback(hal, step_type)
    # forward, back past the start, forward again: 3 direction changes
    cmd = np.repeat([0.3, -0.2, 0.05], [3000, 5000, 3000])
    rec = ["stepgen.0.rawcounts", "stepgen.0.counts", e + "count",
           e + "position", "sb"]
    tr = hal.run(len(cmd), inputs={"stepgen.0.position-cmd": cmd},
                 record=rec)
    raw = tr["stepgen.0.rawcounts"]
    assert raw.max() == 300 and raw.min() == -200
    assert list(tr[e + "count"]) == list(raw)       # every base period
    assert tr["stepgen.0.counts"][-1] == tr[e + "count"][-1] == 50
    assert tr[e + "position"][-1] == pytest.approx(0.05)
    assert list(tr[e + "position"]) == pytest.approx(list(raw / 1000.0))
    if step_type == 0:
        # dir was high (reverse) for the way down only
        assert tr["sb"][np.diff(raw, prepend=0) < 0].all()
        assert not tr["sb"][np.diff(raw, prepend=0) > 0].any()


@pytest.mark.parametrize("step_type", [0, 2])
def test_stepgen_index_every_counts_per_rev(hal, step_type):
    e = stepgen_loopback(hal, step_type)
    rec = ["stepgen.0.rawcounts", e + "count", e + "index-enable"]
    hal.set({"stepgen.0.position-cmd": 0.35})
    tr = hal.run(1000, record=rec)                 # 25 ms: under way
    start = int(tr["stepgen.0.rawcounts"][-1])
    assert 0 < start < 300
    hal.set({e + "index-enable": 1})
    tr = hal.run(6000, record=rec)
    raw, count = tr["stepgen.0.rawcounts"], tr[e + "count"]
    idx = (start // 100 + 1) * 100                 # next multiple up
    hit = int(np.argmax(raw == idx))
    assert raw[hit] == idx
    assert list(tr[e + "index-enable"][:hit]) == [1] * hit
    assert not tr[e + "index-enable"][hit:].any()
    assert list(count[:hit]) == list(raw[:hit])
    assert list(count[hit:]) == list(raw[hit:] - idx)
    assert count[-1] == 350 - idx
    # on the way down the first index met is the multiple below 350
    hal.set({e + "index-enable": 1, "stepgen.0.position-cmd": -0.12})
    tr = hal.run(8000, record=rec)
    raw, count = tr["stepgen.0.rawcounts"], tr[e + "count"]
    hit = int(np.argmax(raw == 300))
    assert raw[hit] == 300 and tr[e + "index-enable"][hit - 1] == 1
    assert not tr[e + "index-enable"][hit:].any()
    assert list(count[hit:]) == list(raw[hit:] - 300)
    assert count[-1] == -420


def test_switches_with_hysteresis(hal):
    board(hal)
    s = P + "switch.00."
    hal.setp(s + "home-pos", 5.0)
    hal.setp(s + "pos-limit-pos", 10.0)
    hal.setp(s + "neg-limit-pos", -10.0)
    hal.setp(s + "hysteresis", 0.5)
    pos = [0.0, 4.9, 5.0, 4.7, 4.4, 5.0, 10.0, 9.6, 9.4, -10.0, -9.6, -9.4]
    tr = hal.run(len(pos), inputs={s + "position": pos},
                 record=[s + "home", s + "pos-limit", s + "neg-limit"])
    assert list(tr[s + "home"]) == [0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 0, 0]
    assert list(tr[s + "pos-limit"]) == [0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0]
    assert list(tr[s + "neg-limit"]) == [0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 0]


@pytest.mark.parametrize("opts, match", [
    ({"num_boards": 0}, r"num_boards=0 is out of range \(must be 1 to 8\)"),
    ({"num_boards": 9}, "num_boards=9 is out of range"),
    ({"num_digin": -1}, "num_digin=-1 is out of range"),
    ({"num_dacout": 65}, "num_dacout=65 is out of range"),
    ({"num_switch": 100}, "num_switch=100 is out of range"),
    ({"num_encoders": 2}, "Unknown parameter `num_encoders=2'"),
    ({"num_adcin": "x"}, "not an integer|invalid"),
])
def test_bad_modparams(hal, opts, match):
    with pytest.raises(halsdk.HalError, match=match):
        hal.loadrt("sim_io", **opts)
    assert hal.components("sim_io") == []
    assert hal.pins() == [] and hal.functions() == []
