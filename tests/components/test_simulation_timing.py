"""Simulation and timing components: sim_encoder, sim_home_switch,
sim_spindle, sim_axis_hardware, watchdog, threadtest, time, timedelta and
latencybins.

Stepped runs are deterministic: a thread's functions see its nominal
period and the simulated clock (rtapi_get_time) advances by exactly one
period a cycle, so the clock-reading components (timedelta, latencybins)
measure no scheduling error at all, and their numbers are exact here.
The expected values come from the LinuxCNC 2.9 reference, observed with
``halrun`` (see tests/data/complib/ for the recorded runs)."""

from __future__ import annotations

import numpy as np
import pytest

import halsdk
from halsdk.core import _core

MS = 1_000_000


def names(items):
    return sorted(i.name for i in items)


# --- sim_encoder -------------------------------------------------------


def encoder_model(speeds, period_ns, ppr=100, scale=1.0):
    """Raw counts of a sim_encoder channel with update-speed running
    before make-pulses in one thread: a 32-bit phase accumulator steps
    each time it passes a multiple of 2^31; the first update-speed assumes
    a 50 us make-pulses period."""
    acc, add, raw, out = 0, 0, 0, []
    pulse_period = 50_000
    for speed in speeds:
        max_rate = 1e9 / pulse_period
        rate = speed * (1.0 / scale) * ppr * 4.0
        rate = min(max(rate, -max_rate), max_rate) * (2.0 ** 31 / max_rate)
        add = -2 ** 31 if rate >= 2.0 ** 31 or rate < -2.0 ** 31 else int(rate)
        before = acc
        acc = (acc + add) % 2 ** 32
        if (before ^ acc) & 0x80000000:
            raw += -1 if add < 0 else 1
        pulse_period = period_ns
        out.append(raw)
    return np.array(out)


def encoder_setup(hal, period=MS, **load):
    made = hal.loadrt("sim_encoder", **load)
    hal.newthread("t", period)
    hal.addf("sim-encoder.update-speed", "t")
    hal.addf("sim-encoder.make-pulses", "t")
    return made


def test_sim_encoder_interface(hal):
    encoder_setup(hal, num_chan=2)
    p = "sim-encoder.0."
    assert [(x.name, x.type, x.direction) for x in hal.pins("sim-encoder.0.*")] == [
        (p + "phase-A", _core.BIT, _core.OUT),
        (p + "phase-B", _core.BIT, _core.OUT),
        (p + "phase-Z", _core.BIT, _core.OUT),
        (p + "ppr", _core.U32, _core.IO),
        (p + "rawcounts", _core.S32, _core.IN),
        (p + "scale", _core.FLOAT, _core.IO),
        (p + "speed", _core.FLOAT, _core.IN)]
    assert hal.getp(p + "ppr") == 100 and hal.getp(p + "scale") == 1.0
    fp = {f.name: f.uses_fp for f in hal.functions()}
    assert fp == {"sim-encoder.make-pulses": False,
                  "sim-encoder.update-speed": True}
    assert hal.pins("sim-encoder.2.*") == []


def test_sim_encoder_counts_quadrature_and_index(hal):
    encoder_setup(hal)
    hal.setp("sim-encoder.0.ppr", 3)
    speeds = [10.0] * 150 + [-25.0] * 150
    tr = hal.run(300, inputs={"sim-encoder.0.speed": speeds},
                 record=["sim-encoder.0.rawcounts", "sim-encoder.0.phase-A",
                         "sim-encoder.0.phase-B", "sim-encoder.0.phase-Z"])
    raw = tr["sim-encoder.0.rawcounts"]
    np.testing.assert_array_equal(raw, encoder_model(speeds, MS, ppr=3))
    # 10 rev/s * 12 counts: 0.12 counts a cycle, then 0.3 down
    assert raw[149] == 17 and raw[-1] == 17 - 45
    # A and B follow the count: 10 11 01 00 10 ...
    quad = {0: (1, 0), 1: (1, 1), 2: (0, 1), 3: (0, 0)}
    for r, a, b in zip(raw, tr["sim-encoder.0.phase-A"],
                       tr["sim-encoder.0.phase-B"]):
        assert (a, b) == quad[r % 4]
    # the index: once per revolution of 12 counts
    np.testing.assert_array_equal(tr["sim-encoder.0.phase-Z"], raw % 12 == 0)


