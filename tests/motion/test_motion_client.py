"""The Python motion client (halsdk.motion) driving motmod, and the
exact-stop trajectory planner tpmod (directly through its halsdk_tp_api
table and through motmod's coordinated mode).

The machine: trivkins with three joints, each joint's motor-pos-cmd looped
back to its motor-pos-fb, stepped deterministically by the client.
"""

from __future__ import annotations

import ctypes as C
import dataclasses
import math
import subprocess
import sys
import threading

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as hst

from halsdk.core import _core
from halsdk.errors import HalError
from halsdk.motion import (
    HOME_SEQUENCE_NONE,
    EnableFailed,
    HomeFlag,
    Mode,
    Motion,
    MotionError,
    MotionTimeout,
    Rejected,
    homing_fields,
)

DT = 1e-3
VMAX, AMAX = 20.0, 200.0


def load_machine(hal, kins="trivkins", kins_args=None, num_joints=3):
    hal.loadrt(kins, **(kins_args or {}))
    hal.loadrt("homemod")
    hal.loadrt("tpmod")
    hal.loadrt("motmod", servo_period_nsec=1_000_000, num_joints=num_joints)
    hal.addf("motion-command-handler", "servo-thread")
    hal.addf("motion-controller", "servo-thread")
    for j in range(num_joints):
        hal.net(f"fb{j}", f"joint.{j}.motor-pos-cmd", f"joint.{j}.motor-pos-fb")
    m = Motion.connect(hal)
    m.configure(
        joints=[dict(MIN_LIMIT=-100, MAX_LIMIT=100, MAX_VELOCITY=VMAX,
                     MAX_ACCELERATION=AMAX, FERROR=1, MIN_FERROR=0.5)]
        * num_joints,
        axes={a: dict(MIN_LIMIT=-100, MAX_LIMIT=100, MAX_VELOCITY=VMAX,
                      MAX_ACCELERATION=AMAX) for a in "xyz"},
        traj=dict(MAX_LINEAR_VELOCITY=30, MAX_LINEAR_ACCELERATION=150))
    return m


@pytest.fixture
def machine(hal):
    return load_machine(hal)


def joint_trace(hal, n, joints=(0, 1, 2), pin="pos-cmd"):
    names = [f"joint.{j}.{pin}" for j in joints]
    tr = hal.run(n, record=names)
    return np.stack([tr[k] for k in names], axis=1)


def check_limits(p, vmax, amax, tol=1e-6):
    """Per-coordinate velocity and acceleration of a sampled trace."""
    v = np.diff(p, axis=0) / DT
    a = np.diff(v, axis=0) / DT
    assert np.abs(v).max() <= vmax * (1 + tol) + 1e-9
    assert np.abs(a).max() <= amax * (1 + tol) + 1e-6


# ------------------------------------------------------------ connecting


def test_connect_without_motmod_says_so(hal):
    with pytest.raises(MotionError, match="is motmod loaded"):
        Motion.connect(hal)


def test_rejected_and_motion_error_are_hal_errors():
    assert issubclass(Rejected, HalError)
    assert issubclass(MotionError, HalError)
    assert issubclass(MotionTimeout, TimeoutError)
    r = Rejected("JOG_INCR", "joint 7 does not exist")
    assert r.reason == "joint 7 does not exist" and "JOG_INCR" in str(r)


def test_status_snapshot_after_configure(machine):
    st = machine.status()
    assert st.mode == Mode.FREE and isinstance(st.mode, Mode)
    assert not st.enabled
    assert st.num_joints == 3 and len(st.joints) == 3 and len(st.axes) == 9
    j = st.joints[0]
    assert (j.min_pos_limit, j.max_pos_limit) == (-100, 100)
    assert (j.vel_limit, j.acc_limit) == (VMAX, AMAX)
    assert (j.min_ferror, j.max_ferror) == (0.5, 1)
    assert st.axes[0].letter == "x" and st.axes[0].vel_limit == VMAX
    assert st.vel_limit == 30 and st.acc_limit == 150
    assert st.homed == (False, False, False)
    with pytest.raises(dataclasses.FrozenInstanceError):
        st.enabled = True


# ------------------------------------------------------------ jogs


