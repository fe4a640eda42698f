"""The timing-logic components: edge, flipflop, oneshot, toggle,
toggle2nist, debounce, dbounce, timedelay, tof, ton, multiclick,
multiswitch and estop_latch.

Stepped one 1 ms period at a time; the expected numbers are the ones the
LinuxCNC 2.9 reference gives for the same inputs (see the differential tests
in ``tests/data/complib``)."""

from __future__ import annotations

import numpy as np
import pytest

import halsdk

MS = 1_000_000


def start(hal, comp, count=1, fp=True):
    """Load COUNT instances of COMP and add their functions, in name
    order, to a 1 ms thread ``t``; return the function names."""
    hal.loadrt(comp, count=count)
    hal.newthread("t", MS, fp=fp)
    names = sorted(f.name for f in hal.functions())
    for name in names:
        hal.addf(name, "t")
    return names


def bits(values):
    return [bool(v) for v in values]


# ------------------------------------------------------------------ edge

def test_edge_pulse_width_is_rounded_up_to_whole_periods(hal):
    start(hal, "edge", fp=False)
    hal.setp("edge.0.in-edge", False)           # rising
    hal.setp("edge.0.out-width-ns", 2_500_000)
    tr = hal.run(7, inputs={"edge.0.in": [0, 1, 1, 1, 1, 1, 1]},
                 record=["edge.0.out", "edge.0.out-invert",
                         "edge.0.time-left-ns"])
    assert bits(tr["edge.0.out"]) == bits([0, 1, 1, 1, 0, 0, 0])
    assert bits(tr["edge.0.out-invert"]) == bits([1, 0, 0, 0, 1, 1, 1])
    assert tr["edge.0.time-left-ns"].tolist() == [
        0, 2_500_000, 1_500_000, 500_000, 0, 0, 0]
    assert hal.functions()[0].uses_fp is False


def test_edge_default_is_falling_and_one_period_long(hal):
    start(hal, "edge", fp=False)
    assert hal.getp("edge.0.in-edge") is True
    tr = hal.run(6, inputs={"edge.0.in": [1, 1, 0, 0, 1, 0]},
                 record=["edge.0.out", "edge.0.last-in"])
    assert bits(tr["edge.0.out"]) == bits([0, 0, 1, 0, 0, 1])
    assert bits(tr["edge.0.last-in"]) == bits([1, 1, 0, 0, 1, 0])


def test_edge_high_input_at_start_is_not_an_edge(hal):
    start(hal, "edge", fp=False)
    hal.setp("edge.0.both", True)
    hal.setp("edge.0.in", True)
    tr = hal.run(3, record=["edge.0.out"])
    assert not tr["edge.0.out"].any()


def test_edge_both_edges_retrigger_and_negative_width(hal):
    start(hal, "edge", count=2, fp=False)
    for k, width in ((0, 1_500_000), (1, -1_000_000)):
        hal.setp(f"edge.{k}.both", True)
        hal.setp(f"edge.{k}.out-width-ns", width)
    inp = [0, 1, 0, 0, 0, 1, 1, 1]
    tr = hal.run(8, inputs={"edge.0.in": inp, "edge.1.in": inp},
                 record=["edge.0.out", "edge.1.out"])
    # the falling edge in cycle 2 restarts the pulse begun in cycle 1
    assert bits(tr["edge.0.out"]) == bits([0, 1, 1, 1, 0, 1, 1, 0])
    # a width of 0 or less still gives one period
    assert bits(tr["edge.1.out"]) == bits([0, 1, 1, 0, 0, 1, 0, 0])


# -------------------------------------------------------------- flipflop

def test_flipflop_clock_set_and_reset(hal):
    start(hal, "flipflop", fp=False)
    rows = [  # data, clk, set, reset -> out
        (1, 0, 0, 0, 0), (1, 1, 0, 0, 1), (0, 1, 0, 0, 1), (0, 0, 0, 0, 1),
        (0, 1, 0, 0, 0), (0, 0, 1, 0, 1), (0, 0, 1, 1, 0), (1, 1, 0, 1, 0),
        (1, 1, 0, 0, 0), (1, 0, 0, 0, 0), (1, 1, 0, 0, 1)]
    cols = list(zip(*rows))
    names = ["data", "clk", "set", "reset"]
    tr = hal.run(len(rows), inputs={f"flipflop.0.{n}": list(c)
                                    for n, c in zip(names, cols)},
                 record=["flipflop.0.out", "flipflop.0.out-not"])
    assert bits(tr["flipflop.0.out"]) == bits(cols[4])
    assert (tr["flipflop.0.out-not"] == ~tr["flipflop.0.out"]).all()