def test_sim_encoder_scale_rpm_and_rawcounts_offset(hal):
    encoder_setup(hal, period=100_000)
    hal.setp("sim-encoder.0.scale", 60)
    hal.setp("sim-encoder.0.rawcounts", 1000)
    tr = hal.run(500, inputs={"sim-encoder.0.speed": 600.0},
                 record=["sim-encoder.0.rawcounts"])
    want = 1000 + encoder_model([600.0] * 500, 100_000, scale=60)
    np.testing.assert_array_equal(tr["sim-encoder.0.rawcounts"], want)
    assert want[-1] == 1000 + 199         # 10 rev/s: 0.4 counts a cycle


def test_sim_encoder_limits_rate_and_fixes_tiny_scale(hal):
    encoder_setup(hal, num_chan=3)
    hal.setp("sim-encoder.0.speed", 1e6)      # far beyond 1000 counts/s
    hal.setp("sim-encoder.1.scale", 1e-30)
    hal.setp("sim-encoder.1.speed", 1.0)
    hal.setp("sim-encoder.2.scale", 0.0)       # before the first update
    hal.setp("sim-encoder.2.speed", 1.0)
    hal.step(20)
    # at the limit the add value overflows: one count down per cycle
    assert hal.getp("sim-encoder.0.rawcounts") == -20
    assert hal.getp("sim-encoder.1.scale") == 1.0
    assert hal.getp("sim-encoder.2.scale") == 0.0     # not noticed
    assert hal.getp("sim-encoder.1.rawcounts") == \
        hal.getp("sim-encoder.2.rawcounts") == encoder_model([1.0] * 20, MS)[-1]


def test_sim_encoder_load_errors_leave_nothing(hal):
    with pytest.raises(halsdk.HalError, match="invalid number of channels 9"):
        hal.loadrt("sim_encoder", num_chan=9)
    with pytest.raises(halsdk.HalError, match="mutually exclusive"):
        hal.loadrt("sim_encoder", num_chan=2, names="a")
    assert hal.components("sim_encoder") == []
    assert hal.pins() == [] and hal.functions() == []
    encoder_setup(hal, names="x,y")
    assert names(hal.pins("*.speed")) == ["x.speed", "y.speed"]


# --- sim_home_switch ---------------------------------------------------


def test_sim_home_switch_hysteresis_both_ends(hal):
    hal.loadrt("sim_home_switch", count=2)
    hal.newthread("t", MS)
    hal.addf("sim-home-switch.0", "t")
    hal.addf("sim-home-switch.1", "t")
    hal.setp("sim-home-switch.1.home-pos", -2.0)
    hal.setp("sim-home-switch.1.hysteresis", 0.5)
    pos = [0.0, 0.99, 1.0, 0.95, 0.91, 1.2, 0.9, 0.95]
    tr = hal.run(len(pos), inputs={"sim-home-switch.0.cur-pos": pos},
                 record=["sim-home-switch.0.home-sw"])
    assert list(tr["sim-home-switch.0.home-sw"]) == [0, 0, 1, 1, 1, 1, 0, 0]
    neg = [-1.0, -2.0, -1.75, -1.5, -2.5, -1.25]
    tr = hal.run(len(neg), inputs={"sim-home-switch.1.cur-pos": neg},
                 record=["sim-home-switch.1.home-sw"])
    assert list(tr["sim-home-switch.1.home-sw"]) == [0, 1, 1, 0, 1, 0]


def test_sim_home_switch_index_enable_delay(hal):
    hal.loadrt("sim_home_switch", count=3)
    hal.newthread("t", MS)
    for k, delay in enumerate((3.5, 1.0, 0.0)):
        hal.addf(f"sim-home-switch.{k}", "t")
        hal.setp(f"sim-home-switch.{k}.index-delay-ms", delay)
        hal.setp(f"sim-home-switch.{k}.index-enable", True)
    rec = [f"sim-home-switch.{k}.index-enable" for k in range(3)]
    tr = hal.run(8, record=rec)
    # cleared in the cycle at which the delay has passed; 0 never clears
    assert list(tr[rec[0]]) == [1, 1, 1, 1, 0, 0, 0, 0]
    assert list(tr[rec[1]]) == [1, 0, 0, 0, 0, 0, 0, 0]
    assert list(tr[rec[2]]) == [1] * 8
    # set again: a new delay starts
    hal.setp(rec[1], True)
    tr = hal.run(3, record=[rec[1]])
    assert list(tr[rec[1]]) == [1, 0, 0]


# --- sim_spindle -------------------------------------------------------