def test_jog_incr_twice_is_cumulative_and_limited(hal, machine):
    m = machine
    m.enable()
    m.jog_incr(0, 10, 1.0)
    m.jog_incr(0, 10, 1.0)          # while the first one moves
    p = joint_trace(hal, 400)
    assert p[-1, 0] == pytest.approx(2.0, abs=1e-12)
    assert p[-1, 1] == 0 and p[-1, 2] == 0
    check_limits(p, 10, AMAX)
    st = m.wait_inpos()
    assert st.joints[0].pos_cmd == pytest.approx(2.0, abs=1e-12)
    assert st.joints[0].pos_fb == pytest.approx(2.0, abs=1e-12)
    assert st.in_position and st.joints[0].in_position


def test_jog_abs_and_jog_cont_stop(hal, machine):
    m = machine
    m.enable()
    m.jog_abs(1, 15, -2.5)
    st = m.wait_inpos()
    assert st.joints[1].pos_cmd == pytest.approx(-2.5, abs=1e-12)
    m.jog_cont(2, -5)
    hal.step(300)
    st = m.status()
    assert st.joints[2].vel == pytest.approx(-5)
    assert not st.in_position
    m.jog_stop(2)
    st = m.wait_inpos()
    assert st.joints[2].vel == 0 and st.joints[2].pos_cmd < -1.0


@pytest.mark.parametrize("call, words", [
    (lambda m: m.jog_incr(7, 10, 1), ["joint 7"]),
    (lambda m: m.jog_incr(-3, 10, 1), ["joint -3"]),
    (lambda m: m.jog_incr(0, math.nan, 1), ["velocity", "nan"]),
    (lambda m: m.jog_incr(0, -1, 1), ["velocity"]),
    (lambda m: m.jog_abs(0, 10, math.inf), ["inf"]),
    (lambda m: m.set_joint_max_velocity(9, 1), ["joint 9"]),
    (lambda m: m.set_joint_max_acceleration(0, -5), ["-5"]),
    (lambda m: m.set_feed_scale(math.nan), ["nan"]),
    (lambda m: m.set_axis_max_velocity(12, 3), ["12"]),
])
def test_bad_arguments_are_rejected_with_reason(machine, call, words):
    machine.enable()
    with pytest.raises(Rejected) as e:
        call(machine)
    assert e.value.reason
    for w in words:
        assert w in e.value.reason.lower()


def test_jog_while_disabled_is_rejected(machine):
    with pytest.raises(Rejected, match="enabled"):
        machine.jog_incr(0, 10, 1)
    assert machine.status().joints[0].pos_cmd == 0


def test_mode_change_while_moving_is_rejected(hal, machine):
    m = machine
    m.enable()
    m.jog_cont(0, 5)
    hal.step(10)
    with pytest.raises(Rejected):
        m.coord()
    assert m.status().mode == Mode.FREE
    m.abort()
    m.wait_inpos()
    m.coord()
    assert m.status().mode == Mode.COORD


def test_coord_needs_homing_with_nontrivial_kins(hal):
    m = load_machine(hal, kins_args={"kinstype": "b"})
    m.enable()
    with pytest.raises(Rejected, match="home"):
        m.coord()
    assert m.status().mode == Mode.FREE


def test_teleop_axis_jogs_by_letter_and_number(hal, machine):
    m = machine
    m.enable()
    m.teleop()
    assert m.status().mode == Mode.TELEOP
    m.jog_incr("y", 5, 1.25)
    st = m.wait_inpos()
    assert st.axes[1].pos_cmd == pytest.approx(1.25, abs=1e-9)
    assert st.joints[1].pos_cmd == pytest.approx(1.25, abs=1e-9)
    m.jog_abs(2, 5, -0.5, teleop=True)
    st = m.wait_inpos()
    assert st.carte_pos_cmd.z == pytest.approx(-0.5, abs=1e-9)
    with pytest.raises(ValueError, match="axis letter"):
        m.jog_incr("q", 5, 1)


# ------------------------------------------------------------ errors