def test_flipflop_out_is_io_and_keeps_a_set_value(hal):
    start(hal, "flipflop", fp=False)
    assert hal.pin("flipflop.0.out").direction == halsdk.core._core.IO
    hal.setp("flipflop.0.out", True)
    hal.step(3)
    assert hal.getp("flipflop.0.out") is True
    assert hal.getp("flipflop.0.out-not") is False


# --------------------------------------------------------------- oneshot

def test_oneshot_pulse_and_width_change_mid_pulse(hal):
    start(hal, "oneshot")
    hal.setp("oneshot.0.width", 0.0035)
    width = [0.0035] * 3 + [0.010] * 5
    tr = hal.run(8, inputs={"oneshot.0.in": [0, 1, 1, 1, 1, 1, 1, 1],
                            "oneshot.0.width": width},
                 record=["oneshot.0.out", "oneshot.0.out-not",
                         "oneshot.0.time-left"])
    # a new width does not stretch the running pulse: 4 periods of 3.5 ms
    assert bits(tr["oneshot.0.out"]) == bits([0, 1, 1, 1, 1, 0, 0, 0])
    assert (tr["oneshot.0.out-not"] == ~tr["oneshot.0.out"]).all()
    assert tr["oneshot.0.time-left"] == pytest.approx(
        [0, 0.0035, 0.0025, 0.0015, 0.0005, 0, 0, 0])


def test_oneshot_retriggerable_or_not(hal):
    start(hal, "oneshot", count=2)
    hal.setp("oneshot.1.retriggerable", False)
    inp = [1, 0, 1, 0, 1, 0, 0, 0, 0, 0]
    for k in (0, 1):
        hal.setp(f"oneshot.{k}.width", 0.0025)
    tr = hal.run(10, inputs={"oneshot.0.in": inp, "oneshot.1.in": inp},
                 record=["oneshot.0.out", "oneshot.1.out"])
    assert bits(tr["oneshot.0.out"]) == bits([1, 1, 1, 1, 1, 1, 1, 0, 0, 0])
    # the edge of cycle 2 falls in the first pulse; the one of cycle 4
    # comes when that pulse is just over
    assert bits(tr["oneshot.1.out"]) == bits([1, 1, 1, 0, 1, 1, 1, 0, 0, 0])


def test_oneshot_falling_and_zero_or_negative_width(hal):
    start(hal, "oneshot", count=2)
    hal.setp("oneshot.0.rising", False)
    hal.setp("oneshot.0.falling", True)
    hal.setp("oneshot.0.width", 0.002)
    hal.setp("oneshot.1.width", -0.002)
    inp = [1, 1, 0, 0, 0, 0]
    tr = hal.run(6, inputs={"oneshot.0.in": inp, "oneshot.1.in": inp},
                 record=["oneshot.0.out", "oneshot.1.out",
                         "oneshot.1.time-left"])
    assert bits(tr["oneshot.0.out"]) == bits([0, 0, 1, 1, 0, 0])
    assert not tr["oneshot.1.out"].any()
    assert tr["oneshot.1.time-left"][0] == pytest.approx(-0.002)


def test_oneshot_reset_cancels_and_input_counts_as_low(hal):
    start(hal, "oneshot")
    hal.setp("oneshot.0.width", 0.0025)
    tr = hal.run(7, inputs={"oneshot.0.in": [1, 1, 1, 1, 1, 1, 1],
                            "oneshot.0.reset": [0, 1, 1, 0, 0, 0, 0]},
                 record=["oneshot.0.out", "oneshot.0.time-left"])
    assert bits(tr["oneshot.0.out"]) == bits([1, 0, 0, 1, 1, 1, 0])
    # time-left is left alone while reset holds
    assert tr["oneshot.0.time-left"][:3] == pytest.approx([0.0025] * 3)


# ---------------------------------------------------------------- toggle

