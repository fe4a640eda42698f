"""Unit tests of the shipped components spindle and bldc: behaviour stated
in Python, with numbers observed on the LinuxCNC 2.9 reference (the
differential tests in tests/data/complib compare whole runs)."""

from __future__ import annotations

import numpy as np
import pytest

import halsdk

PERIOD = 10_000_000     # 10 ms: a rate of 1000/s is a step of 10


def setup(hal, comp, *funct, args=()):
    hal.loadrt(comp, *args)
    hal.newthread("t", PERIOD)
    for f in funct:
        hal.addf(f, "t")


# spindle -----------------------------------------------------------------

SP = "spindle.0."


def spindle(hal, *args, **gear):
    setup(hal, "spindle", "spindle.0", args=args)
    hal.set({SP + "enable": True})
    hal.set({f"{SP}{k}.0": v for k, v in gear.items()})


def test_spindle_gear_pins_follow_numgears(hal):
    hal.loadrt("spindle", "count=3", "numgears=3,2")
    for n, gears in ((0, 3), (1, 2), (2, 1)):
        for g in range(gears):
            assert hal.getp(f"spindle.{n}.scale.{g}") == 1.0
            assert hal.getp(f"spindle.{n}.speed-tolerance.{g}") == 20.0
            assert hal.getp(f"spindle.{n}.zero-tolerance.{g}") == 20.0
        with pytest.raises(halsdk.HalError):
            hal.getp(f"spindle.{n}.scale.{gears}")
    # only a lone gear starts selected
    assert hal.getp("spindle.2.select.0") is True
    assert hal.getp("spindle.0.select.0") is False


@pytest.mark.parametrize("arg", ["numgears=17", "numgears=0", "numgears=-1"])
def test_spindle_refuses_bad_numgears(hal, arg):
    with pytest.raises(halsdk.HalError, match="Number of gears is out of range"):
        hal.loadrt("spindle", arg)
    with pytest.raises(halsdk.HalError):
        hal.getp("spindle.0.enable")


def test_spindle_simulated_ramp_is_a_rate(hal):
    spindle(hal, accel=1000.0, decel=2000.0)
    hal.set({SP + "simulate-encoder": True, SP + "commanded-speed": 100.0})
    tr = hal.run(10, record=[SP + "spindle-rpm", SP + "at-speed",
                             SP + "spindle-rpm-abs"])
    # 10 RPM a period; within speed-tolerance (20) it goes to the target
    assert list(tr[SP + "spindle-rpm"]) == [10, 20, 30, 40, 50, 60, 70, 80,
                                           100, 100]
    assert list(tr[SP + "at-speed"]).index(True) == 8
    # the "measured" speed is the one sent a period before
    assert tr[SP + "spindle-rpm-abs"][8] == 80.0
    hal.set({SP + "commanded-speed": -100.0})
    tr = hal.run(6, record=[SP + "spindle-rpm", SP + "forward",
                            SP + "reverse"])
    # down at 20 a period, stop at 0, then up in reverse at 10 a period
    assert list(tr[SP + "spindle-rpm"]) == [80, 60, 40, 20, 0, -10]
    assert list(tr[SP + "forward"]) == [True] * 4 + [False] * 2
    assert list(tr[SP + "reverse"]) == [False] * 5 + [True]


def test_spindle_encoder_steps_from_measured_speed(hal):
    spindle(hal, accel=100.0, decel=200.0, offset=5.0, scale=2.0)
    hal.set({SP + "commanded-speed": 1000.0})
    tr = hal.run(4, inputs={SP + "actual-speed": [0.0, 1.0, 16.0, 17.0]},
                 record=[SP + "output", SP + "spindle-rpm"])
    # output = (measured RPM + accel, at most the command + offset) * scale
    assert list(tr[SP + "output"]) == [210.0, 330.0, 2010.0, 2010.0]
    assert list(tr[SP + "spindle-rpm"]) == [0.0, 60.0, 960.0, 1020.0]


def test_spindle_slows_to_zero_before_reversing(hal):
    spindle(hal, accel=100.0, decel=200.0)
    hal.set({SP + "commanded-speed": -500.0, SP + "actual-speed": 2.0})
    hal.step(1)
    assert hal.getp(SP + "output") == 0.0      # 120 - 200 stops at 0
    assert not hal.getp(SP + "forward") and not hal.getp(SP + "reverse")
    hal.set({SP + "actual-speed": -5.0})
    hal.step(1)
    assert hal.getp(SP + "output") == 400.0
    assert hal.getp(SP + "reverse")


