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

from halsdk import _core
from halsdk.errors import HalError
from halsdk.motion import (
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
    assert f["home_flags"] == 0x0002 | 0x0010 | 0x0040
    assert homing_fields({})["home_sequence"] == -1000   # not set
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


# ------------------------------------------------------------ tpmod alone
#
# The planner's table (tp.h) called through ctypes, one cycle per call.


class Cart(C.Structure):
    _fields_ = [("x", C.c_double), ("y", C.c_double), ("z", C.c_double)]


class Pose9(C.Structure):
    _fields_ = [("tran", Cart)] + [(n, C.c_double) for n in "abcuvw"]

    def values(self):
        t = self.tran
        return [t.x, t.y, t.z] + [getattr(self, n) for n in "abcuvw"]


def pose9(*v):
    v = list(v) + [0.0] * (9 - len(v))
    return Pose9(Cart(*v[:3]), *v[3:])


class Move(C.Structure):
    _fields_ = [("id", C.c_int), ("type", C.c_int), ("vel", C.c_double),
                ("ini_maxvel", C.c_double), ("acc", C.c_double),
                ("jerk", C.c_double), ("term_cond", C.c_int),
                ("tolerance", C.c_double), ("flags", C.c_uint)]


class Inputs(C.Structure):
    _fields_ = [("probe_input", C.c_int), ("spindle_revs", C.c_double),
                ("spindle_speed", C.c_double),
                ("spindle_at_speed", C.c_int)]


_F = C.CFUNCTYPE
_P = C.POINTER
_W = [C.c_char_p, C.c_int]


class TpApi(C.Structure):
    _fields_ = [
        ("version", C.c_int),
        ("init", _F(C.c_int, C.c_int, C.c_double, C.c_void_p, *_W)),
        ("set_vel_limit", _F(None, C.c_double)),
        ("set_axis_limits", _F(None, C.c_int, C.c_double, C.c_double)),
        ("set_pos", _F(C.c_int, _P(Pose9), *_W)),
        ("get_pos", _F(None, _P(Pose9))),
        ("add_line", _F(C.c_int, _P(Pose9), _P(Move), *_W)),
        ("add_circle", _F(C.c_int, _P(Pose9), _P(Cart), _P(Cart), C.c_int,
                          _P(Move), *_W)),
        ("add_probe", _F(C.c_int, _P(Pose9), _P(Move), C.c_int, *_W)),
        ("set_dout", _F(C.c_int, C.c_int, C.c_int, C.c_int)),
        ("set_aout", _F(C.c_int, C.c_int, C.c_double, C.c_int)),
        ("abort", _F(None)), ("pause", _F(None)), ("resume", _F(None)),
        ("step", _F(None)),
        ("set_scale", _F(None, C.c_double, C.c_double)),
        ("run_cycle", _F(None, _P(Inputs), _P(Pose9))),
        ("get_state", _F(None, C.c_void_p)),
        ("is_done", _F(C.c_int)), ("queue_depth", _F(C.c_int)),
        ("queue_space", _F(C.c_int)), ("exec_id", _F(C.c_int)),
        ("distance_to_go", _F(C.c_double)),
        ("current_vel", _F(C.c_double)),
        ("probe_result", _F(C.c_int, _P(Pose9))),
        ("clear_probe", _F(None)),
        ("take_error", _F(C.c_char_p)),
    ]


class Planner:
    """tpmod driven cycle by cycle."""

    def __init__(self, hal):
        hal.loadrt("tpmod")
        self.api = TpApi.from_address(_core.symbol_address("halsdk_tp_api"))
        self.why = C.create_string_buffer(200)
        assert self.api.version == 1
        assert self.api.init(0, DT, None, self.why, 200) == 0
        self.inputs = Inputs()
        self.out = Pose9()
        self.next_id = 1

    def move(self, vel=10.0, acc=100.0, maxvel=None, type=2, id=None):
        if id is None:
            id, self.next_id = self.next_id, self.next_id + 1
        return Move(id=id, type=type, vel=vel,
                    ini_maxvel=maxvel if maxvel else vel, acc=acc)

    def line(self, end, **kw):
        r = self.api.add_line(pose9(*end), self.move(**kw), self.why, 200)
        return r, self.why.value.decode()

    def circle(self, end, center, normal, turn=0, **kw):
        r = self.api.add_circle(pose9(*end), Cart(*center), Cart(*normal),
                                turn, self.move(**kw), self.why, 200)
        return r, self.why.value.decode()

    def run(self, n=None, probe=None, until_done=True):
        """Cycles until done (or n); the positions as an array."""
        out = []
        k = 0
        while n is None or k < n:
            if probe is not None:
                self.inputs.probe_input = int(probe(k))
            self.api.run_cycle(self.inputs, self.out)
            out.append(self.out.values())
            k += 1
            if until_done and n is None and self.api.is_done():
                break
            assert k < 200_000
        return np.array(out)


@pytest.fixture
def tp(hal):
    return Planner(hal)


def test_tp_lines_exact_ends_and_limits(tp):
    assert tp.line((1, 2, 0), vel=10, acc=100)[0] == 0
    assert tp.line((1, 2, -3), vel=5, acc=50)[0] == 0
    assert tp.api.queue_depth() == 2
    p = tp.run()
    assert p[-1].tolist() == [1, 2, -3, 0, 0, 0, 0, 0, 0]
    assert np.min(np.linalg.norm(p[:, :3] - [1, 2, 0], axis=1)) == 0
    v = np.linalg.norm(np.diff(p[:, :3], axis=0), axis=1) / DT
    a = np.linalg.norm(np.diff(np.diff(p[:, :3], axis=0), axis=0),
                       axis=1) / DT**2
    assert v.max() == pytest.approx(10) and v.max() <= 10 + 1e-9
    assert a.max() <= 100 * (1 + 1e-9)
    # second move: slower
    k = int(np.argmin(np.linalg.norm(p[:, :3] - [1, 2, 0], axis=1)))
    assert v[k + 1:].max() <= 5 + 1e-9
    assert tp.api.exec_id() == 2 and tp.api.is_done()


def test_tp_circle_helix_any_plane(tp):
    # a helix about an axis along (1, 1, 0) through (0, 0, 0), with the
    # A axis moving along
    n = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)
    start = np.array([0.0, 0.0, 2.0])
    end = start + 1.5 * n                       # 1 full turn + rise 1.5
    tp.api.set_pos(pose9(*start), tp.why, 200)
    assert tp.circle(tuple(end) + (90,), (0, 0, 0), tuple(n), turn=0,
                     vel=6, acc=80)[0] == 0
    p = tp.run()
    assert np.allclose(p[-1, :4], list(end) + [90], atol=1e-12)
    rel = p[:, :3]
    h = rel @ n
    radial = np.linalg.norm(rel - np.outer(h, n), axis=1)
    assert np.allclose(radial, 2.0, atol=1e-9)
    assert np.all(np.diff(h) >= -1e-12)          # rises steadily
    v = np.linalg.norm(np.diff(p[:, :3], axis=0), axis=1) / DT
    a = np.linalg.norm(np.diff(np.diff(p[:, :3], axis=0), axis=0),
                       axis=1) / DT**2
    assert v.max() <= 6 + 1e-9
    assert a.max() <= 80 * 1.001
    # the A axis moves in proportion
    assert np.all(np.diff(p[:, 3]) >= 0) and p[-1, 3] == 90