def test_toggle_needs_a_debounced_press_and_release(hal):
    start(hal, "toggle", fp=False)
    assert hal.getp("toggle.0.debounce") == 2
    inp = [1, 0, 1, 1, 0, 1, 1, 0, 0, 1, 1]
    tr = hal.run(len(inp), inputs={"toggle.0.in": inp},
                 record=["toggle.0.out"])
    assert bits(tr["toggle.0.out"]) == bits([0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 0])


@pytest.mark.parametrize("value,used", [(0, 2), (10000, 10000),
                                        (10001, 2), (1, 1)])
def test_toggle_debounce_out_of_range_becomes_2(hal, value, used):
    start(hal, "toggle", fp=False)
    hal.setp("toggle.0.debounce", value)
    hal.step(1)
    assert hal.getp("toggle.0.debounce") == used


# ----------------------------------------------------------- toggle2nist

def test_toggle2nist_asks_until_the_device_answers(hal):
    start(hal, "toggle2nist", fp=False)
    rows = [  # in, is-on -> on, off
        (0, 0, 0, 0), (1, 0, 1, 0), (1, 0, 1, 0), (1, 1, 0, 0),
        (0, 1, 0, 1), (0, 1, 0, 1), (0, 0, 0, 0), (1, 0, 1, 0)]
    cols = list(zip(*rows))
    tr = hal.run(len(rows), inputs={"toggle2nist.0.in": list(cols[0]),
                                    "toggle2nist.0.is-on": list(cols[1])},
                 record=["toggle2nist.0.on", "toggle2nist.0.off"])
    assert bits(tr["toggle2nist.0.on"]) == bits(cols[2])
    assert bits(tr["toggle2nist.0.off"]) == bits(cols[3])


# ---------------------------------------------------------- (d)debounce

def test_debounce_groups_make_pins_functions_and_delays(hal):
    assert hal.loadrt("debounce", cfg="2,1") == ["debounce"]
    assert [p.name for p in hal.pins("debounce.*.*.*")] == [
        "debounce.0.0.in", "debounce.0.0.out", "debounce.0.1.in",
        "debounce.0.1.out", "debounce.1.0.in", "debounce.1.0.out"]
    assert sorted(f.name for f in hal.functions()) == [
        "debounce.0", "debounce.1"]
    assert not any(f.uses_fp for f in hal.functions())
    assert hal.getp("debounce.0.delay") == 5


def test_debounce_filters_with_lag_and_fixes_negative_delay(hal):
    hal.loadrt("debounce", cfg="1,1,1")
    hal.newthread("t", MS, fp=False)
    for g in range(3):
        hal.addf(f"debounce.{g}", "t")
    hal.setp("debounce.0.delay", 2)
    hal.setp("debounce.1.delay", 0)
    hal.setp("debounce.2.delay", -3)
    inp = [1, 0, 1, 1, 1, 1, 0, 1, 0, 0, 0, 0]
    tr = hal.run(len(inp), inputs={f"debounce.{g}.0.in": inp
                                   for g in range(3)},
                 record=[f"debounce.{g}.0.out" for g in range(3)])
    assert bits(tr["debounce.0.0.out"]) == bits(
        [0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 0, 0])
    assert bits(tr["debounce.1.0.out"]) == bits(inp)
    assert hal.getp("debounce.2.delay") == 1
    assert bits(tr["debounce.2.0.out"]) == bits(
        [0, 0, 0, 1, 1, 1, 1, 1, 1, 0, 0, 0])


@pytest.mark.parametrize("cfg,message", [
    (None, "no channels configured"), ("0", "no channels configured"),
    ("2,-3", "bad group size '-3'"), ("51", "bad group size '51'")])
def test_debounce_refuses_bad_groups(hal, cfg, message):
    with pytest.raises(halsdk.NotPermittedError, match=message):
        if cfg is None:
            hal.loadrt("debounce")
        else:
            hal.loadrt("debounce", cfg=cfg)
    assert hal.components("debounce") == []
    assert hal.pins() == []


def test_debounce_has_no_count_parameter(hal):
    with pytest.raises(halsdk.HalError):
        hal.loadrt("debounce", count=2)
    assert hal.loadrt("debounce", cfg="50,1,1,1,1,1,1,1") == ["debounce"]
    assert len(hal.pins("debounce.0.*.in")) == 50


