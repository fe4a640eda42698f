"""The move queue of motmod (a ring of queued records drained into the
planner every servo cycle), motion ids and program lines, queued-record
rejections, synchronized and immediate outputs, feed hold / inhibit /
adaptive feed pins and M66-style wait_input.

The machine: trivkins with three joints, motor-pos-cmd looped back to
motor-pos-fb, stepped deterministically by the client.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.motion_trace import looped_machine

from halsdk.motion import (
    InputWait,
    MotionTimeout,
    QueueRejected,
    Rejected,
)

VMAX, AMAX = 100.0, 5000.0


def load_machine(hal, vmax=VMAX, amax=AMAX, **modparams):
    return looped_machine(hal, vmax, amax, 500, timeout=60.0, **modparams)


@pytest.fixture
def m(hal):
    return load_machine(hal)


def xyz(x, y=0.0, z=0.0):
    return (x, y, z, 0, 0, 0, 0, 0, 0)


# ------------------------------------------------------------ streaming

def test_streaming_5000_short_lines_never_starves_the_planner(hal, m):
    """5,000 lines of 0.05 mm (a zigzag in XY): the client writes while
    the ring has room and steps one cycle when it is full; in every cycle
    until the last record is written the planner has moves queued."""
    n = 5000
    sent = 0
    starved = cycles = 0
    end = None
    while sent < n:
        while sent < n and m.queue_free() > 0:
            x = 0.05 * (sent + 1) / math.sqrt(2)
            y = 0.05 / math.sqrt(2) * (sent % 2)
            end = xyz(x, y)
            m.queue_line(end, vel=50.0, id=sent + 1, line=sent + 100)
            sent += 1
        hal.step(1)
        cycles += 1
        st = m.status()
        if st.queue_depth == 0:
            starved += 1
    assert cycles > 5, "the ring must have filled up at least once"
    assert starved == 0
    st = m.wait_done(timeout=600)
    assert st.motion_id == n
    assert st.carte_pos_cmd.x == pytest.approx(end[0], abs=1e-9)
    assert st.carte_pos_cmd.y == pytest.approx(end[1], abs=1e-9)
    assert st.program_line == 0 and m.queue_pending() == 0
    assert st.queue_taken == n


def test_many_records_per_cycle(hal, m):
    """The handler takes many records per cycle (up to 16), not one: 200
    moves are in the planner after 13 cycles."""
    for k in range(200):
        m.queue_line(xyz(0.01 * (k + 1)), vel=1.0)
    assert m.queue_pending() == 200
    hal.step(1)
    assert m.queue_pending() == 200 - 16
    hal.step(12)
    assert m.queue_pending() == 0
    assert m.status().queue_depth >= 190


def test_ids_lines_and_requested_vel(hal, m):
    ids = [m.queue_line(xyz(1.0), vel=10.0, line=11),
           m.queue_line(xyz(1.0, 2.0), vel=20.0, line=22),
           m.queue_circle(xyz(3.0, 2.0), center=(2.0, 2.0, 0.0),
                          normal=(0, 0, 1), vel=15.0, line=33)]
    assert ids == [ids[0], ids[0] + 1, ids[0] + 2]
    tr = hal.run(3000, record=["motion.program-line", "motion.requested-vel",
                               "motion.motion-type"])
    lines = tr["motion.program-line"]
    seen = [int(v) for k, v in enumerate(lines) if k == 0 or v != lines[k - 1]]
    assert seen == [11, 22, 33, 0]
    req = tr["motion.requested-vel"]
    assert set(np.unique(req[lines == 11])) == {10.0}
    assert set(np.unique(req[lines == 22])) == {20.0}
    assert set(np.unique(req[lines == 33])) == {15.0}
    assert set(np.unique(tr["motion.motion-type"][lines == 33])) == {3}
    assert req[-1] == 0 and tr["motion.motion-type"][-1] == 0
    st = m.wait_done()
    assert st.motion_id == ids[-1]


def test_rejected_queued_record_stops_the_queue(hal, m):
    m.queue_line(xyz(1.0), vel=10.0, line=1)
    m.queue_line(xyz(2.0), vel=0.0, id=77, line=2)      # refused
    m.queue_line(xyz(3.0), vel=10.0, line=3)            # dropped
    hal.step(2)
    with pytest.raises(QueueRejected) as e:
        m.queue_line(xyz(4.0), vel=10.0, line=4)
    assert isinstance(e.value, Rejected)
    assert (e.value.id, e.value.line, e.value.command) == (77, 2, "SET_LINE")
    assert "velocity must be a positive number" in e.value.reason
    assert "line 2" in str(e.value)
    errs = m.errors()
    assert any("id 77, line 2" in t for t in errs), errs
    # the error is raised once; the first move runs, the third never
    st = m.wait_done()
    assert st.carte_pos_cmd.x == pytest.approx(1.0, abs=1e-12)
    # new records run again
    m.queue_line(xyz(5.0), vel=10.0, line=5)
    st = m.wait_done()
    assert st.carte_pos_cmd.x == pytest.approx(5.0, abs=1e-12)


def test_rejection_is_raised_by_wait_done_and_by_commands(hal, m):
    m.queue_line(xyz(1.0, 0, 0), vel=10.0)
    m.queue(m_cmd("SET_DOUT"), index=9, ival=1, sync=1, id=5, line=8)
    with pytest.raises(QueueRejected) as e:
        m.wait_done()
    assert "digital output 9 does not exist" in e.value.reason
    assert e.value.line == 8
    m.queue(m_cmd("SPINDLE_ORIENT"), index=0, value=1.0, line=9)
    hal.step(1)
    with pytest.raises(QueueRejected) as e:
        m.set_feed_scale(1.0)
    assert "cannot be queued" in e.value.reason


def m_cmd(name):
    from halsdk.motion import Cmd
    return Cmd[name]


def test_abort_drops_what_is_not_taken(hal, m):
    for k in range(50):
        m.queue_line(xyz(0.5 * (k + 1)), vel=10.0)
    m.abort()
    assert m.queue_pending() == 0
    st = m.wait_done()
    assert st.carte_pos_cmd.x < 25.0


def test_disable_drops_the_queue_and_later_records_are_refused(hal, m):
    for k in range(20):
        m.queue_line(xyz(0.5 * (k + 1)), vel=10.0)
    hal.step(30)
    m.disable()
    assert m.queue_pending() == 0
    m.queue_line(xyz(9.0), vel=10.0, line=42)
    hal.step(1)
    with pytest.raises(QueueRejected) as e:
        m.enable()
    assert "needs motion enabled" in e.value.reason and e.value.line == 42


# ------------------------------------------------------------ outputs

def test_sync_dout_and_aout_change_when_the_next_move_starts(hal, m):
    a = m.queue_line(xyz(2.0), vel=10.0)
    m.queue_dout(1, True)
    m.queue_aout(2, 4.5)
    b = m.queue_line(xyz(2.0, 1.0), vel=10.0)
    tr = hal.run(600, record=["motion.digital-out-01",
                              "motion.analog-out-02", "joint.1.pos-cmd",
                              "joint.0.pos-cmd"])
    dout = tr["motion.digital-out-01"]
    aout = tr["motion.analog-out-02"]
    y = tr["joint.1.pos-cmd"]
    x = tr["joint.0.pos-cmd"]
    first_on = int(np.argmax(dout))
    assert dout[first_on] and not dout[:first_on].any()
    assert (aout[:first_on] == 0).all() and aout[first_on] == 4.5
    # move a is complete, move b has not moved yet (it starts now)
    assert x[first_on] == pytest.approx(2.0, abs=1e-12)
    assert y[first_on - 1] == 0.0
    assert y[first_on + 20] > 0.0
    assert m.wait_done().motion_id == b and b == a + 1


def test_immediate_aout_m68_while_moves_run(hal, m):
    m.queue_line(xyz(5.0), vel=10.0)
    hal.step(50)
    m.set_aout(0, -3.25)                    # M68: now
    m.set_dout(3, True)                     # M64: now
    assert hal.getp("motion.analog-out-00") == -3.25
    assert hal.getp("motion.digital-out-03")
    st = m.status()
    assert st.aout[0] == -3.25 and st.dout & 8
    assert not st.in_position               # the move still runs
    m.set_aout(1, 2.0, sync=True)           # M67 through the mailbox
    assert hal.getp("motion.analog-out-01") == 0.0
    m.queue_line(xyz(6.0), vel=10.0)
    m.wait_done()
    assert hal.getp("motion.analog-out-01") == 2.0


# ------------------------------------------------------------ feed pins

def test_feed_pins_units_and_requested_vel(hal, m):
    m.set_linear_units("inch")
    m.set_feed_scale(0.5)
    m.queue_line(xyz(20.0), vel=10.0)
    hal.step(200)
    assert hal.getp("motion.requested-vel") == 10.0
    assert hal.getp("motion.feed-upm") == pytest.approx(300.0)
    assert hal.getp("motion.feed-inches-per-minute") == pytest.approx(300.0)
    assert hal.getp("motion.feed-mm-per-minute") == pytest.approx(7620.0)
    assert hal.getp("motion.feed-mm-per-second") == pytest.approx(127.0)
    assert hal.getp("motion.feed-inches-per-second") == pytest.approx(5.0)
    assert hal.getp("motion.current-vel") == pytest.approx(5.0)
    assert hal.getp("motion.distance-to-go") > 0
    assert hal.getp("motion.motion-type") == 2
    m.set_feed_scale(1.0)
    m.wait_done()
    assert hal.getp("motion.feed-upm") == 0.0
    with pytest.raises(ValueError):
        m.set_linear_units("furlong")


def test_feed_hold_applies_only_when_enabled(hal, m):
    hal.setp("motion.feed-hold", True)
    m.set_feed_hold_enable(False)           # M53 P0
    m.queue_line(xyz(3.0), vel=10.0)
    st = m.wait_done()
    assert st.carte_pos_cmd.x == pytest.approx(3.0)
    m.set_feed_hold_enable(True)            # M53 P1
    m.queue_line(xyz(0.0), vel=10.0)
    hal.step(200)
    st = m.status()
    assert st.feed_hold and st.feed_hold_enabled
    assert st.carte_pos_cmd.x == pytest.approx(3.0)
    assert hal.getp("motion.feed-upm") == 0.0
    hal.setp("motion.feed-hold", False)
    assert m.wait_done().carte_pos_cmd.x == pytest.approx(0.0)


def test_feed_inhibit_stops_within_limits_and_resumes(hal, m):
    m.queue_line(xyz(10.0), vel=20.0)
    hal.step(200)
    hal.setp("motion.feed-inhibit", True)
    tr = hal.run(300, record=["joint.0.vel-cmd", "joint.0.pos-cmd"])
    v = tr["joint.0.vel-cmd"]
    assert v[-1] == 0 and np.abs(np.diff(v)).max() <= AMAX * 1e-3 * 1.000001
    assert m.status().feed_inhibit
    held = tr["joint.0.pos-cmd"][-1]
    assert 0 < held < 10.0
    hal.setp("motion.feed-inhibit", False)
    assert m.wait_done().carte_pos_cmd.x == pytest.approx(10.0)


def test_adaptive_feed_needs_m52(hal, m):
    hal.setp("motion.adaptive-feed", 0.25)
    m.queue_line(xyz(20.0), vel=10.0)
    hal.step(300)
    assert hal.getp("motion.current-vel") == pytest.approx(10.0)
    m.set_adaptive_feed_enable(True)        # M52 P1
    hal.step(300)
    assert hal.getp("motion.current-vel") == pytest.approx(2.5)
    assert hal.getp("motion.feed-upm") == pytest.approx(150.0)
    st = m.status()
    assert st.adaptive_enabled and st.adaptive_feed == 0.25
    m.set_adaptive_feed_enable(False)
    m.wait_done()


# ------------------------------------------------------------ wait_input

def test_wait_input_modes_and_timeouts(hal, m):
    # digital-in-00 from a 2 Hz clock: false 250 ms, true 250 ms, ...
    hal.loadrt("siggen")
    hal.addf("siggen.0.update", "servo-thread", position=1)
    hal.setp("siggen.0.frequency", 2.0)
    hal.net("clk", "siggen.0.clock", "motion.digital-in-00")
    hal.setp("motion.analog-in-01", 1.75)
    hal.step(1)
    assert m.wait_input("analog", 1) == 1.75
    assert m.status().ain[1] == 1.75
    start = m.status().heartbeat
    assert m.wait_input("digital", 0, "immediate") is False
    assert m.wait_input("digital", 0, InputWait.LOW, timeout=0) is False
    assert m.wait_input("digital", 0, "rise", timeout=1.0) is True
    t_rise = m.status().heartbeat
    assert 240 <= t_rise - start <= 260
    assert m.wait_input("digital", 0, "high", timeout=0) is True
    assert m.wait_input("digital", 0, "fall", timeout=1.0) is False
    assert 240 <= m.status().heartbeat - t_rise <= 260
    # a timeout: None (M66's -1); the servo thread ran the whole time
    t0 = m.status().heartbeat
    assert m.wait_input("digital", 0, "fall", timeout=0.1) is None
    assert m.status().heartbeat - t0 == pytest.approx(100, abs=1)
    assert m.wait_input("digital", 1, "high", timeout=0.05) is None
    with pytest.raises(ValueError, match="does not exist"):
        m.wait_input("digital", 4)
    with pytest.raises(ValueError, match="only be read"):
        m.wait_input("analog", 0, "rise")
    with pytest.raises(ValueError, match="unknown wait mode"):
        m.wait_input("digital", 0, "sideways")


def test_wait_done_times_out_clearly(hal, m):
    m.queue_line(xyz(100.0), vel=1.0)
    with pytest.raises(MotionTimeout):
        m.wait_done(timeout=0.2)
    m.abort()
    m.wait_done()


def test_queued_settings_keep_their_order(hal, m):
    from halsdk.motion import TermCond
    m.queue_line(xyz(1.0), vel=10.0)
    m.queue_term_cond(TermCond.BLEND, tolerance=0.5, cam_tolerance=0.01)
    hal.step(1)
    st = m.status()
    assert st.term_cond == TermCond.BLEND and st.tolerance == 0.5
    m.queue_term_cond(7)
    with pytest.raises(QueueRejected, match="7 is not a termination"):
        m.wait_done()


def test_random_records_in_the_queue_never_break_it(hal, m):
    """Garbage through the ring: every bad record is reported, nothing
    crashes, no output becomes NaN."""
    from halsdk.motion import Cmd
    rng = np.random.default_rng(7)
    codes = [int(c) for c in Cmd] + [0, 99, 149, 150, -3, 10**6]
    vals = [0.0, -1.0, 1.0, 5.0, 1e300, -1e300, float("nan"),
            float("inf")]
    rejected = 0
    for k in range(300):
        fields = {f: float(rng.choice(vals)) for f in
                  ("vel", "ini_maxvel", "acc", "value", "pitch",
                   "tolerance", "offset") if rng.random() < 0.5}
        fields.update(index=int(rng.integers(-2, 6)),
                      ival=int(rng.integers(-2, 4)),
                      motion_type=int(rng.integers(-1, 8)), id=k, line=k,
                      pos=tuple(float(rng.choice(vals)) * rng.random()
                                for _ in range(9)))
        try:
            m.queue(int(rng.choice(codes)) if rng.random() < 0.9
                    else Cmd.SET_LINE, **fields)
        except QueueRejected:
            rejected += 1
        except ValueError:
            pass                    # not a command code: the client says so
        if k % 10 == 0:
            hal.step(3)
    hal.step(50)
    try:
        m.abort()
    except QueueRejected:
        rejected += 1
    assert rejected > 10
    for pin in ("motion.current-vel", "motion.requested-vel",
                "motion.feed-upm", "spindle.0.speed-out", "joint.0.pos-cmd",
                "joint.1.pos-cmd", "joint.2.pos-cmd", "motion.analog-out-00"):
        assert not math.isnan(hal.getp(pin)), pin
    m.errors()
    if not m.status().enabled:
        m.enable()
        m.coord()
    m.queue_line(xyz(1.0), vel=10.0)
    m.wait_done()