def test_amp_fault_disables_and_reports(hal, machine):
    m = machine
    m.enable()
    assert m.errors() == []
    hal.set({"joint.1.amp-fault-in": True})
    st = m.wait_for(lambda s: not s.enabled, timeout=0.1,
                    what="the fault disabling motion")
    assert st.joints[1].faulted
    assert st.errors, "the status shows the pending message"
    msgs = m.errors()
    assert any("1" in t and "fault" in t.lower() for t in msgs), msgs
    assert m.errors() == []         # taken


def test_motion_enable_pin_false_disables_and_refuses_enable(hal, machine):
    m = machine
    m.enable()
    hal.set({"motion.enable": False})
    st = m.wait_for(lambda s: not s.enabled, timeout=0.1)
    assert st.errors
    with pytest.raises(Rejected, match="motion.enable"):
        m.enable()
    hal.set({"motion.enable": True})
    m.enable()
    assert m.status().enabled


# ------------------------------------------------------------ enable


@pytest.mark.parametrize("pins,joint,fault,text", [
    ({"joint.1.amp-fault-in": True}, 1, "amp-fault",
     "joint 1 amplifier fault (joint.1.amp-fault-in is true)"),
    ({"joint.2.pos-lim-sw-in": True}, 2, "pos-hard-limit",
     "joint 2 on its positive hard limit (joint.2.pos-lim-sw-in is true)"),
    ({"joint.0.neg-lim-sw-in": True}, 0, "neg-hard-limit",
     "joint 0 on its negative hard limit (joint.0.neg-lim-sw-in is true)"),
    ({"spindle.0.amp-fault-in": True}, None, "spindle-amp-fault",
     "spindle 0 amplifier fault (spindle.0.amp-fault-in is true)"),
])
def test_enable_with_a_fault_raises_the_reason(hal, machine, pins, joint,
                                               fault, text):
    m = machine
    hal.set(pins)
    with pytest.raises(EnableFailed) as e:
        m.enable()
    assert isinstance(e.value, Rejected) and e.value.command == "ENABLE"
    assert str(e.value) == f"ENABLE rejected: {text}"
    assert (e.value.joint, e.value.fault) == (joint, fault)
    assert e.value.messages and "motion disabled" in e.value.messages[-1]
    st = m.status()
    assert not st.enabled and st.error
    # the message stays for errors() (the task's error channel)
    assert any("motion disabled" in t for t in m.errors())
    hal.set({k: False for k in pins})
    m.enable()
    assert m.status().enabled


def test_enable_with_a_misc_error_raises_the_reason(hal):
    """A misc-error input that is true disables motion at once: enable()
    says which input."""
    hal.loadrt("trivkins")
    hal.loadrt("homemod")
    hal.loadrt("tpmod")
    hal.loadrt("motmod", servo_period_nsec=1_000_000, num_joints=1,
               num_misc_error=3)
    hal.addf("motion-command-handler", "servo-thread")
    hal.addf("motion-controller", "servo-thread")
    hal.net("fb0", "joint.0.motor-pos-cmd", "joint.0.motor-pos-fb")
    m = Motion.connect(hal)
    hal.set({"motion.misc-error-02": True})
    with pytest.raises(EnableFailed) as e:
        m.enable()
    assert (e.value.joint, e.value.fault) == (None, "misc-error")
    assert "motion.misc-error-02 is true" in str(e.value)
    assert not m.status().enabled
    hal.set({"motion.misc-error-02": False})
    m.enable()
    assert m.status().enabled


def test_enable_with_motion_enable_false_is_refused(hal, machine):
    hal.set({"motion.enable": False})
    with pytest.raises(Rejected, match="motion.enable is false"):
        machine.enable()
    assert not machine.status().enabled


def test_enable_with_limits_overridden_stays_enabled(hal, machine):
    m = machine
    hal.set({"joint.1.pos-lim-sw-in": True})
    m.override_limits(True)
    m.enable()
    assert m.status().enabled
    m.jog_incr(1, 5, -0.5)              # off the switch
    hal.run(50)
    hal.set({"joint.1.pos-lim-sw-in": False})
    m.wait_inpos()
    assert m.status().enabled