def test_dbounce_delay_pin_changes_mid_run(hal):
    start(hal, "dbounce", fp=False)
    assert hal.getp("dbounce.0.delay") == 5
    inp = [1] * 6 + [0] * 5 + [1, 0, 1]
    delay = [3] * 6 + [1] * 5 + [0] * 3
    tr = hal.run(len(inp), inputs={"dbounce.0.in": inp,
                                   "dbounce.0.delay": delay},
                 record=["dbounce.0.out"])
    # up to 3, out TRUE; a lower delay does not shorten the way down
    assert bits(tr["dbounce.0.out"]) == bits(
        [0, 0, 0, 1, 1, 1, 1, 1, 1, 0, 0, 1, 0, 1])


# --------------------------------------------------------------- timers

def test_timedelay_delays_and_restarts_after_a_glitch(hal):
    start(hal, "timedelay")
    assert hal.getp("timedelay.0.on-delay") == 0.5
    assert hal.getp("timedelay.0.off-delay") == 0.5
    hal.setp("timedelay.0.on-delay", 0.002)
    hal.setp("timedelay.0.off-delay", 0.003)
    inp = [1, 0, 1, 1, 1, 0, 0, 0, 0]
    tr = hal.run(len(inp), inputs={"timedelay.0.in": inp},
                 record=["timedelay.0.out", "timedelay.0.elapsed"])
    assert bits(tr["timedelay.0.out"]) == bits([0, 0, 0, 1, 1, 1, 1, 0, 0])
    assert tr["timedelay.0.elapsed"] == pytest.approx(
        [0.001, 0.001, 0.001, 0.002, 0.002, 0.001, 0.002, 0.003, 0.003])


def test_timedelay_zero_or_negative_delay_passes_at_once(hal):
    start(hal, "timedelay")
    hal.setp("timedelay.0.on-delay", 0.0)
    hal.setp("timedelay.0.off-delay", -1.0)
    inp = [0, 1, 0, 1]
    tr = hal.run(4, inputs={"timedelay.0.in": inp},
                 record=["timedelay.0.out"])
    assert bits(tr["timedelay.0.out"]) == bits(inp)


def test_ton_and_tof_exact_delay(hal):
    hal.loadrt("ton")
    hal.loadrt("tof")
    hal.newthread("t", MS)
    hal.addf("ton.0", "t")
    hal.addf("tof.0", "t")
    hal.setp("ton.0.pt", 0.002)
    hal.setp("tof.0.pt", 0.002)
    inp = np.array([1, 1, 1, 1, 0, 0, 0, 0, 1, 0], dtype=bool)
    tr = hal.run(10, inputs={"ton.0.in": inp, "tof.0.in": inp},
                 record=["ton.0.q", "ton.0.et", "tof.0.q", "tof.0.et"])
    assert bits(tr["ton.0.q"]) == bits([0, 0, 1, 1, 0, 0, 0, 0, 0, 0])
    assert tr["ton.0.et"] == pytest.approx(
        [0.001, 0.002, 0.002, 0.002, 0, 0, 0, 0, 0.001, 0])
    assert bits(tr["tof.0.q"]) == bits([1, 1, 1, 1, 1, 1, 0, 0, 1, 1])
    assert tr["tof.0.et"] == pytest.approx(
        [0, 0, 0, 0, 0.001, 0.002, 0.002, 0.002, 0, 0.001])


def test_ton_tof_zero_delay_follow_input(hal):
    hal.loadrt("ton")
    hal.loadrt("tof")
    hal.newthread("t", MS)
    hal.addf("ton.0", "t")
    hal.addf("tof.0", "t")
    assert hal.getp("ton.0.pt") == 0.0
    inp = [1, 0, 1, 1, 0]
    tr = hal.run(5, inputs={"ton.0.in": inp, "tof.0.in": inp},
                 record=["ton.0.q", "tof.0.q"])
    assert bits(tr["ton.0.q"]) == bits(inp)
    assert bits(tr["tof.0.q"]) == bits(inp)


# ------------------------------------------------------------ multiclick

def clicks(n, hold=2, space=2):
    return ([1] * hold + [0] * space) * n


def fast_multiclick(hal, count=1):
    start(hal, "multiclick", count=count, fp=False)
    for k in range(count):
        hal.setp(f"multiclick.{k}.max-hold-ns", 5 * MS)
        hal.setp(f"multiclick.{k}.max-space-ns", 5 * MS)
        hal.setp(f"multiclick.{k}.output-hold-ns", 3 * MS)


