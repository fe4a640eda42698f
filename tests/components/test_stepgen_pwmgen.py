"""stepgen and pwmgen: load lines, interface and behaviour.

The numbers match the LinuxCNC 2.9 reference (see tests/data/complib/stepgen*.hal
and pwmgen*.hal); these tests state the behaviour a machine builder relies
on, with a fast base thread for make-pulses and a slower servo thread for
the rest, stepped deterministically.
"""

from __future__ import annotations

import numpy as np
import pytest

import halsdk
from halsdk.core import _core

BASE = 25_000           # ns, make-pulses
SERVO = 1_000_000       # ns, update-freq / capture-position / update


def stepgen_threads(hal, args):
    hal.loadrt("stepgen", args)
    hal.newthread("base", BASE, fp=False)
    hal.newthread("servo", SERVO)
    hal.addf("stepgen.make-pulses", "base")
    hal.addf("stepgen.update-freq", "servo")
    hal.addf("stepgen.capture-position", "servo")


def names(hal, pattern):
    return sorted(p.name for p in hal.pins(pattern))


def edges(x):
    """Indices where a bit trace goes from low to high."""
    x = np.asarray(x, dtype=int)
    return np.flatnonzero(np.diff(np.concatenate(([0], x))) == 1)


# ---------------------------------------------------------------- stepgen

def test_stepgen_pins_follow_step_and_control_types(hal):
    hal.loadrt("stepgen", "step_type=0,1,2,15 ctrl_type=p,v,P,V "
               "user_step_type=1,3,2,6,4")
    assert names(hal, "stepgen.0.*") == [
        "stepgen.0.counts", "stepgen.0.dir", "stepgen.0.enable",
        "stepgen.0.position-cmd", "stepgen.0.position-fb", "stepgen.0.step"]
    assert "stepgen.1.up" in names(hal, "stepgen.1.*")
    assert "stepgen.1.velocity-cmd" in names(hal, "stepgen.1.*")
    assert [n for n in names(hal, "stepgen.2.*") if "phase" in n] == [
        "stepgen.2.phase-A", "stepgen.2.phase-B"]
    # the user pattern uses bits 0-2: three phases
    assert [n for n in names(hal, "stepgen.3.*") if "phase" in n] == [
        "stepgen.3.phase-A", "stepgen.3.phase-B", "stepgen.3.phase-C"]
    params0 = sorted(p.name for p in hal.params("stepgen.0.*"))
    assert params0 == [f"stepgen.0.{p}" for p in (
        "dirhold", "dirsetup", "frequency", "maxaccel", "maxvel",
        "position-scale", "rawcounts", "steplen", "stepspace")]
    assert "stepgen.1.dirdelay" in [p.name for p in hal.params("stepgen.1.*")]
    assert "stepgen.2.stepspace" not in [p.name for p in hal.params()]
    assert hal.getp("stepgen.0.position-scale") == 1.0
    assert hal.getp("stepgen.0.steplen") == 1
    fps = {f.name: f.uses_fp for f in hal.functions("stepgen.*")}
    assert fps == {"stepgen.make-pulses": False, "stepgen.update-freq": True,
                   "stepgen.capture-position": True}


@pytest.mark.parametrize("args", [
    "", "step_type=16", "step_type=-2", "step_type=0 ctrl_type=x",
    "step_type=15 user_step_type=1,2,40",
    "step_type=" + ",".join(["0"] * 17)])
def test_stepgen_refuses_bad_load_lines(hal, args):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("stepgen", args) if args else hal.loadrt("stepgen")
    assert not hal.pins("stepgen.*")


def test_position_mode_reaches_command_within_limits(hal):
    stepgen_threads(hal, "step_type=0")
    hal.set({"stepgen.0.position-scale": 1000.0, "stepgen.0.maxvel": 10.0,
             "stepgen.0.maxaccel": 200.0, "stepgen.0.enable": True,
             "stepgen.0.position-cmd": 0.5})
    n = 200 * SERVO // BASE
    tr = hal.run(n, record=["stepgen.0.step", "stepgen.0.dir",
                            "stepgen.0.counts", "stepgen.0.position-fb",
                            "stepgen.0.frequency"])
    assert tr["stepgen.0.counts"][-1] == 500
    assert tr["stepgen.0.position-fb"][-1] == pytest.approx(0.5, abs=1e-3)
    # one pulse per count, all forward
    assert len(edges(tr["stepgen.0.step"])) == 500
    assert not tr["stepgen.0.dir"].any()
    freq = tr["stepgen.0.frequency"]
    assert freq.max() <= 10.0 * 1000 + 1e-6
    assert freq.max() > 9000            # it did cruise
    # accel limit: 200 units/s^2 = 200 steps/s per servo period
    assert np.abs(np.diff(freq)).max() <= 200.0 + 1e-6
    assert freq[-1] == 0.0