def test_enable_when_the_fault_comes_in_the_same_cycle(hal, machine):
    """A fault that motmod sees only in the controller cycle after the
    command (motion-controller before the command handler in the thread)
    is still caught."""
    hal.delf("motion-controller", "servo-thread")
    hal.addf("motion-controller", "servo-thread", position=1)
    m = machine
    hal.set({"joint.0.amp-fault-in": True})
    with pytest.raises(EnableFailed, match="joint 0 amplifier fault"):
        m.enable()


def test_enable_with_a_fault_and_threads_running(hal, machine):
    """Not stepped: enable() polls the status and still sees the drop."""
    m = machine
    hal.set({"joint.2.amp-fault-in": True})
    hal.start()
    try:
        with pytest.raises(EnableFailed, match="joint 2 amplifier fault"):
            m.enable(timeout=5)
        hal.set({"joint.2.amp-fault-in": False})
        m.enable(timeout=5)
        assert m.status().enabled
    finally:
        hal.stop()


def test_enable_without_the_controller_times_out_clearly(hal, machine):
    hal.delf("motion-controller", "servo-thread")
    with pytest.raises(MotionTimeout, match="motion-controller"):
        machine.enable(timeout=0.01)


# ------------------------------------------------------------ jogs and limits


def _homed_machine(m):
    """Every joint homed where it stands (0), soft limits -2 .. 3."""
    for j in range(3):
        m.set_joint_homing(j, HOME=0, HOME_OFFSET=0, HOME_SEARCH_VEL=0,
                           HOME_SEQUENCE=0)
        m.set_joint_limits(j, -2.0, 3.0)
    for a in "xyz":
        m.set_axis_limits(a, -2.0, 3.0)
    m.enable()
    m.home(-1)
    m.wait_homed(timeout=2)
    m.wait_inpos()
    return m


def test_jog_abs_beyond_a_soft_limit_is_refused_and_nothing_moves(machine):
    m = _homed_machine(machine)
    with pytest.raises(Rejected, match=r"JOG_ABS: joint 0 target 7 is beyond "
                       r"its positive soft limit \(3\)"):
        m.jog_abs(0, 10, 7.0)
    with pytest.raises(Rejected, match=r"joint 1 target -2\.5 is beyond its "
                       r"negative soft limit \(-2\)"):
        m.jog_abs(1, 10, -2.5)
    st = m.status()
    assert st.in_position and not st.joints[0].jog_active
    assert [j.pos_cmd for j in st.joints] == [0.0, 0.0, 0.0]
    m.jog_abs(0, 10, 3.0)               # exactly on the limit: fine
    assert m.wait_inpos().joints[0].pos_cmd == 3.0
    # an increment past the limit still ends at it (the reference's
    # "terminated at the soft limit")
    m.jog_abs(0, 10, 2.5)
    m.wait_inpos()
    m.jog_incr(0, 10, 2.0)
    assert m.wait_inpos().joints[0].pos_cmd == 3.0
    # teleop: an axis target beyond its limit is refused the same way
    m.jog_abs(0, 10, 0.0)
    m.wait_inpos()
    m.teleop()
    with pytest.raises(Rejected, match=r"JOG_ABS: axis X target 4 is beyond "
                       r"its positive limit \(3\)"):
        m.jog_abs("x", 10, 4.0, teleop=True)
    assert m.status().axes[0].teleop_target == pytest.approx(0.0)
    m.jog_abs("x", 10, -1.0, teleop=True)
    assert m.wait_inpos().carte_pos_cmd.x == pytest.approx(-1.0, abs=1e-9)


def test_jog_abs_unhomed_ignores_the_soft_limits(machine):
    m = machine
    m.set_joint_limits(0, -2.0, 3.0)
    m.enable()
    m.jog_abs(0, 20, 4.0)               # soft limits need homing
    assert m.wait_inpos().joints[0].pos_cmd == pytest.approx(4.0)


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(joint=hst.integers(0, 2),
       target=hst.floats(-6.0, 6.0, allow_nan=False))
def test_jog_abs_is_accepted_exactly_within_the_soft_limits(machine, joint,
                                                            target):
    """Homed: a JOG_ABS is accepted iff its target lies within the soft
    limits, and then aims at the target itself (never a clamped one)."""
    m = machine
    if not m.status().all_homed:
        _homed_machine(m)
    inside = -2.0 <= target <= 3.0
    try:
        m.jog_abs(joint, 20, target)
    except Rejected as e:
        assert not inside, e
        assert "soft limit" in e.reason and f"joint {joint} " in e.reason
        assert not m.status().joints[joint].jog_active
        return
    assert inside
    assert m.status().joints[joint].free_target == target
    m.abort()
    m.wait_inpos()