OUTS = ["single-click", "single-click-only", "double-click",
        "double-click-only", "triple-click", "triple-click-only",
        "quadruple-click", "quadruple-click-only"]


def test_multiclick_defaults(hal):
    hal.loadrt("multiclick")
    assert hal.getp("multiclick.0.max-hold-ns") == 250_000_000
    assert hal.getp("multiclick.0.max-space-ns") == 250_000_000
    assert hal.getp("multiclick.0.output-hold-ns") == 100_000_000
    assert hal.getp("multiclick.0.invert-input") is False


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_multiclick_counts_clicks(hal, n):
    fast_multiclick(hal)
    inp = clicks(n) + [0] * 10
    tr = hal.run(len(inp), inputs={"multiclick.0.in": inp},
                 record=[f"multiclick.0.{o}" for o in OUTS])
    fired = [o for o in OUTS if tr[f"multiclick.0.{o}"].any()]
    want = [OUTS[2 * k] for k in range(n)] + [OUTS[2 * n - 1]]
    assert sorted(fired) == sorted(want)
    # the -only pulse: 3 periods, once the 5 ms space is over
    only = tr[f"multiclick.0.{OUTS[2 * n - 1]}"]
    first = 4 * n - 2 + 6
    assert np.flatnonzero(only).tolist() == [first, first + 1, first + 2]


def test_multiclick_long_hold_and_fifth_click(hal):
    fast_multiclick(hal)
    inp = [1] * 8 + [0] * 10 + clicks(5) + [0] * 10
    tr = hal.run(len(inp), inputs={"multiclick.0.in": inp},
                 record=[f"multiclick.0.{o}" for o in OUTS] +
                 ["multiclick.0.state"])
    assert tr["multiclick.0.state"][:9].tolist() == [1] * 6 + [9, 9, 0]
    only = [o for o in OUTS if o.endswith("only")]
    assert not any(tr[f"multiclick.0.{o}"].any() for o in only)
    assert tr["multiclick.0.quadruple-click"].any()


def test_multiclick_inverted_input(hal):
    fast_multiclick(hal)
    hal.setp("multiclick.0.invert-input", True)
    inp = [1 - v for v in clicks(2)] + [1] * 10
    tr = hal.run(len(inp), inputs={"multiclick.0.in": inp},
                 record=["multiclick.0.double-click-only"])
    assert tr["multiclick.0.double-click-only"].sum() == 3


def test_multiclick_timer_wraps_at_32_bits(hal):
    """The click timer is 32 bits wide, as the reference's: a limit above
    2^32 - period is never passed (the timer wraps first), so a release
    of 4.4 s does not end the click; a limit the timer reaches before it
    wraps does (tests/data/complib/multiclick-wrap.* against the
    reference)."""
    fast_multiclick(hal, count=2)
    hal.setp("multiclick.0.max-space-ns", 4_294_967_295)
    hal.setp("multiclick.1.max-space-ns", 4_293_500_000)
    inp = [1, 1] + [0] * 4400
    tr = hal.run(len(inp), inputs={"multiclick.0.in": inp,
                                   "multiclick.1.in": inp},
                 record=["multiclick.0.single-click-only",
                         "multiclick.1.single-click-only",
                         "multiclick.0.state"])
    assert not tr["multiclick.0.single-click-only"].any()
    assert (tr["multiclick.0.state"][2:] == 2).all()
    # 4,293,500,000 ns is passed after 4,294 periods of release
    assert np.flatnonzero(tr["multiclick.1.single-click-only"])[0] == 2 + 4294


# ----------------------------------------------------------- multiswitch

def test_multiswitch_cfg_sizes(hal):
    hal.loadrt("multiswitch", cfg="2,5,32")
    assert [len(hal.pins(f"multiswitch.{k}.bit-*")) for k in range(3)] == [
        2, 5, 32]
    assert [hal.getp(f"multiswitch.{k}.top-position")
            for k in range(3)] == [1, 4, 31]
    assert hal.functions()[0].uses_fp is True


def test_multiswitch_default_is_four_bits(hal):
    hal.loadrt("multiswitch")
    assert len(hal.pins("multiswitch.0.bit-*")) == 4
    assert hal.getp("multiswitch.0.top-position") == 3


