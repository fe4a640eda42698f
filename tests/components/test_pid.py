"""The motor-control components (pid, ...): load lines, pins and behaviour,
checked against facts observed on the LinuxCNC 2.9 reference."""

from __future__ import annotations

import numpy as np
import pytest

import halsdk


def test_pid_default_load_and_debug_pins(hal):
    hal.loadrt("pid")
    names = [p.name for p in hal.pins("pid.*.Pgain")]
    assert names == ["pid.0.Pgain", "pid.1.Pgain", "pid.2.Pgain"]
    assert hal.getp("pid.0.Pgain") == 1.0
    assert hal.getp("pid.0.error-previous-target") is True
    assert hal.getp("pid.0.tune-cycles") == 50
    assert hal.pins("pid.0.errorI") == []
    assert [f.name for f in hal.functions()] == [
        "pid.0.do-pid-calcs", "pid.1.do-pid-calcs", "pid.2.do-pid-calcs"]


def test_pid_debug_and_names(hal):
    hal.loadrt("pid", "names=x,y debug=1")
    assert [p.name for p in hal.pins("*.errorI")] == ["x.errorI", "y.errorI"]
    assert [p.name for p in hal.pins("x.ultimate-*")] == [
        "x.ultimate-gain", "x.ultimate-period"]


@pytest.mark.parametrize("args", ["num_chan=17", "num_chan=-1",
                                  "num_chan=2 names=a,b"])
def test_pid_refused_load_lines(hal, args):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("pid", args)
    assert hal.pins("pid.*") == []


def _loop(hal, **pins):
    hal.loadrt("pid", "num_chan=1 debug=1")
    hal.newthread("servo", 1_000_000)
    hal.addf("pid.0.do-pid-calcs", "servo")
    hal.set({"pid.0.enable": True, "pid.0.error-previous-target": False})
    hal.set({f"pid.0.{k}": v for k, v in pins.items()})


def test_pid_p_and_i_terms(hal):
    _loop(hal, Pgain=2.0, Igain=10.0)
    tr = hal.run(5, inputs={"pid.0.command": 1.0, "pid.0.feedback": 0.5},
                 record=["pid.0.output", "pid.0.errorI", "pid.0.error"])
    assert tr["pid.0.error"][-1] == pytest.approx(0.5)
    assert tr["pid.0.errorI"][-1] == pytest.approx(0.5 * 0.005)
    assert tr["pid.0.output"][-1] == pytest.approx(1.0 + 10.0 * 0.0025)


def test_pid_deadband_and_maxerror(hal):
    _loop(hal, Pgain=1.0, deadband=0.1, maxerror=0.3)
    tr = hal.run(3, inputs={"pid.0.command": [0.05, 1.0, -1.0],
                            "pid.0.feedback": 0.0},
                 record=["pid.0.output"])
    # inside the deadband: nothing; outside: limited, then shrunk by it
    assert tr["pid.0.output"].tolist() == pytest.approx([0.0, 0.2, -0.2])


def test_pid_saturation_holds_integrator(hal):
    _loop(hal, Pgain=100.0, Igain=1.0, maxoutput=2.0)
    tr = hal.run(4, inputs={"pid.0.command": 1.0},
                 record=["pid.0.output", "pid.0.saturated",
                         "pid.0.saturated-count", "pid.0.saturated-s",
                         "pid.0.errorI"])
    assert tr["pid.0.output"].tolist() == [2.0] * 4
    assert tr["pid.0.saturated-count"].tolist() == [1, 2, 3, 4]
    assert tr["pid.0.saturated-s"][-1] == pytest.approx(0.004)
    # only the first period integrates; then the output is at its limit
    assert tr["pid.0.errorI"].tolist() == pytest.approx([0.001] * 4)


def test_pid_disabled_output_zero_and_integrator_cleared(hal):
    _loop(hal, Pgain=1.0, Igain=1.0, bias=0.5)
    hal.run(3, inputs={"pid.0.command": 1.0})
    tr = hal.run(2, inputs={"pid.0.enable": [False, True],
                            "pid.0.command": 1.0},
                 record=["pid.0.output", "pid.0.errorI"])
    assert tr["pid.0.output"][0] == 0.0
    assert tr["pid.0.errorI"].tolist() == pytest.approx([0.0, 0.001])


def test_pid_derivatives_estimated_or_from_pins(hal):
    _loop(hal, Pgain=0.0, FF1=1.0)
    ramp = np.arange(1, 6) * 0.01
    tr = hal.run(5, inputs={"pid.0.command": ramp},
                 record=["pid.0.commandD", "pid.0.output"])
    assert tr["pid.0.commandD"].tolist() == pytest.approx([10.0] * 5)
    assert tr["pid.0.output"][-1] == pytest.approx(10.0)
    hal.newsig("v", "float")
    hal.linkps("pid.0.command-deriv", "v")
    hal.set({"v": 3.0})
    tr = hal.run(1, record=["pid.0.commandD"])
    assert tr["pid.0.commandD"][0] == 3.0


def test_pid_error_previous_target(hal):
    _loop(hal)
    hal.set({"pid.0.error-previous-target": True})
    tr = hal.run(2, inputs={"pid.0.command": [1.0, 2.0]},
                 record=["pid.0.error"])
    assert tr["pid.0.error"].tolist() == [0.0, 1.0]