FAULT_PINS = ("amp-fault-in", "pos-lim-sw-in", "neg-lim-sw-in")


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(faults=hst.sets(hst.tuples(hst.integers(0, 2), hst.sampled_from(
    FAULT_PINS)), max_size=4))
def test_enable_succeeds_exactly_when_no_fault_and_names_one(hal, machine,
                                                             faults):
    """enable() returns iff no joint has a fault; when it raises, the joint
    and fault it names are one that is there."""
    m = machine
    m.disable()
    pins = {f"joint.{j}.{p}": False for j in range(3) for p in FAULT_PINS}
    pins.update({f"joint.{j}.{p}": True for j, p in faults})
    hal.set(pins)
    kind = {"amp-fault-in": "amp-fault", "pos-lim-sw-in": "pos-hard-limit",
            "neg-lim-sw-in": "neg-hard-limit"}
    if not faults:
        m.enable()
        assert m.status().enabled
        return
    with pytest.raises(EnableFailed) as e:
        m.enable()
    assert not m.status().enabled
    named = (e.value.joint, e.value.fault)
    present = {(j, kind[p]) for j, p in faults}
    assert named in present, (named, present)
    assert f"joint {e.value.joint} " in e.value.reason
    m.errors()


def test_wait_timeout_is_clear(machine):
    with pytest.raises(MotionTimeout, match="simulated"):
        machine.wait_for(lambda s: s.enabled, timeout=0.01,
                         what="motion to enable itself")


def test_wait_done_raises_when_disabled(hal, machine):
    m = machine
    m.enable()
    m.coord()
    m.set_line({"x": 50}, vel=10)
    hal.step(50)
    m.disable()
    with pytest.raises(MotionError, match="disabled"):
        m.wait_done(timeout=1)


def test_client_lock_held_by_live_or_dead_process(machine):
    addr, _ = _core.shmem_attach("motmod.channel")
    lock = C.c_int32.from_address(addr + 12)       # lock_pid
    lock.value = 1                  # init: alive, not us
    with pytest.raises(MotionTimeout, match="lock"):
        Motion.connect(machine._hal, timeout=0.05).enable()
    assert not machine.status().enabled
    lock.value = 2 ** 22 + 12345    # no such process: a stale lock
    machine.enable()
    assert machine.status().enabled and lock.value == 0


CHILD = """
from halsdk.motion import Motion
m = Motion.connect(timeout=5)
for _ in range(30):
    m.jog_incr(1, 10, 0.01)
print("child done")
"""