def test_multiswitch_refuses_more_than_32_bits(hal):
    with pytest.raises(halsdk.CapacityError,
                       match="Requested size 33 exceeds max size 32"):
        hal.loadrt("multiswitch", cfg="4,33")
    assert hal.components("multiswitch") == []


def test_multiswitch_up_down_wrap(hal):
    hal.loadrt("multiswitch", cfg="3")
    hal.newthread("t", MS)
    hal.addf("multiswitch.0", "t")
    up = [0, 1, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0]
    down = [0, 0, 0, 0, 0, 0, 1, 0, 1, 0, 1, 0]
    tr = hal.run(12, inputs={"multiswitch.0.up": up,
                             "multiswitch.0.down": down},
                 record=["multiswitch.0.position"] +
                 [f"multiswitch.0.bit-0{k}" for k in range(3)])
    # round from the top to 0 and back; both edges at once cancel
    assert tr["multiswitch.0.position"].tolist() == [
        0, 1, 1, 2, 2, 0, 2, 2, 1, 1, 1, 1]
    for k in range(3):
        assert (tr[f"multiswitch.0.bit-0{k}"] ==
                (tr["multiswitch.0.position"] == k)).all()


def test_multiswitch_position_out_of_range(hal):
    hal.loadrt("multiswitch", cfg="4,4")
    hal.newthread("t", MS)
    hal.addf("multiswitch.0", "t")
    hal.addf("multiswitch.1", "t")
    hal.setp("multiswitch.0.position", 9)
    hal.setp("multiswitch.1.top-position", 1)
    hal.setp("multiswitch.1.position", -1)
    hal.step(1)
    assert hal.getp("multiswitch.0.position") == 0
    assert hal.getp("multiswitch.1.position") == 1


# ----------------------------------------------------------- estop_latch

def test_estop_latch_pins_and_defaults(hal):
    hal.loadrt("estop_latch")
    assert sorted(f.name for f in hal.functions()) == ["estop-latch.0"]
    assert hal.getp("estop-latch.0.ok-in") is True
    assert hal.getp("estop-latch.0.fault-out") is True
    assert hal.getp("estop-latch.0.ok-out") is False


def test_estop_latch_reset_edge_fault_and_watchdog(hal):
    start(hal, "estop_latch", fp=False)
    rows = [  # ok-in, fault-in, reset -> ok-out
        (1, 0, 0, 0), (1, 0, 1, 1), (1, 0, 1, 1), (1, 1, 1, 0),
        (1, 0, 1, 0), (1, 0, 0, 0), (0, 0, 1, 0), (1, 0, 0, 0),
        (1, 0, 1, 1), (1, 0, 0, 1)]
    cols = list(zip(*rows))
    names = ["ok-in", "fault-in", "reset"]
    tr = hal.run(len(rows), inputs={f"estop-latch.0.{n}": list(c)
                                    for n, c in zip(names, cols)},
                 record=["estop-latch.0.ok-out", "estop-latch.0.fault-out",
                         "estop-latch.0.watchdog"])
    assert bits(tr["estop-latch.0.ok-out"]) == bits(cols[3])
    assert (tr["estop-latch.0.fault-out"] ==
            ~tr["estop-latch.0.ok-out"]).all()
    wd = tr["estop-latch.0.watchdog"].tolist()
    # toggles every OK period, holds while faulted
    assert wd[:4] == [False, True, False, False]
    assert wd[4:8] == [False] * 4
    assert wd[8:] == [True, False]


def test_multiclick_output_hold_zero_stays_on_and_pulses_restart(hal):
    fast_multiclick(hal, count=2)
    hal.setp("multiclick.0.output-hold-ns", 0)
    hal.setp("multiclick.1.output-hold-ns", 12 * MS)
    inp = ([1] + [0] * 9) * 2 + [0] * 12
    tr = hal.run(len(inp), inputs={"multiclick.0.in": inp,
                                   "multiclick.1.in": inp},
                 record=["multiclick.0.single-click",
                         "multiclick.1.single-click"])
    assert tr["multiclick.0.single-click"][1:].all()
    # fired in cycles 1 and 11: on until 12 ms after the second
    on = tr["multiclick.1.single-click"]
    assert np.flatnonzero(on).tolist() == list(range(1, 23))