def test_spindle_limits(hal):
    spindle(hal, accel=0.0, decel=0.0, min=30.0, max=3000.0)
    for cmd, out, lim in ((10.0, 30.0, True), (-10.0, 30.0, True),
                          (0.0, 0.0, False), (5000.0, 3000.0, True),
                          (-5000.0, 3000.0, True), (1000.0, 1000.0, False)):
        hal.set({SP + "commanded-speed": cmd})
        hal.step(1)
        # accel and decel 0: no ramp, straight to the limited target
        assert hal.getp(SP + "output") == out
        assert hal.getp(SP + "limited") is lim
    hal.set({SP + "max.0": 0.0, SP + "commanded-speed": 9000.0})
    hal.step(1)
    assert hal.getp(SP + "output") == 9000.0    # max 0: no upper limit


def test_spindle_disable_stops_and_counts_as_zero(hal):
    spindle(hal, accel=100.0, decel=200.0, max=1000.0)
    hal.set({SP + "commanded-speed": 5000.0, SP + "enable": False,
             SP + "actual-speed": 5.0})
    hal.step(1)
    assert hal.getp(SP + "output") == 100.0
    assert hal.getp(SP + "limited") is False
    assert not hal.getp(SP + "forward")
    hal.set({SP + "actual-speed": 0.3})         # 18 RPM: at "speed" 0
    hal.step(1)
    assert hal.getp(SP + "at-speed") and hal.getp(SP + "zero-speed")


def test_spindle_gear_selection(hal):
    spindle(hal, "numgears=3")
    hal.set({SP + "commanded-speed": 100.0, SP + "scale.1": 2.0,
             SP + "scale.2": -3.0})
    cases = [(0, (0, 0, 0), 0), (0, (0, 1, 0), 1), (0, (1, 1, 1), 2),
             (1, (0, 0, 1), 1), (2, (1, 0, 0), 2)]
    for sel, bits, gear in cases:
        hal.set({SP + "select-gear": sel})
        hal.set({f"{SP}select.{i}": bool(b) for i, b in enumerate(bits)})
        hal.step(1)
        assert hal.getp(SP + "current-gear") == gear
        assert hal.getp(SP + "output") == 100.0 * (1, 2, -3)[gear]


def test_spindle_lpf_smooths_abs_while_at_speed(hal):
    spindle(hal, accel=100.0, decel=200.0, **{"speed-tolerance": 50.0})
    hal.set({SP + "commanded-speed": 1000.0, SP + "spindle-lpf": 5.0})
    rpm = np.array([1000.0, 1010.0, 990.0, 900.0, 1040.0])
    tr = hal.run(5, inputs={SP + "actual-speed": rpm / 60},
                 record=[SP + "spindle-rpm-abs"])
    # first period not yet at speed: raw; then 5/s * 10 ms = 5 % a period,
    # judged by the at-speed of the period before
    assert list(tr[SP + "spindle-rpm-abs"][:3]) == pytest.approx(
        [1000.0, 1000.5, 999.975])
    assert tr[SP + "spindle-rpm-abs"][3] == pytest.approx(
        999.975 + (900 - 999.975) * 0.05)
    assert tr[SP + "spindle-rpm-abs"][4] == 1040.0


def test_spindle_zero_command_keeps_forward_only(hal):
    spindle(hal, accel=100.0, decel=200.0)
    hal.set({SP + "commanded-speed": 100.0, SP + "actual-speed": 1.0})
    hal.step(1)
    hal.set({SP + "commanded-speed": 0.0, SP + "actual-speed": 6.0})
    hal.step(1)
    assert hal.getp(SP + "forward")             # slowing down from forward
    hal.set({SP + "commanded-speed": -100.0, SP + "actual-speed": -1.0})
    hal.step(1)
    assert hal.getp(SP + "reverse")
    hal.set({SP + "commanded-speed": 0.0, SP + "actual-speed": -6.0})
    hal.step(1)
    assert not hal.getp(SP + "reverse") and not hal.getp(SP + "forward")
    assert hal.getp(SP + "brake") is False