def test_tp_rotary_only_and_uvw_lines(tp):
    assert tp.line((0, 0, 0, 45), vel=90, acc=900)[0] == 0
    assert tp.line((0, 0, 0, 45, 0, 0, 2, 0, 0), vel=4, acc=40)[0] == 0
    p = tp.run()
    assert p[-1, 3] == 45 and p[-1, 6] == 2
    va = np.abs(np.diff(p[:, 3])) / DT
    vu = np.abs(np.diff(p[:, 6])) / DT
    assert va.max() == pytest.approx(90) and vu.max() == pytest.approx(4)


def test_tp_axis_limits_bound_the_path(tp):
    tp.api.set_axis_limits(1, 2.0, 10.0)        # Y slow
    tp.line((3, 4, 0), vel=50, acc=500)
    p = tp.run()
    vy = np.abs(np.diff(p[:, 1])) / DT
    ay = np.abs(np.diff(np.diff(p[:, 1]))) / DT**2
    assert vy.max() <= 2 + 1e-9 and ay.max() <= 10 * (1 + 1e-9)
    assert p[-1, 1] == 4


def test_tp_feed_scale_pause_resume_abort(tp):
    tp.line((100, 0, 0), vel=10, acc=100)
    tp.api.set_scale(0.5, 1.0)
    p = tp.run(300)
    assert (p[-1, 0] - p[-2, 0]) / DT == pytest.approx(5)
    tp.api.pause()
    q = tp.run(300)
    assert q[-1, 0] == q[-2, 0] and tp.api.queue_depth() == 1
    dv = np.abs(np.diff(np.diff(np.r_[p[-2:, 0], q[:, 0]]))) / DT**2
    assert dv.max() <= 100 * (1 + 1e-9)
    tp.api.set_scale(1.0, 1.0)
    tp.api.resume()
    r = tp.run(300)
    assert (r[-1, 0] - r[-2, 0]) / DT == pytest.approx(10)
    tp.api.abort()
    s = tp.run()
    assert tp.api.is_done() and tp.api.queue_depth() == 0
    dv = np.abs(np.diff(np.diff(np.r_[r[-2:, 0], s[:, 0]]))) / DT**2
    assert dv.max() <= 100 * (1 + 1e-9)
    assert s[-1, 0] < 100
    # the next move starts where the abort stopped
    tp.line((0, 0, 0), vel=10, acc=100)
    assert tp.run()[-1, 0] == 0