def test_two_processes_send_commands(hal, machine, tmp_path):
    """The client lock lets commands of two processes through one at a
    time: every increment of both arrives."""
    m = machine
    m.enable()
    hal.start()
    try:
        # not the source tree as cwd: it holds no compiled core
        child = subprocess.Popen([sys.executable, "-c", CHILD],
                                 cwd=str(tmp_path), stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
        for _ in range(30):
            m.jog_incr(0, 10, 0.01)
        out, err = child.communicate(timeout=30)
        assert child.returncode == 0, err
        assert "child done" in out
        st = m.wait_inpos(timeout=5)
    finally:
        hal.stop()
    assert st.joints[0].pos_cmd == pytest.approx(0.3, abs=1e-9)
    assert st.joints[1].pos_cmd == pytest.approx(0.3, abs=1e-9)


def test_channel_gone_after_unload(hal, machine):
    hal.unloadrt("motmod")
    with pytest.raises(MotionError, match="gone"):
        machine.status()
    with pytest.raises(MotionError, match="gone"):
        machine.enable()


def test_status_is_consistent_under_concurrent_updates(hal, machine):
    """Read snapshots while the servo thread runs in another thread: the
    values of one cycle (from the start and the end of the status block)
    must never mix with those of another."""
    m = machine
    m.enable()
    m.jog_cont(0, 0.1)
    stop = threading.Event()

    def stepper():             # long steps without the GIL
        while not stop.is_set():
            hal.step(5000, thread="servo-thread")

    t = threading.Thread(target=stepper)
    switch = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    t.start()
    seen = {}
    mixed = []
    try:
        for _ in range(3000):
            st = m.status()
            j = st.joints[0]
            row = (j.pos_cmd, j.motor_pos_cmd, st.carte_pos_cmd.x,
                   st.axes[0].pos_cmd)
            if seen.setdefault(st.heartbeat, row) != row or \
                    row[2] != row[3] or row[0] != row[1]:
                mixed.append((st.heartbeat, row))
    finally:
        stop.set()
        t.join()
        sys.setswitchinterval(switch)
    m.abort()
    assert not mixed
    beats = sorted(seen)
    assert len(beats) > 10
    pos = [seen[b][0] for b in beats]
    assert pos == sorted(pos)


# ------------------------------------------------------------ coord moves


def test_line_and_circle_through_motmod(hal, machine):
    m = machine
    m.enable()
    m.coord()
    i1 = m.set_line({"x": 3, "y": 4}, vel=10)
    i2 = m.set_circle({"x": 5, "y": 6}, center=(5, 4, 0), normal=(0, 0, 1),
                      vel=8)
    assert i2 == i1 + 1
    st = m.status()
    assert st.queue_depth == 2
    p = joint_trace(hal, 2500)
    # exact ends; the line's end is visited
    assert tuple(p[-1]) == (5.0, 6.0, 0.0)
    assert np.min(np.linalg.norm(p[:, :2] - [3, 4], axis=1)) < 1e-12
    # the arc keeps its radius (points after the line's end)
    k = int(np.argmin(np.linalg.norm(p[:, :2] - [3, 4], axis=1)))
    r = np.linalg.norm(p[k:, :2] - [5, 4], axis=1)
    assert np.allclose(r, 2.0, atol=1e-9)
    # it went the counterclockwise way round: through (5, 2)
    assert np.min(np.linalg.norm(p[k:, :2] - [5, 2], axis=1)) < 0.01
    # path velocity within the requested, per-axis acceleration within
    # the path limit (SET_ACC 150)
    v = np.linalg.norm(np.diff(p, axis=0), axis=1) / DT
    assert v.max() <= 10 + 1e-9
    check_limits(p, VMAX, 150)
    st = m.wait_done()
    assert st.motion_id == i2 and st.queue_depth == 0


def test_feed_scale_pause_resume_and_probe_through_motmod(hal, machine):
    m = machine
    m.enable()
    m.coord()
    m.set_feed_scale(0.5)
    m.set_line({"x": 10}, vel=10)
    hal.step(1000)
    st = m.status()
    assert st.current_vel == pytest.approx(5) and st.feed_scale == 0.5
    m.pause()
    st = m.wait_for(lambda s: s.current_vel == 0, timeout=1)
    x = st.carte_pos_cmd.x
    hal.step(100)
    assert m.status().carte_pos_cmd.x == x and m.status().queue_depth == 1
    m.resume()
    m.set_feed_scale(1)
    st = m.wait_done(timeout=5)
    assert st.carte_pos_cmd.x == 10
    # probe toward x=0; the input trips after 300 cycles
    m.probe({"x": 0}, vel=5)
    hal.step(300)
    hal.set({"motion.probe-input": True})
    st = m.wait_done(timeout=5)
    assert st.probe_tripped
    assert 8 < st.probed_pos.x < 9 and st.carte_pos_cmd.x < st.probed_pos.x
    with pytest.raises(Rejected, match="probe"):
        m.probe({"x": 0}, vel=5)    # the flag is still set
    hal.set({"motion.probe-input": False})
    m.clear_probe_flag()
    assert not m.status().probe_tripped


def test_coord_move_rejections(machine):
    m = machine
    m.enable()
    with pytest.raises(Rejected):        # free mode
        m.set_line({"x": 1}, vel=10)
    m.coord()
    with pytest.raises(Rejected, match="nan"):
        m.set_line([math.nan] + [0] * 8, vel=10)
    with pytest.raises(Rejected, match="velocity"):
        m.set_line({"x": 1}, vel=0)
    with pytest.raises(Rejected, match="radius zero|normal"):
        m.set_circle({"x": 1}, center=(0, 0, 0), normal=(0, 0, 1), vel=1)
    assert m.status().queue_depth == 0


def test_pose_argument_checks(machine):
    with pytest.raises(ValueError, match="9 values"):
        machine.set_line([1, 2, 3], vel=1)
    with pytest.raises(ValueError, match="axis letter"):
        machine.set_line({"q": 1}, vel=1)


# ------------------------------------------------------------ configure


def test_configure_rejects_unknown_keys_before_sending(machine):
    with pytest.raises(ValueError, match=r"\[JOINT_1\].*MAX_VELOCITYY"):
        machine.configure(joints=[{}, {"MAX_VELOCITYY": 3}])
    with pytest.raises(ValueError, match=r"\[AXIS_X\].*FOO"):
        machine.configure(axes={"x": {"foo": 1}})
    with pytest.raises(ValueError, match="MAX_VELOCITY = 'fast'"):
        machine.configure(joints=[{"max_velocity": "fast"}])
    assert machine.status().joints[0].vel_limit == VMAX


def test_homing_keys_map_to_fields():
    f = homing_fields({"HOME_SEARCH_VEL": "-2.5", "home_latch_vel": 0.5,
                       "HOME_SEQUENCE": "-1", "HOME_USE_INDEX": "YES",
                       "HOME_ABSOLUTE_ENCODER": 2, "VOLATILE_HOME": 1})
    assert f["home_search_vel"] == -2.5 and f["home_latch_vel"] == 0.5
    assert f["home_sequence"] == -1 and f["volatile_home"] == 1
    assert f["home_flags"] == (HomeFlag.USE_INDEX | HomeFlag.ABSOLUTE_ENCODER
                               | HomeFlag.NO_FINAL_MOVE)
    assert homing_fields({})["home_sequence"] == HOME_SEQUENCE_NONE
    with pytest.raises(ValueError, match="HOME_ABSOLUTE_ENCODER"):
        homing_fields({"HOME_ABSOLUTE_ENCODER": 3})
    with pytest.raises(ValueError, match="HOME_BOGUS"):
        homing_fields({"HOME_BOGUS": 3})
    with pytest.raises(ValueError, match="yes/no"):
        homing_fields({"HOME_USE_INDEX": "perhaps"})


def test_load_comp_file_sends_the_table(machine, tmp_path, monkeypatch):
    path = tmp_path / "x.comp"
    path.write_text("# nominal forward reverse\n-10 -10.01 -9.99\n"
                    "0 0.02 0.01\n10 10.03 10.02\n")
    sent = []
    monkeypatch.setattr(machine, "command",
                        lambda cmd, **f: sent.append((cmd.name, f)))
    assert machine.load_comp_file(2, str(path), type=0) == 3
    assert sent[0] == ("CLEAR_JOINT_COMP", {"joint": 2})
    assert np.allclose([f["comp"] for _, f in sent[1:]],
                       [(-10, -0.01, 0.01), (0, 0.02, 0.01),
                        (10, 0.03, 0.02)], atol=1e-12)
    assert all(n == "SET_JOINT_COMP" and f["joint"] == 2
               for n, f in sent[1:])
    # a bad line: an error naming file and line, nothing sent
    sent.clear()
    path.write_text("0 0 0\n1 1 one\n")
    with pytest.raises(ValueError, match=r"x.comp:2:"):
        machine.load_comp_file(0, str(path))
    with pytest.raises(ValueError, match=r"x.comp:2:"):
        machine.configure(joints=[{"COMP_FILE": str(path)}])
    assert sent == []


def test_set_joint_homing_and_home_one_joint(hal, machine):
    m = machine
    m.set_joint_homing(0, HOME=1.5, HOME_OFFSET=0, HOME_SEARCH_VEL=0,
                       HOME_SEQUENCE=0)
    m.enable()
    m.home(0)
    st = m.wait_homed([0], timeout=2)
    assert st.joints[0].homed and not st.joints[1].homed
    st = m.wait_inpos()
    assert st.joints[0].pos_cmd == pytest.approx(1.5, abs=1e-9)