def test_velocity_mode_ramps_and_counts(hal):
    stepgen_threads(hal, "step_type=0 ctrl_type=v")
    hal.set({"stepgen.0.position-scale": 100.0, "stepgen.0.maxaccel": 50.0,
             "stepgen.0.enable": True, "stepgen.0.velocity-cmd": -20.0})
    tr = hal.run(400 * SERVO // BASE,
                 record=["stepgen.0.frequency", "stepgen.0.counts",
                         "stepgen.0.dir"])
    freq = tr["stepgen.0.frequency"]
    # 50 units/s^2 * 100 steps/unit = 5000 steps/s per second: 400 ms
    # reach -2000 steps/s
    assert freq[-1] == pytest.approx(-2000.0)
    assert freq[SERVO // BASE * 100] == pytest.approx(-500.0)
    assert tr["stepgen.0.dir"][-1]
    # ramp for 0.4 s: half the final speed on average
    assert tr["stepgen.0.counts"][-1] == pytest.approx(-400, abs=2)


def test_timing_parameters_round_up_and_shape_the_pulses(hal):
    stepgen_threads(hal, "step_type=0 ctrl_type=v")
    hal.set({"stepgen.0.steplen": 60_000, "stepgen.0.stepspace": 30_000,
             "stepgen.0.dirsetup": 100_000, "stepgen.0.dirhold": 1,
             "stepgen.0.enable": True})
    cmd = np.where(np.arange(4000) < 2000, 1e6, -1e6)
    tr = hal.run(4000, inputs={"stepgen.0.velocity-cmd": cmd},
                 record=["stepgen.0.step", "stepgen.0.dir"])
    assert hal.getp("stepgen.0.steplen") == 75_000      # 3 base periods
    assert hal.getp("stepgen.0.stepspace") == 50_000    # 2
    assert hal.getp("stepgen.0.dirsetup") == 100_000    # 4
    assert hal.getp("stepgen.0.dirhold") == 25_000      # 1
    # the step rate was limited to 1 / (75 + 50 us)
    assert hal.getp("stepgen.0.frequency") == pytest.approx(-8000.0)
    step = tr["stepgen.0.step"].astype(int)
    rise = edges(step)
    fall = edges(1 - step)
    fall = fall[fall > rise[0]]
    widths = fall[:len(rise) - 1] - rise[:len(fall)][:len(rise) - 1]
    assert set(widths) == {3}
    assert np.diff(rise).min() >= 5
    # the direction is set at least dirsetup before the next pulse
    flip = np.flatnonzero(np.diff(tr["stepgen.0.dir"].astype(int))) + 1
    assert len(flip) == 1
    after = rise[rise >= flip[0]]
    assert after[0] - flip[0] >= 4


def test_maxvel_above_step_rate_is_lowered(hal, capfd):
    stepgen_threads(hal, "step_type=0")
    hal.set({"stepgen.0.maxvel": 1000.0, "stepgen.0.position-scale": 100.0,
             "stepgen.0.enable": True})
    hal.run(SERVO // BASE)
    # steplen + stepspace = 2 base periods: 20000 steps/s
    assert hal.getp("stepgen.0.maxvel") == pytest.approx(200.0)
    assert "maximum possible frequency is 20000" in capfd.readouterr().err


def test_zero_scale_is_replaced_by_one(hal):
    stepgen_threads(hal, "step_type=0")
    hal.set({"stepgen.0.position-scale": 0.0})
    hal.run(SERVO // BASE)
    assert hal.getp("stepgen.0.position-scale") == 1.0


def test_disable_stops_and_resumes_from_new_command(hal):
    stepgen_threads(hal, "step_type=0")
    hal.set({"stepgen.0.position-scale": 100.0, "stepgen.0.enable": True,
             "stepgen.0.position-cmd": 0.2})
    hal.run(50 * SERVO // BASE)
    assert hal.getp("stepgen.0.rawcounts") == 20
    hal.set({"stepgen.0.enable": False, "stepgen.0.position-cmd": 5.0})
    tr = hal.run(20 * SERVO // BASE, record=["stepgen.0.counts",
                                              "stepgen.0.step"])
    assert (tr["stepgen.0.counts"] == 20).all()
    assert not tr["stepgen.0.step"][-100:].any()
    assert hal.getp("stepgen.0.frequency") == 0.0
    # enabled again it moves to the command, starting from standstill
    hal.set({"stepgen.0.enable": True, "stepgen.0.maxaccel": 100.0,
             "stepgen.0.position-cmd": 0.3})
    tr = hal.run(100 * SERVO // BASE, record=["stepgen.0.frequency"])
    assert abs(tr["stepgen.0.frequency"][0]) <= 100 * 100 * SERVO * 1e-9
    assert hal.getp("stepgen.0.rawcounts") == 30


def test_quadrature_and_phase_patterns(hal):
    hal.loadrt("stepgen", "step_type=2,3,15 ctrl_type=v,v,v "
               "user_step_type=1,0,2")
    hal.newthread("t", 50_000)
    hal.addf("stepgen.update-freq", "t")
    hal.addf("stepgen.make-pulses", "t")
    for c in range(3):
        hal.set({f"stepgen.{c}.enable": True,
                 f"stepgen.{c}.velocity-cmd": 5000.0})
    rec = ["stepgen.0.phase-A", "stepgen.0.phase-B", "stepgen.1.phase-A",
           "stepgen.1.phase-B", "stepgen.1.phase-C", "stepgen.2.phase-A",
           "stepgen.2.phase-B"]
    tr = hal.run(60, record=rec)

    def words(pins):
        w = sum(tr[p].astype(int) << k for k, p in enumerate(pins))
        return [int(x) for i, x in enumerate(w) if i == 0 or x != w[i - 1]]
    assert words(rec[:2])[:8] == [1, 3, 2, 0, 1, 3, 2, 0]
    assert words(rec[2:5])[:6] == [1, 2, 4, 1, 2, 4]
    # a user pattern may hold an all-off state
    assert words(rec[5:])[:6] == [1, 0, 2, 1, 0, 2]
    # backwards the patterns run the other way
    for c in range(3):
        hal.set({f"stepgen.{c}.velocity-cmd": -5000.0})
    tr = hal.run(60, record=rec)
    assert words(rec[:2])[:5] == [0, 2, 3, 1, 0]


def test_up_down_pulses_by_direction(hal):
    stepgen_threads(hal, "step_type=1 ctrl_type=v")
    hal.set({"stepgen.0.enable": True})
    cmd = np.where(np.arange(2000) < 1000, 2000.0, -2000.0)
    tr = hal.run(2000, inputs={"stepgen.0.velocity-cmd": cmd},
                 record=["stepgen.0.up", "stepgen.0.down",
                         "stepgen.0.counts"])
    up, down = tr["stepgen.0.up"], tr["stepgen.0.down"]
    assert not (up & down).any()
    assert len(edges(up)) > 40 and len(edges(down)) > 40
    assert edges(up).max() < edges(down).min()


# ----------------------------------------------------------------- pwmgen

def pwmgen_setup(hal, types, period=50_000):
    hal.loadrt("pwmgen", "output_type=" + ",".join(map(str, types)))
    hal.newthread("base", period, fp=False)
    hal.newthread("servo", SERVO)
    hal.addf("pwmgen.make-pulses", "base")
    hal.addf("pwmgen.update", "servo")


def test_pwmgen_pins_and_refused_loads(hal):
    hal.loadrt("pwmgen", "output_type=0,1,2")
    assert [n for n in names(hal, "pwmgen.*") if n.split(".")[-1] in (
        "pwm", "dir", "up", "down")] == [
        "pwmgen.0.pwm", "pwmgen.1.dir", "pwmgen.1.pwm", "pwmgen.2.down",
        "pwmgen.2.up"]
    io = [p.name for p in hal.pins("pwmgen.0.*") if p.direction == _core.IO]
    assert sorted(io) == [f"pwmgen.0.{n}" for n in (
        "dither-pwm", "max-dc", "min-dc", "offset", "pwm-freq", "scale")]
    assert hal.getp("pwmgen.0.max-dc") == 1.0
    assert hal.getp("pwmgen.0.scale") == 1.0


@pytest.mark.parametrize("args", ["", "output_type=3",
                                  "output_type=" + ",".join(["0"] * 9)])
def test_pwmgen_refuses_bad_load_lines(hal, args):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("pwmgen", args) if args else hal.loadrt("pwmgen")
    assert not hal.pins("pwmgen.*")


def test_pwm_rounds_frequency_and_duty_cycle(hal):
    pwmgen_setup(hal, [0])
    hal.set({"pwmgen.0.enable": True, "pwmgen.0.pwm-freq": 3000.0,
             "pwmgen.0.value": 0.5})
    tr = hal.run(700, record=["pwmgen.0.pwm", "pwmgen.0.curr-dc"])
    # 333 us is rounded to 7 base periods; 3.5 high periods round to 4
    assert hal.getp("pwmgen.0.pwm-freq") == pytest.approx(1e9 / 350_000)
    assert tr["pwmgen.0.curr-dc"][-1] == pytest.approx(4 / 7)
    pwm = tr["pwmgen.0.pwm"]
    assert pwm[140:].mean() == pytest.approx(4 / 7)
    rise = edges(pwm)
    assert set(np.diff(rise[rise > 40])) == {7}


def test_pwm_limits_and_direction_outputs(hal):
    pwmgen_setup(hal, [0, 1, 2])
    for c in range(3):
        hal.set({f"pwmgen.{c}.enable": True, f"pwmgen.{c}.pwm-freq": 1000.0,
                 f"pwmgen.{c}.scale": 10.0, f"pwmgen.{c}.min-dc": 0.1,
                 f"pwmgen.{c}.max-dc": 0.8, f"pwmgen.{c}.value": -3.0})
    tr = hal.run(400, record=["pwmgen.0.pwm", "pwmgen.0.curr-dc",
                              "pwmgen.1.pwm", "pwmgen.1.dir",
                              "pwmgen.1.curr-dc", "pwmgen.2.up",
                              "pwmgen.2.down"])
    # type 0 gives no negative output, only min-dc
    assert tr["pwmgen.0.curr-dc"][-1] == pytest.approx(0.1)
    assert tr["pwmgen.1.curr-dc"][-1] == pytest.approx(-0.3)
    assert tr["pwmgen.1.dir"][-1]
    assert tr["pwmgen.1.pwm"][40:].mean() == pytest.approx(0.3)
    assert not tr["pwmgen.2.up"].any()
    assert tr["pwmgen.2.down"][40:].mean() == pytest.approx(0.3)
    hal.set({f"pwmgen.{c}.value": 20.0 for c in range(3)})
    tr = hal.run(400, record=["pwmgen.1.curr-dc", "pwmgen.2.up"])
    assert tr["pwmgen.1.curr-dc"][-1] == pytest.approx(0.8)
    assert tr["pwmgen.2.up"][40:].mean() == pytest.approx(0.8)


@pytest.mark.parametrize("mode", ["pdm", "dither"])
def test_pdm_and_dither_average_the_exact_duty_cycle(hal, mode):
    pwmgen_setup(hal, [0])
    hal.set({"pwmgen.0.enable": True, "pwmgen.0.value": 0.237})
    if mode == "dither":
        hal.set({"pwmgen.0.pwm-freq": 3000.0, "pwmgen.0.dither-pwm": True})
    tr = hal.run(20_000, record=["pwmgen.0.pwm", "pwmgen.0.curr-dc"])
    assert tr["pwmgen.0.curr-dc"][-1] == pytest.approx(0.237)
    assert tr["pwmgen.0.pwm"][20:].mean() == pytest.approx(0.237, abs=2e-3)
    if mode == "dither":
        # the PWM frequency is kept as asked
        assert hal.getp("pwmgen.0.pwm-freq") == 3000.0


def test_pwmgen_disabled_outputs_stay_low(hal):
    pwmgen_setup(hal, [2])
    hal.set({"pwmgen.0.min-dc": 0.5, "pwmgen.0.value": 0.9})
    tr = hal.run(200, record=["pwmgen.0.up", "pwmgen.0.down"])
    assert not tr["pwmgen.0.up"].any() and not tr["pwmgen.0.down"].any()
    hal.set({"pwmgen.0.pwm-freq": 1e9, "pwmgen.0.min-dc": 2.0})
    hal.set({"pwmgen.0.enable": True})
    hal.run(40)
    # above half the make-pulses rate, and min-dc above max-dc
    assert hal.getp("pwmgen.0.pwm-freq") == pytest.approx(10_000.0)
    assert hal.getp("pwmgen.0.min-dc") == 1.0