# bldc --------------------------------------------------------------------

def bldc(hal, cfg, n=1):
    hal.loadrt("bldc", f"cfg={cfg}")
    hal.newthread("t", 1_000_000)
    for i in range(n):
        hal.addf(f"bldc.{i}", "t")


def test_bldc_pins_follow_the_letters(hal):
    hal.loadrt("bldc", "cfg=n,h,a,qi6,aB,fH")
    assert hal.getp("bldc.0.frequency") == 0.0
    assert hal.getp("bldc.1.pattern") == 25
    assert hal.getp("bldc.2.scale") == 512 and hal.getp("bldc.2.poles") == 4
    assert hal.getp("bldc.2.lead-angle") == 90.0
    assert hal.getp("bldc.3.initvalue") == pytest.approx(0.2)
    assert hal.getp("bldc.3.A-high") == 0.0
    assert hal.getp("bldc.4.A-on") is False
    assert hal.getp("bldc.5.output-pattern") == 25
    for missing in ("bldc.0.hall1", "bldc.1.frequency", "bldc.2.init",
                    "bldc.4.A-value", "bldc.5.A-value", "bldc.3.A-value"):
        with pytest.raises(halsdk.HalError):
            hal.getp(missing)


def test_bldc_refuses_count_and_too_many(hal):
    with pytest.raises(halsdk.HalError, match="count=2"):
        hal.loadrt("bldc", "count=2")
    with pytest.raises(halsdk.HalError, match="can only take 8 arguments"):
        hal.loadrt("bldc", "cfg=" + ",".join("n" * 9))


def test_bldc_first_period_sets_up(hal):
    bldc(hal, "n")
    hal.set({"bldc.0.value": 1.0, "bldc.0.frequency": 100.0})
    assert hal.getp("bldc.0.in-type") == -1
    hal.step(1)
    assert hal.getp("bldc.0.in-type") == 0
    assert hal.getp("bldc.0.out-type") == 0
    assert hal.getp("bldc.0.A-value") == 0.0      # nothing driven yet
    assert hal.getp("bldc.0.out-abs") == 1.0


def test_bldc_free_running_field(hal):
    bldc(hal, "n")
    hal.set({"bldc.0.value": -2.0, "bldc.0.frequency": 100.0})
    hal.step(1)
    tr = hal.run(3, record=["bldc.0.phase-angle", "bldc.0.A-value",
                            "bldc.0.B-value", "bldc.0.C-value",
                            "bldc.0.out", "bldc.0.out-dir"])
    # 100 Hz at 1 ms: a tenth of a revolution a period
    assert tr["bldc.0.phase-angle"] == pytest.approx([0.1, 0.2, 0.3])
    ph = np.array([0.1, 0.2, 0.3]) * 2 * np.pi
    assert tr["bldc.0.A-value"] == pytest.approx(2 * np.cos(ph))
    assert tr["bldc.0.B-value"] == pytest.approx(2 * np.cos(ph - 2 * np.pi / 3))
    assert tr["bldc.0.C-value"] == pytest.approx(2 * np.cos(ph + 2 * np.pi / 3))
    assert list(tr["bldc.0.out"]) == [-2.0] * 3
    assert all(tr["bldc.0.out-dir"])


def test_bldc_hall_block_commutation(hal):
    bldc(hal, "h")
    hal.set({"bldc.0.value": 1.0})
    hal.step(1)
    # pattern 25: Hall states for B-A, C-A, C-B, A-B, A-C, B-C
    states = [(1, 0, 1), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)]
    drive = [(-1, 1, 0), (-1, 0, 1), (0, -1, 1), (1, -1, 0), (1, 0, -1),
             (0, 1, -1)]
    for (h1, h2, h3), abc in zip(states, drive):
        hal.set({"bldc.0.hall1": bool(h1), "bldc.0.hall2": bool(h2),
                 "bldc.0.hall3": bool(h3)})
        hal.step(1)
        got = tuple(hal.getp(f"bldc.0.{p}-value") for p in "ABC")
        assert got == abc
    assert hal.getp("bldc.0.hall-error") is False
    hal.set({"bldc.0.rev": True})              # reversed: the opposite pair
    hal.step(1)
    assert tuple(hal.getp(f"bldc.0.{p}-value") for p in "ABC") == (0, -1, 1)
    hal.set({"bldc.0.hall1": False, "bldc.0.hall3": False})   # 000
    hal.step(1)
    assert tuple(hal.getp(f"bldc.0.{p}-value") for p in "ABC") == (0, 0, 0)
    assert hal.getp("bldc.0.hall-error") is True
    hal.set({"bldc.0.hall1": True, "bldc.0.hall3": True})     # valid again
    hal.step(1)
    assert hal.getp("bldc.0.hall-error") is True              # it stays


