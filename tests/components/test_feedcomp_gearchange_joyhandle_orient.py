"""Unit tests of the shipped components feedcomp, gearchange, joyhandle and
orient: behaviour stated in Python, with numbers observed on the LinuxCNC
2.9 reference (the differential tests in tests/data/complib compare whole runs)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.components import setup

import halsdk
from halsdk.core import _core

# feedcomp ----------------------------------------------------------------

def test_feedcomp_scales_by_velocity_over_feed(hal):
    setup(hal, "feedcomp", "feedcomp.0")
    hal.set({"feedcomp.0.feed": 100.0, "feedcomp.0.in": 5.0,
             "feedcomp.0.enable": True})
    tr = hal.run(4, inputs={"feedcomp.0.vel": [100.0, 50.0, 0.0, -25.0]},
                 record=["feedcomp.0.out"])
    assert list(tr["feedcomp.0.out"]) == [5.0, 2.5, 0.0, -1.25]


def test_feedcomp_disabled_passes_input(hal):
    setup(hal, "feedcomp", "feedcomp.0")
    hal.set({"feedcomp.0.feed": 100.0, "feedcomp.0.vel": 10.0,
             "feedcomp.0.in": -7.5})
    hal.step(1)
    assert hal.getp("feedcomp.0.out") == -7.5
    hal.set({"feedcomp.0.enable": True})
    hal.step(1)
    assert hal.getp("feedcomp.0.out") == -0.75


def test_feedcomp_zero_feed_divides_by_zero(hal):
    """The default feed of 0 gives inf (or NaN for 0/0), as the reference."""
    setup(hal, "feedcomp", "feedcomp.0")
    hal.set({"feedcomp.0.enable": True, "feedcomp.0.in": 5.0,
             "feedcomp.0.vel": 50.0})
    hal.step(1)
    assert hal.getp("feedcomp.0.out") == math.inf
    hal.set({"feedcomp.0.vel": 0.0})
    hal.step(1)
    assert math.isnan(hal.getp("feedcomp.0.out"))


def test_feedcomp_interface(hal):
    hal.loadrt("feedcomp", "names=laser")
    pins = {(p.name, p.type, p.direction) for p in hal.pins("laser.*")}
    assert {("laser.in", _core.FLOAT, _core.IN),
            ("laser.vel", _core.FLOAT, _core.IN),
            ("laser.enable", _core.BIT, _core.IN),
            ("laser.out", _core.FLOAT, _core.OUT)} <= pins
    assert hal.getp("laser.feed") == 0.0


# gearchange --------------------------------------------------------------

def gears(hal, **params):
    setup(hal, "gearchange", "gearchange.0")
    hal.set({f"gearchange.0.{k}": v for k, v in params.items()})


def test_gearchange_gear1_limits_magnitude_keeping_sign(hal):
    gears(hal, min1=100.0, max1=1000.0)
    speeds = [0.0, 50.0, 500.0, 1500.0, -50.0, -5000.0]
    tr = hal.run(len(speeds), inputs={"gearchange.0.speed-in": speeds},
                 record=["gearchange.0.speed-out"])
    assert list(tr["gearchange.0.speed-out"]) == [
        100.0, 100.0, 500.0, 1000.0, -100.0, -1000.0]


def test_gearchange_gear2_limits_then_divides_by_scale2(hal):
    gears(hal, min2=500.0, max2=3000.0, scale2=2.5, sel=True)
    speeds = [0.0, 1000.0, 4000.0, -100.0]
    tr = hal.run(len(speeds), inputs={"gearchange.0.speed-in": speeds},
                 record=["gearchange.0.speed-out"])
    assert list(tr["gearchange.0.speed-out"]) == [200.0, 400.0, 1200.0,
                                                  -200.0]


def test_gearchange_reverse_inverts_direction_in_gear2_only(hal):
    gears(hal, reverse=True, **{"dir-in": True})
    tr = hal.run(3, inputs={"gearchange.0.sel": [False, True, False]},
                 record=["gearchange.0.dir-out"])
    assert list(tr["gearchange.0.dir-out"]) == [True, False, True]


def test_gearchange_scale2_below_one_is_set_back(hal):
    gears(hal, scale2=0.5, sel=True, **{"speed-in": 700.0})
    hal.step(1)
    assert hal.getp("gearchange.0.scale2") == 1.0
    assert hal.getp("gearchange.0.speed-out") == 700.0


def test_gearchange_lower_limit_applies_first(hal):
    """With max below min the maximum wins (the reference's order)."""
    gears(hal, min2=0.0, max2=-10.0, sel=True)
    tr = hal.run(2, inputs={"gearchange.0.speed-in": [100.0, -100.0]},
                 record=["gearchange.0.speed-out"])
    assert list(tr["gearchange.0.speed-out"]) == [-10.0, 10.0]


# joyhandle ---------------------------------------------------------------

def joy(hal, xs, **params):
    setup(hal, "joyhandle", "joyhandle.0")
    hal.set({f"joyhandle.0.{k}": v for k, v in params.items()})
    tr = hal.run(len(xs), inputs={"joyhandle.0.in": xs},
                 record=["joyhandle.0.out"])
    return tr["joyhandle.0.out"]


def test_joyhandle_default_is_signed_square(hal):
    out = joy(hal, [0.0, 0.5, -0.5, 0.9, 1.5, -2.0])
    assert out == pytest.approx([0.0, 0.25, -0.25, 0.81, 1.0, -1.0])


def test_joyhandle_curve_runs_from_deadband_to_full_scale(hal):
    d, p, s, o = 0.1, 3.0, 2.0, 0.5
    a = 1 / (1 - d ** (p - 1))
    xs = np.array([0.1, 0.15, 0.5, 0.99, 1.0, -0.5])
    out = joy(hal, xs, deadband=d, power=p, scale=s, offset=o)
    curve = s * (a * np.abs(xs) ** p + (1 - a) * np.abs(xs)) + o
    expect = np.sign(xs) * curve
    expect[0] = 0.0                     # |x| <= deadband gives 0
    expect[4] = s + o
    assert out == pytest.approx(expect)


def test_joyhandle_power_one_is_linear_after_deadband(hal):
    out = joy(hal, [0.2, 0.6, -0.6, 0.1], power=1.0, deadband=0.2,
              scale=2.0, offset=0.5, inverse=True)
    assert out == pytest.approx([0.0, 1.5, -1.5, 0.0])


def test_joyhandle_inverse_is_progressive(hal):
    out = joy(hal, [0.05, 0.5, 1e-6], inverse=True)
    assert out == pytest.approx([0.0975, 0.75, 2e-6])


def test_joyhandle_inverse_negative_side_as_reference(hal):
    """Negative deflections with inverse: -scale*(1 + c) - 3*offset."""
    out = joy(hal, [-0.5, -1.0], inverse=True, scale=3.0, offset=-0.1)
    assert out == pytest.approx([-3.45, -2.9])


def test_joyhandle_parameters_are_corrected(hal):
    joy(hal, [0.0], power=0.5, deadband=2.0)
    assert hal.getp("joyhandle.0.power") == 1.0
    assert hal.getp("joyhandle.0.deadband") == 0.99
    hal.set({"joyhandle.0.deadband": -1.0})
    hal.step(1)
    assert hal.getp("joyhandle.0.deadband") == 0.0


# orient ------------------------------------------------------------------

def orient_cmd(hal, position, angle, mode):
    """Command computed on a rising edge of enable."""
    hal.set({"orient.0.enable": False})
    hal.step(1)
    hal.set({"orient.0.position": position, "orient.0.angle": angle,
             "orient.0.mode": mode, "orient.0.enable": True})
    hal.step(1)
    return hal.getp("orient.0.command")


@pytest.mark.parametrize("position, angle, mode, command", [
    (2.3, 90.0, 0, 2.25),       # nearer way: back
    (2.9, 90.0, 0, 3.25),       # nearer way: forward
    (2.1, 300.0, 0, 1.8333333333333333),
    (1.5, 0.0, 0, 2.0),         # half a revolution behind: forward
    (1.5, 360.0, 0, 2.0),       # half a revolution ahead: stays
    (2.3, 90.0, 1, 3.25),       # always forward
    (2.2, 90.0, 1, 2.25),
    (2.3, 90.0, 2, 2.25),       # always backward
    (2.2, 90.0, 2, 1.25),
    (-2.3, 90.0, 0, -2.75),
    (-2.3, 90.0, 1, -1.75),
    (-0.9, 270.0, 0, -1.25),
])
def test_orient_command_on_rising_edge(hal, position, angle, mode, command):
    setup(hal, "orient", "orient.0")
    assert orient_cmd(hal, position, angle, mode) == pytest.approx(command)


def test_orient_command_holds_and_poserr_follows_while_enabled(hal):
    setup(hal, "orient", "orient.0")
    assert orient_cmd(hal, 2.3, 90.0, 0) == 2.25
    tr = hal.run(3, inputs={"orient.0.position": [2.4, 2.25, 2.0],
                            "orient.0.enable": [True, True, False]},
                 record=["orient.0.command", "orient.0.poserr"])
    assert list(tr["orient.0.command"]) == [2.25, 2.25, 2.25]
    # poserr is kept while disabled
    assert tr["orient.0.poserr"] == pytest.approx([54.0, 0.0, 0.0])


def test_orient_unknown_mode_keeps_command(hal):
    setup(hal, "orient", "orient.0")
    orient_cmd(hal, 2.3, 90.0, 0)
    assert orient_cmd(hal, 5.5, 45.0, 3) == 2.25
    assert hal.getp("orient.0.poserr") == pytest.approx(1170.0)


def test_orient_is_oriented_stays_false_as_reference(hal):
    setup(hal, "orient", "orient.0")
    hal.set({"orient.0.tolerance": 1000.0})
    orient_cmd(hal, 0.3, 108.0, 0)
    assert hal.getp("orient.0.poserr") == 0.0
    assert hal.getp("orient.0.is-oriented") is False


def test_orient_interface(hal):
    hal.loadrt("orient", "names=spo")
    pins = {p.name: (p.type, p.direction) for p in hal.pins("spo.*")}
    assert pins["spo.mode"] == (_core.S32, _core.IN)
    assert pins["spo.is-oriented"] == (_core.BIT, _core.OUT)
    assert hal.getp("spo.tolerance") == 0.5
    with pytest.raises(halsdk.HalError):
        hal.loadrt("orient", "count=1", "names=a")