def test_sim_spindle_integrates_and_finds_index(hal):
    hal.loadrt("sim_spindle", count=2)
    hal.newthread("t", MS)
    hal.addf("sim-spindle.0", "t")
    hal.addf("sim-spindle.1", "t")
    hal.setp("sim-spindle.0.scale", 1 / 60)
    hal.setp("sim-spindle.0.velocity-cmd", 6000.0)       # RPM: 0.1 rev/ms
    tr = hal.run(25, record=["sim-spindle.0.position-fb"])
    assert tr["sim-spindle.0.position-fb"][-1] == pytest.approx(2.5)
    hal.setp("sim-spindle.0.index-enable", True)
    tr = hal.run(6, record=["sim-spindle.0.position-fb",
                            "sim-spindle.0.index-enable"])
    # 2.6 2.7 2.8 2.9 3.0 -> 0.0 at the next whole revolution
    assert list(tr["sim-spindle.0.index-enable"]) == [1, 1, 1, 1, 0, 0]
    assert tr["sim-spindle.0.position-fb"][4] == pytest.approx(0.0, abs=1e-9)
    # reverse: passes 0 going down, the whole revolution above is zero
    hal.setp("sim-spindle.1.velocity-cmd", -350.0)
    hal.setp("sim-spindle.1.index-enable", True)
    tr = hal.run(3, record=["sim-spindle.1.position-fb"])
    assert tr["sim-spindle.1.position-fb"] == pytest.approx([-0.35, -0.7,
                                                             -1.05])
    assert hal.getp("sim-spindle.1.index-enable") is False  # at 0
    hal.setp("sim-spindle.1.index-enable", True)
    tr = hal.run(3, record=["sim-spindle.1.position-fb"])
    assert tr["sim-spindle.1.position-fb"] == pytest.approx([-1.4, -1.75,
                                                             -0.1])
    assert hal.getp("sim-spindle.1.index-enable") is False


# --- sim_axis_hardware -------------------------------------------------


def axis_setup(hal):
    hal.loadrt("sim_axis_hardware")
    hal.newthread("t", MS)
    hal.addf("sim-axis-hardware.0.update", "t")
    p = "sim-axis-hardware.0."
    for j in ("X", "A"):
        hal.set({p + j + "maxsw-lower": 2.0, p + j + "maxsw-upper": 3.0,
                 p + j + "minsw-lower": -3.0, p + j + "minsw-upper": -2.0,
                 p + j + "homesw-hyst": 0.5})
    return p


def test_sim_axis_hardware_windows(hal):
    p = axis_setup(hal)
    outs = ["homesw-out", "maxsw-out", "minsw-out", "bothsw-out",
            "maxsw-homesw-out", "minsw-homesw-out", "bothsw-homesw-out"]
    cases = {
        1.25: [1, 0, 0, 0, 1, 1, 1],      # home: |pos - 1| <= 0.25
        1.26: [0, 0, 0, 0, 0, 0, 0],
        2.01: [0, 0, 0, 0, 0, 0, 0],      # max: above 2 + limit-offset
        2.02: [0, 1, 0, 1, 1, 0, 1],
        3.0: [0, 0, 0, 0, 0, 0, 0],
        -2.01: [0, 0, 0, 0, 0, 0, 0],     # min: below -2 - limit-offset
        -2.5: [0, 0, 1, 1, 0, 1, 1],
        -3.0: [0, 0, 0, 0, 0, 0, 0],
    }
    for pos, want in cases.items():
        hal.set({p + "Xcurrent-pos": pos, p + "Acurrent-pos": pos})
        hal.step(1)
        assert [int(hal.getp(p + "X" + o)) for o in outs] == want, pos
        # joint A: the same switches, but its combined outputs stay FALSE
        assert [int(hal.getp(p + "A" + o)) for o in outs] == want[:4] + \
            [0, 0, 0], pos
        assert hal.getp(p + "limitsw-all") == bool(want[3])
        assert hal.getp(p + "homesw-all") is False


def test_sim_axis_hardware_homing(hal):
    p = axis_setup(hal)
    hal.set({p + "Xcurrent-pos": -2.5, p + "Ycurrent-pos": 1.0,
             p + "Zhoming": True})
    hal.step(1)
    # any joint homing: no joint reports a limit in bothsw-out
    assert hal.getp(p + "Xminsw-out") is True
    assert hal.getp(p + "Xbothsw-out") is False
    assert hal.getp(p + "limitsw-all") is False
    # a joint on its home switch while some joint homes
    assert hal.getp(p + "homesw-all") is True
    assert hal.getp(p + "limitsw-homesw-all") is True
    hal.set({p + "Zhoming": False})
    hal.step(1)
    assert hal.getp(p + "Xbothsw-out") is True
    assert hal.getp(p + "homesw-all") is False
    assert hal.getp(p + "limitsw-homesw-all") is True