def test_bldc_absolute_encoder_angle(hal):
    bldc(hal, "a")
    hal.set({"bldc.0.value": 1.0, "bldc.0.poles": 6, "bldc.0.scale": 1000,
             "bldc.0.encoder-offset": 10})
    hal.set({"bldc.0.rawcounts": 100})
    hal.step(1)
    tr = hal.run(3, inputs={"bldc.0.rawcounts": [100, 150, 200]},
                 record=["bldc.0.rotor-angle", "bldc.0.phase-angle"])
    # (counts + half the last change - offset) * poles / 2 / scale
    assert tr["bldc.0.rotor-angle"] == pytest.approx([0.27, 0.495, 0.645])
    assert tr["bldc.0.phase-angle"] == pytest.approx([0.52, 0.745, 0.895])
    hal.set({"bldc.0.value": -1.0})
    hal.step(1)
    # no change of count this period: (200 - 10) * 3 / 1000, minus the lead
    assert hal.getp("bldc.0.phase-angle") == pytest.approx(0.57 - 0.25)


def test_bldc_emulated_outputs(hal):
    bldc(hal, "nH,nF", n=2)
    for i in range(2):
        hal.set({f"bldc.{i}.value": 1.0, f"bldc.{i}.frequency": 100.0})
    hal.step(1)
    hall, code = [], []
    for _ in range(10):
        hal.step(1)
        hall.append(tuple(int(hal.getp(f"bldc.0.hall{k}-out"))
                          for k in (1, 2, 3)))
        c = sum(int(hal.getp(f"bldc.1.C{b}-out")) << i
                for i, b in enumerate((1, 2, 4, 8)))
        code.append(c ^ (c >> 1) ^ (c >> 2) ^ (c >> 3))
    # Gray code: sixteenths of the angle, an exact one counting below
    assert code == [1, 3, 4, 6, 7, 9, 11, 12, 14, 15]
    # Halls of pattern 25 at the nearest sixth
    assert hall[0] == (1, 0, 0) and hall[2] == (1, 1, 0)


def test_bldc_combinations_messages(hal, capfd):
    bldc(hal, "ai,i", n=2)
    hal.set({"bldc.0.value": 1.0, "bldc.1.value": 1.0})
    hal.step(3)
    err = capfd.readouterr().err
    assert "Index is not needed with an Absoluteencoder" in err
    assert "only an index for feedback is notpossible" in err
    assert hal.getp("bldc.0.in-type") == 2
    assert hal.getp("bldc.1.in-type") == -2
    assert hal.getp("bldc.1.out") == 0.0        # disabled: nothing driven


def test_bldc_qh_homes_on_first_hall_edge(hal):
    bldc(hal, "qh")
    hal.set({"bldc.0.value": 1.0, "bldc.0.hall1": True,
             "bldc.0.hall3": True})                     # 101: B-A
    hal.step(2)
    assert hal.getp("bldc.0.A-value") == -1.0          # block commutation
    hal.set({"bldc.0.rawcounts": 23, "bldc.0.hall3": False})   # 100: edge
    hal.step(1)
    # the edge between the first two sectors is at a quarter revolution:
    # 64 counts of 256 per electrical revolution
    assert hal.getp("bldc.0.rotor-angle") == pytest.approx(0.25)
    assert hal.getp("bldc.0.offset-measured") == 23 - 64
    hal.set({"bldc.0.rawcounts": 27})
    hal.step(1)
    # now the encoder: 27 + 4 / 2 + 41 counts, sine outputs with lead 90
    assert hal.getp("bldc.0.rotor-angle") == pytest.approx(70 / 256)
    assert hal.getp("bldc.0.A-value") == pytest.approx(
        np.cos(2 * np.pi * (70 / 256 + 0.25)))
