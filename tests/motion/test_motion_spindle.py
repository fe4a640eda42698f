"""Spindle control of motmod: the spindle.N.* pins for on/off/reverse,
speed, inhibit, brake, the orient handshake, amplifier faults, the
at-speed wait before the first feed move, and spindle-synchronized moves
(G33 threading, G33.1 rigid tapping) on a simulated spindle
(sim_spindle driving spindle.0.revs and answering index-enable).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.motion_trace import looped_machine

from halsdk.motion import (
    EnableFailed,
    MotionError,
    OrientState,
    Rejected,
)

VMAX, AMAX = 50.0, 1000.0


def _sim_spindle(hal):
    hal.loadrt("sim_spindle")
    hal.addf("sim-spindle.0", "servo-thread")
    hal.net("spcmd", "spindle.0.speed-out-rps", "sim-spindle.0.velocity-cmd",
            "spindle.0.speed-in")
    hal.net("sprevs", "sim-spindle.0.position-fb", "spindle.0.revs")
    hal.net("spindex", "sim-spindle.0.index-enable",
            "spindle.0.index-enable")


def load_machine(hal, sim_spindle=False, **modparams):
    return looped_machine(hal, VMAX, AMAX, 100,
                          setup=_sim_spindle if sim_spindle else None,
                          **modparams)


@pytest.fixture
def m(hal):
    return load_machine(hal)


def pins(hal, n=0):
    names = ["on", "forward", "reverse", "brake", "speed-out",
             "speed-out-abs", "speed-out-rps", "speed-out-rps-abs",
             "speed-cmd-rps", "orient", "locked"]
    return {k: hal.getp(f"spindle.{n}.{k}") for k in names}


def xyz(x=0.0, y=0.0, z=0.0):
    return (x, y, z, 0, 0, 0, 0, 0, 0)


# ------------------------------------------------------------ pins

def test_on_reverse_speed_and_off(hal, m):
    p = pins(hal)
    assert not p["on"] and p["speed-out"] == 0
    m.spindle_on(600)
    hal.step(1)
    p = pins(hal)
    assert p["on"] and p["forward"] and not p["reverse"] and not p["brake"]
    assert p["speed-out"] == 600 and p["speed-out-abs"] == 600
    assert p["speed-out-rps"] == 10 and p["speed-out-rps-abs"] == 10
    assert p["speed-cmd-rps"] == 10
    m.spindle_on(-300)
    hal.step(1)
    p = pins(hal)
    assert p["on"] and p["reverse"] and not p["forward"]
    assert p["speed-out"] == -300 and p["speed-out-abs"] == 300
    assert p["speed-out-rps"] == -5 and p["speed-out-rps-abs"] == 5
    sp = m.status().spindles[0]
    assert sp.on and sp.direction == -1 and sp.speed == -300
    m.spindle_increase(step=100)
    m.spindle_decrease()                    # 10 %
    hal.step(1)
    assert hal.getp("spindle.0.speed-out") == pytest.approx(-360.0)
    with pytest.raises(Rejected, match="would stop"):
        m.spindle_decrease(step=500)
    with pytest.raises(Rejected, match="send SPINDLE_OFF first"):
        m.spindle_brake(True)
    m.spindle_off()
    hal.step(1)
    p = pins(hal)
    assert not p["on"] and not p["forward"] and not p["reverse"]
    assert p["brake"] and p["speed-out"] == 0
    m.spindle_brake(False)
    hal.step(1)
    assert not hal.getp("spindle.0.brake")
    with pytest.raises(Rejected, match="spindle 0 is off"):
        m.spindle_increase()
    with pytest.raises(Rejected, match=r"spindle 1 does not exist"):
        m.spindle_on(100, spindle=1)


def test_second_spindle_and_disable_stops_spindles(hal):
    m = load_machine(hal, num_spindles=2)
    m.spindle_on(1200, spindle=1)
    hal.step(1)
    assert hal.getp("spindle.1.speed-out") == 1200
    assert not hal.getp("spindle.0.on")
    m.disable()
    hal.step(1)
    assert not hal.getp("spindle.1.on") and hal.getp("spindle.1.brake")
    with pytest.raises(Rejected, match="needs motion enabled"):
        m.spindle_on(100)


def test_inhibit_holds_the_speed_at_zero(hal, m):
    m.spindle_on(900)
    hal.setp("spindle.0.inhibit", True)
    hal.step(1)
    assert hal.getp("spindle.0.speed-out") == 0
    assert hal.getp("spindle.0.speed-out-rps-abs") == 0
    assert hal.getp("spindle.0.on")         # still on: only held
    m.spindle_increase(step=100)            # a change is held too
    hal.step(1)
    assert hal.getp("spindle.0.speed-out") == 0
    assert m.status().spindles[0].inhibit
    hal.setp("spindle.0.inhibit", False)
    hal.step(1)
    assert hal.getp("spindle.0.speed-out") == 1000


def test_css_speed_follows_the_radius(hal, m):
    m.set_line(xyz(x=10.0), vel=20.0)
    m.wait_done()
    # 100 units/min at radius 10: 100 / (2 pi 10) rpm, at most 2000
    m.spindle_on(500, css=100.0, css_axis="x", css_max=2000)
    hal.step(1)
    assert hal.getp("spindle.0.speed-out") == pytest.approx(
        100 / (2 * np.pi * 10))
    m.set_line(xyz(x=0.0), vel=20.0)
    m.wait_done()
    assert hal.getp("spindle.0.speed-out") == pytest.approx(2000.0)


# ------------------------------------------------------------ orient

def test_orient_handshake(hal, m):
    m.spindle_on(600)
    m.spindle_orient(90.0, mode=1)
    hal.step(1)
    p = pins(hal)
    assert p["orient"] and not p["locked"] and not p["on"]
    assert p["speed-out"] == 0
    assert hal.getp("spindle.0.orient-angle") == 90.0
    assert hal.getp("spindle.0.orient-mode") == 1
    assert m.status().spindles[0].orient_state == OrientState.RUNNING
    hal.step(20)
    assert hal.getp("spindle.0.orient")     # until the drive answers
    hal.setp("spindle.0.is-oriented", True)
    st = m.wait_oriented()
    assert st.spindles[0].locked and st.spindles[0].brake
    hal.step(1)
    p = pins(hal)
    assert not p["orient"] and p["locked"] and p["brake"]
    hal.setp("spindle.0.is-oriented", False)
    m.spindle_on(300)                       # M3 clears locked and brake
    hal.step(1)
    p = pins(hal)
    assert not p["locked"] and not p["brake"] and p["on"]


def test_orient_fault_is_an_error(hal, m):
    m.errors()
    hal.setp("spindle.0.orient-fault", 7)
    with pytest.raises(MotionError, match="orient-fault 7"):
        m.spindle_orient(45.0, wait=True)
    assert not hal.getp("spindle.0.orient")
    assert any("orient failed" in e and "is 7" in e for e in m.errors())
    assert m.status().enabled               # not a machine fault


# ------------------------------------------------------------ amp fault

def test_amp_fault_disables_with_a_message(hal, m):
    m.spindle_on(600)
    m.errors()
    hal.setp("spindle.0.amp-fault-in", True)
    hal.step(1)
    st = m.status()
    assert not st.enabled and st.error
    assert not hal.getp("spindle.0.on")
    assert any("spindle 0 amplifier fault" in e for e in m.errors())
    with pytest.raises(Rejected, match="needs motion enabled"):
        m.spindle_on(600)
    # enabling again with the fault still there: disabled at once, and
    # enable() says so
    with pytest.raises(EnableFailed, match="spindle 0 amplifier fault"):
        m.enable()
    assert not m.status().enabled
    assert any("spindle 0 amplifier fault" in e for e in m.errors())
    hal.setp("spindle.0.amp-fault-in", False)
    m.enable()
    m.spindle_on(600)
    hal.step(5)
    assert m.status().enabled and hal.getp("spindle.0.on")


# ------------------------------------------------------------ at-speed

def test_first_feed_move_waits_for_at_speed(hal, m):
    hal.setp("spindle.0.at-speed", False)
    m.queue_line(xyz(x=2.0), vel=20.0, rapid=True)
    m.queue_spindle_on(600)
    b = m.queue_line(xyz(x=2.0, y=1.0), vel=20.0)
    tr = hal.run(800, record=["joint.0.pos-cmd", "joint.1.pos-cmd",
                              "spindle.0.on"])
    # the spindle turns on once the traverse is queued; the traverse runs,
    # then the feed move waits at rest
    assert tr["spindle.0.on"][2]
    assert tr["joint.0.pos-cmd"][-1] == pytest.approx(2.0, abs=1e-12)
    assert tr["joint.1.pos-cmd"][-1] == 0.0
    assert m.queue_pending() == 1
    assert m.status().at_speed_wait
    hal.setp("spindle.0.at-speed", True)
    st = m.wait_done()
    assert st.motion_id == b and st.carte_pos_cmd.y == pytest.approx(1.0)
    # no speed change: the next feed move does not wait
    hal.setp("spindle.0.at-speed", False)
    m.queue_line(xyz(x=3.0, y=1.0), vel=20.0)
    assert m.wait_done().carte_pos_cmd.x == pytest.approx(3.0)


def test_spindle_off_cancels_the_wait(hal, m):
    hal.setp("spindle.0.at-speed", False)
    m.queue_spindle_on(1000)
    m.queue_spindle_off()
    m.queue_line(xyz(x=1.0), vel=20.0)
    hal.step(10)
    assert m.queue_pending() == 0           # taken at once: no wait
    assert m.wait_done().carte_pos_cmd.x == pytest.approx(1.0)


def test_mailbox_feed_move_after_spindle_on_waits_too(hal, m):
    """Through the mailbox the move is answered at once and held until the
    spindle is at speed; meanwhile the mailbox stays free (ABORT gets
    through and drops the held move)."""
    hal.setp("spindle.0.at-speed", False)
    m.spindle_on(400)
    m.set_line(xyz(x=1.0), vel=20.0)
    hal.step(50)
    assert m.status().carte_pos_cmd.x == 0.0
    with pytest.raises(Rejected, match="already waits for the spindle"):
        m.set_line(xyz(x=2.0), vel=20.0)
    hal.setp("spindle.0.at-speed", True)
    st = m.wait_for(lambda s: s.carte_pos_cmd.x == 1.0 and s.in_position)
    assert st.queue_depth == 0
    # a new speed, a held move, then ABORT: the move never runs
    hal.setp("spindle.0.at-speed", False)
    m.spindle_on(800)
    m.set_line(xyz(x=3.0), vel=20.0)
    m.abort()
    hal.setp("spindle.0.at-speed", True)
    hal.step(500)
    assert m.status().carte_pos_cmd.x == 1.0


# ------------------------------------------------------------ G33, G33.1

def test_g33_thread_follows_the_spindle(hal):
    m = load_machine(hal, sim_spindle=True)
    m.spindle_on(600)                       # 10 rev/s
    hal.step(37)                            # some fraction of a turn
    pitch = 0.5
    m.queue_thread(xyz(z=-5.0), pitch, line=33)
    tr = hal.run(1500, record=["joint.2.pos-cmd", "spindle.0.revs",
                               "spindle.0.index-enable",
                               "motion.program-line"])
    z = tr["joint.2.pos-cmd"]
    revs = tr["spindle.0.revs"]
    armed = tr["spindle.0.index-enable"]
    assert armed.any(), "G33 arms index-enable"
    start = int(np.argmax(z < 0))
    assert start > int(np.argmax(armed))
    assert not armed[start:].any()
    # once up to speed, z follows pitch x revolutions since the index
    # (10 rev/s x 0.5 = 5 units/s)
    v = -np.diff(z) / 1e-3
    mid = slice(start + 300, start + 800)
    assert v[mid] == pytest.approx(5.0, abs=0.05)
    lag = -z[mid] - pitch * revs[mid]
    assert np.ptp(lag) < 0.01
    assert set(np.unique(tr["motion.program-line"][start:start + 900])) \
        == {33}
    st = m.wait_done()
    assert st.carte_pos_cmd.z == pytest.approx(-5.0, abs=1e-9)


def test_g33_needs_the_spindle_on(hal, m):
    with pytest.raises(Rejected, match="needs spindle 0 turning"):
        m.spindle_sync_line(xyz(z=-1.0), 1.0)
    with pytest.raises(Rejected, match="pitch must be a positive"):
        m.spindle_on(100)
        m.spindle_sync_line(xyz(z=-1.0), 0.0)


def test_rigid_tap_goes_in_reverses_and_comes_back(hal):
    m = load_machine(hal, sim_spindle=True)
    m.spindle_on(300)                       # 5 rev/s
    hal.step(10)
    m.queue_rigid_tap(xyz(z=-3.0), 1.0, line=7)
    tr = hal.run(3000, record=["joint.2.pos-cmd", "spindle.0.reverse",
                               "spindle.0.forward", "spindle.0.speed-out"])
    z = tr["joint.2.pos-cmd"]
    rev = tr["spindle.0.reverse"]
    assert z.min() <= -3.0 + 1e-6 and z.min() > -3.3
    bottom = int(np.argmin(z))
    assert rev.any() and rev[bottom:].any()
    assert not rev[-1] and tr["spindle.0.forward"][-1]
    assert tr["spindle.0.speed-out"][-1] == 300
    st = m.wait_done()
    assert st.carte_pos_cmd.z == pytest.approx(0.0, abs=1e-9)