def test_tp_step_pauses_after_one_move(tp):
    for x in (1, 2, 3):
        tp.line((x, 0, 0), vel=10, acc=100)
    tp.api.pause()
    assert tp.run(50)[-1, 0] == 0
    tp.api.step()
    p = tp.run(1000, until_done=False)
    assert p[-1, 0] == 1 and tp.api.queue_depth() == 2
    tp.api.resume()
    assert tp.run()[-1, 0] == 3


def test_tp_probe_trips_records_and_stops(tp):
    r = tp.api.add_probe(pose9(10), tp.move(vel=5, acc=100), 0, tp.why, 200)
    assert r == 0
    tp.line((0, 0, 0))                          # dropped by the trip
    p = tp.run(probe=lambda k: k >= 500)
    where = Pose9()
    assert tp.api.probe_result(C.byref(where)) == 1
    x = where.values()[0]
    assert x == pytest.approx(p[499, 0], abs=1e-12)
    assert p[-1, 0] > x and p[-1, 0] - x < 5 * 5 / 100  # stopped soon
    assert tp.api.queue_depth() == 0
    # a probe already tripped at the start: error, nothing moves
    tp.api.clear_probe()
    tp.api.add_probe(pose9(20), tp.move(vel=5), 0, tp.why, 200)
    q = tp.run(probe=lambda k: 1)
    assert q[-1, 0] == p[-1, 0]
    assert b"already tripped" in tp.api.take_error()
    # no contact: error unless asked not to
    tp.api.add_probe(pose9(11), tp.move(vel=5), 0, tp.why, 200)
    tp.run(probe=lambda k: 0)
    assert tp.api.probe_result(None) == -1
    assert b"without contact" in tp.api.take_error()
    tp.api.add_probe(pose9(12), tp.move(vel=5), 1, tp.why, 200)
    tp.run(probe=lambda k: 0)
    assert tp.api.take_error() == b""


def test_tp_deep_queue_and_bad_moves(tp):
    for k in range(500):
        assert tp.line((0.01 * (k + 1), 0, 0), vel=10, acc=100)[0] == 0
    assert tp.api.queue_depth() == 500
    assert tp.api.queue_space() == 2000 - 500
    p = tp.run()
    assert p[-1, 0] == pytest.approx(5.0, abs=1e-12)
    for bad, words in [(dict(vel=math.nan), "velocity"),
                       (dict(vel=-1), "velocity"),
                       (dict(acc=0), "acceleration"),
                       (dict(type=99), "motion type")]:
        r, why = tp.line((1, 1, 1), **bad)
        assert r < 0 and words in why
    r, why = tp.line((math.inf, 0, 0))
    assert r < 0 and "finite" in why
    r, why = tp.circle((1, 0, 0), (0, 0, 0), (0, 0, 0))
    assert r < 0 and "normal" in why
    assert tp.api.queue_depth() == 0


class Hooks(C.Structure):
    _fields_ = [("set_dout", C.CFUNCTYPE(None, C.c_int, C.c_int)),
                ("set_aout", C.CFUNCTYPE(None, C.c_int, C.c_double))]


def test_tp_synchronized_outputs_fire_when_the_next_move_starts(tp):
    log = []
    hooks = Hooks(Hooks._fields_[0][1](lambda i, v: log.append(("d", i, v))),
                  Hooks._fields_[1][1](lambda i, v: log.append(("a", i, v))))
    assert tp.api.init(0, DT, C.addressof(hooks), tp.why, 200) == 0
    tp.line((1, 0, 0))
    assert tp.api.set_dout(3, 1, 0) == 0        # with the next move
    assert tp.api.set_aout(1, 2.5, 1) == 0      # now
    assert log == [("a", 1, 2.5)]
    tp.line((1, 0, 0))                          # zero length
    tp.line((2, 0, 0))
    n1 = len(tp.run(1))                         # first move starts
    assert n1 == 1 and log == [("a", 1, 2.5)]
    p = tp.run()
    assert log == [("a", 1, 2.5), ("d", 3, 1)]
    assert p[-1, 0] == 2 and tp.api.exec_id() == 3
    assert tp.api.set_dout(64, 1, 0) < 0        # no such output