# --- watchdog ----------------------------------------------------------


def watchdog_setup(hal, n, timeouts):
    hal.loadrt("watchdog", num_inputs=n)
    hal.newthread("t", MS)
    hal.addf("watchdog.set-timeouts", "t")
    hal.addf("watchdog.process", "t")
    for k, t in enumerate(timeouts):
        hal.setp(f"watchdog.timeout-{k}", t)


def test_watchdog_interface_and_errors(hal):
    for args, msg in (({}, "must specify at least one input"),
                      ({"num_inputs": 33},
                       r"too many inputs requested \(33 > 32\)")):
        with pytest.raises(halsdk.HalError, match=msg):
            hal.loadrt("watchdog", **args)
        assert hal.components("watchdog") == [] and hal.pins() == []
    watchdog_setup(hal, 3, ())
    assert names(hal.pins("watchdog.*")) == [
        "watchdog.enable-in", "watchdog.input-0", "watchdog.input-1",
        "watchdog.input-2", "watchdog.ok-out", "watchdog.process.time",
        "watchdog.set-timeouts.time"]
    assert {f.name: f.uses_fp for f in hal.functions()} == {
        "watchdog.process": False, "watchdog.set-timeouts": True}
    assert hal.getp("watchdog.timeout-2") == 0.0


def test_watchdog_timeout_and_restart(hal):
    watchdog_setup(hal, 2, (0.0035, 0.1))
    toggle = [k % 2 for k in range(30)]
    en = [0] * 2 + [1] * 28
    stall = [k % 2 if k < 10 else 0 for k in range(30)]   # stops at 10
    tr = hal.run(30, inputs={"watchdog.enable-in": en,
                             "watchdog.input-0": stall,
                             "watchdog.input-1": toggle},
                 record=["watchdog.ok-out"])
    ok = list(tr["watchdog.ok-out"])
    # last change (1 -> 0) in cycle 10; more than 3.5 ms later in cycle 14
    assert ok[:14] == [0, 0] + [1] * 12
    assert ok[14:] == [0] * 16
    # changing again does not help; a new rising edge of enable-in does
    tr = hal.run(6, inputs={"watchdog.enable-in": [1, 0, 1, 1, 1, 1],
                            "watchdog.input-0": [1, 0, 1, 0, 1, 0],
                            "watchdog.input-1": [1, 0, 1, 0, 1, 0]},
                 record=["watchdog.ok-out"])
    assert list(tr["watchdog.ok-out"]) == [0, 0, 1, 1, 1, 1]


# --- threadtest --------------------------------------------------------


def test_threadtest_counts_and_resets(hal):
    hal.loadrt("threadtest", count=2)
    hal.newthread("fast", MS)
    hal.newthread("slow", 4 * MS)
    hal.addf("threadtest.0.increment", "fast")
    hal.addf("threadtest.0.reset", "slow")
    hal.addf("threadtest.1.increment", "fast")
    assert {f.name: f.uses_fp for f in hal.functions()} == {
        "threadtest.0.increment": False, "threadtest.0.reset": False,
        "threadtest.1.increment": False, "threadtest.1.reset": False}
    tr = hal.run(12, record=["threadtest.0.count", "threadtest.1.count"])
    np.testing.assert_array_equal(tr["threadtest.1.count"], np.arange(1, 13))
    # the slow thread runs in every fourth cycle, after the fast one
    assert list(tr["threadtest.0.count"]) == [1, 2, 3, 0] * 3


# --- time --------------------------------------------------------------


def test_time_hours_minutes_seconds(hal):
    hal.loadrt("time")
    hal.newthread("t", 250 * MS)
    hal.addf("time.0", "t")
    hal.setp("time.0.start", True)
    hal.step(4 * 3725)                     # 1 h 2 min 5 s
    assert (hal.getp("time.0.hours"), hal.getp("time.0.minutes"),
            hal.getp("time.0.seconds")) == (1, 2, 5)
    hal.step(3)                            # 0.75 s more: still 5 s
    assert hal.getp("time.0.seconds") == 5


def test_time_pause_and_restart(hal):
    hal.loadrt("time")
    hal.newthread("t", 100 * MS)
    hal.addf("time.0", "t")
    seq = [(1, 0)] * 25 + [(1, 1)] * 30 + [(1, 0)] * 5 + [(0, 0)] * 5 + \
        [(0, 1)] * 3 + [(1, 0)] * 12
    tr = hal.run(len(seq), inputs={"time.0.start": [s for s, _ in seq],
                                   "time.0.pause": [p for _, p in seq]},
                 record=["time.0.seconds"])
    sec = list(tr["time.0.seconds"])
    assert sec[24] == 2 and sec[54] == 2   # pause holds the count
    assert sec[59] == 3                    # 30 counted periods
    assert sec[60:68] == [3] * 8           # shown until counting resumes
    assert sec[68] == 0 and sec[-1] == 1   # pause rose from idle: zero


# --- timedelta ---------------------------------------------------------


TD = ["out", "err", "min", "max", "jitter", "current-jitter",
      "current-error", "avg-err"]


def test_timedelta_exact_clock(hal):
    hal.loadrt("timedelta", count=2)
    hal.newthread("fast", MS)
    hal.newthread("slow", 2_500_000)
    hal.addf("timedelta.0", "fast")
    hal.addf("timedelta.1", "slow")
    assert [f.uses_fp for f in hal.functions()] == [False, False]
    tr = hal.run(10, record=[f"timedelta.0.{p}" for p in TD])
    assert tr["timedelta.0.out"][0] == 0           # first run: clock only
    assert list(tr["timedelta.0.out"][1:]) == [MS] * 9
    assert tr["timedelta.0.min"][-1] == tr["timedelta.0.max"][-1] == MS
    for p in ("err", "jitter", "current-jitter", "current-error", "avg-err"):
        assert not tr[f"timedelta.0.{p}"].any(), p
    assert hal.getp("timedelta.1.out") == 2_500_000


def test_timedelta_reset(hal):
    hal.loadrt("timedelta")
    hal.newthread("t", MS)
    hal.addf("timedelta.0", "t")
    hal.step(5)
    tr = hal.run(4, inputs={"timedelta.0.reset": [1, 1, 0, 0]},
                 record=[f"timedelta.0.{p}" for p in TD])
    assert list(tr["timedelta.0.out"]) == [0, 0, 0, MS]
    assert list(tr["timedelta.0.max"]) == [0, 0, 0, MS]
    assert list(tr["timedelta.0.min"]) == [MS] * 4   # not reset


# --- latencybins -------------------------------------------------------


def test_latencybins_interface_and_defaults(hal):
    hal.loadrt("latencybins")
    assert hal.getp("latencybins.0.availablebins") == 1000
    assert hal.getp("latencybins.0.maxbinnumber") == 1000
    assert names(hal.pins()) == sorted(
        f"latencybins.0.{p}" for p in (
            "maxbinnumber", "index", "reset", "nsbinsize", "check",
            "latency", "latency-max", "latency-min", "pbinvalue",
            "nbinvalue", "pextra", "nextra", "variance", "availablebins",
            "time"))


def test_latencybins_counts_zero_latency(hal):
    hal.loadrt("latencybins", count=2)
    hal.newthread("t", MS)
    hal.addf("latencybins.0", "t")
    hal.addf("latencybins.1", "t")
    hal.setp("latencybins.0.nsbinsize", 1000)
    hal.setp("latencybins.0.index", 0)
    hal.setp("latencybins.1.index", 7)         # nsbinsize 0: no measuring
    rec = ["latencybins.0.pbinvalue", "latencybins.0.nbinvalue",
           "latencybins.0.latency", "latencybins.0.variance",
           "latencybins.1.pbinvalue", "latencybins.1.check",
           "latencybins.1.latency-max", "latencybins.1.latency-min"]
    tr = hal.run(10, record=rec)
    # every latency is 0: bin 0, counted from the second run on
    np.testing.assert_array_equal(tr[rec[0]], np.arange(10))
    assert not tr[rec[1]].any() and not tr[rec[2]].any()
    assert not tr[rec[3]].any()
    assert hal.getp("latencybins.0.latency-max") == 0
    assert hal.getp("latencybins.0.latency-min") == 0
    assert not tr[rec[4]].any() and set(tr[rec[5]]) == {7}
    assert tr[rec[6]][-1] == -2 ** 31 and tr[rec[7]][-1] == 2 ** 31 - 1
    # out of range reads -1; reset clears, and the next run counts again
    hal.set({"latencybins.0.index": 1001})
    hal.step(1)
    assert hal.getp("latencybins.0.pbinvalue") == -1
    assert hal.getp("latencybins.0.check") == 1001
    tr = hal.run(3, inputs={"latencybins.0.index": 0,
                            "latencybins.0.reset": [1, 0, 0]},
                 record=[rec[0]])
    assert list(tr[rec[0]]) == [0, 1, 2]
