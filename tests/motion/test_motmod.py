"""The motion module motmod: loading, command channel, modes, jogs, limits.

Load listings are compared with the reference's in
tests/golden/test_motmod_listings.py.  Commands go through the shared block
"motmod.channel" with a ctypes view of components/motion/channel.h built
from the layout the compiled halsdk.motion._channel reports (numbers from
halsdk.motion.protocol), so these tests depend on no client library; each
command is echoed after one servo cycle (the handler runs first in the
servo thread).
"""

from __future__ import annotations

import ctypes as C
import math
import re

import numpy as np
import pytest
from helpers import data_path

import halsdk
from halsdk.core import _core
from halsdk.motion import _channel
from halsdk.motion.protocol import (
    Cmd,
    Echo,
    JointFlag,
    KinsType,
    Mode,
    MotionType,
    Profile,
)

MOTION = data_path("motion")
DT = 0.001                      # servo period of the tests (s)

# ------------------------------------------------------ channel view

# The numbers come from halsdk.motion.protocol and the structures' layout
# from the compiled halsdk.motion._channel (both from channel.h); this is
# a ctypes view built from that layout, so the test reads and writes the
# block itself (raw records, sequence numbers) without the client.

AXES = [f[0] for f in _channel.LAYOUT["EmcPose"][1]]     # x y z a ... w
_SCALARS = {"i32": C.c_int32, "u32": C.c_uint32, "u64": C.c_uint64,
            "f64": C.c_double, "char": C.c_char}
_VIEWS: dict[str, type] = {}


def _view(name: str) -> type:
    """A ctypes structure with the fields of ``name`` where the compiler
    put them (_channel.LAYOUT); padding and reserved fields unnamed."""
    if name in _VIEWS:
        return _VIEWS[name]
    size, fields = _channel.LAYOUT[name]
    out, at = [], 0
    for fname, offset, kind, count in fields:
        assert offset >= at, f"{name}.{fname} overlaps the field before"
        if offset > at:
            out.append((f"_pad{at}", C.c_char * (offset - at)))
        t = _SCALARS[kind] if kind in _SCALARS else _view(kind)
        out.append((fname, t * count if count > 1 else t))
        at = offset + C.sizeof(t) * count
    assert at <= size, f"{name} is larger than sizeof ({at} > {size})"
    if size > at:
        out.append((f"_pad{at}", C.c_char * (size - at)))
    view = type(name, (C.Structure,), {"_pack_": 1, "_fields_": out})
    assert C.sizeof(view) == size
    _VIEWS[name] = view
    return view


EmcPose = _view("EmcPose")
Cart = _view("PmCartesian")
Command = _view("mot_command_t")
Status = _view("mot_status_t")
Channel = _view("mot_channel_t")


class Machine:
    """A motmod machine in the test's HAL, commanded through the channel.
    Feedback is looped back (motor-pos-cmd -> motor-pos-fb) unless
    loop=False."""

    def __init__(self, hal, joints=3, kins="trivkins", kins_args=(),
                 loop=True, **modparams):
        self.hal = hal
        hal.loadrt(kins, *kins_args)
        hal.loadrt("homemod")
        hal.loadrt("tpmod")
        hal.loadrt("motmod", num_joints=joints, **modparams)
        hal.addf("motion-command-handler", "servo-thread")
        hal.addf("motion-controller", "servo-thread")
        if loop:
            for j in range(joints):
                hal.command(f"net fb{j} joint.{j}.motor-pos-cmd "
                            f"joint.{j}.motor-pos-fb")
        addr, size = _core.shmem_attach("motmod.channel")
        assert size >= C.sizeof(Channel)
        self.ch = Channel.from_address(addr)
        self.msgs_read = 0

    def send(self, cmd, **kw):
        """Send one command, run one cycle, return (status, reason)."""
        c = Command()
        c.joint = c.axis = -1
        c.cmd = cmd
        for k, v in kw.items():
            if k in AXES:
                setattr(c.pos, k, v)
            else:
                setattr(c, k, v)
        ch = self.ch
        assert ch.echo_seq == ch.cmd_seq
        ch.command = c
        ch.cmd_seq = ch.cmd_seq + 1
        self.hal.step(1)
        assert ch.echo_seq == ch.cmd_seq, "the handler did not echo"
        assert ch.echo_cmd == cmd
        return ch.echo_status, ch.echo_reason.decode()

    def ok(self, cmd, **kw):
        st, why = self.send(cmd, **kw)
        assert st in (Echo.DONE, Echo.ACCEPTED), why
        assert why == ""
        return st

    def no(self, cmd, **kw):
        st, why = self.send(cmd, **kw)
        assert st == Echo.REJECTED
        assert why, "a rejection without a reason"
        return why

    @property
    def status(self) -> Status:
        """A consistent copy of the snapshot (seqlock read)."""
        ch = self.ch
        while True:
            s1 = ch.status_seq
            if s1 & 1:
                continue
            copy = Status.from_buffer_copy(ch.status)
            if ch.status_seq == s1:
                return copy

    def messages(self) -> list[str]:
        out = []
        while self.msgs_read < self.ch.msg_count:
            m = self.ch.msgs[self.msgs_read % _channel.MSG_RING]
            assert m.n == self.msgs_read
            out.append(m.text.decode())
            self.msgs_read += 1
        return out

    def config_joint(self, j, vel=10.0, acc=100.0, lo=-100.0, hi=100.0,
                     min_ferror=1.0, max_ferror=2.0):
        self.ok(Cmd.SET_JOINT_VEL_LIMIT, joint=j, vel=vel)
        self.ok(Cmd.SET_JOINT_ACC_LIMIT, joint=j, acc=acc)
        self.ok(Cmd.SET_JOINT_POSITION_LIMITS, joint=j, min_limit=lo,
                max_limit=hi)
        self.ok(Cmd.SET_JOINT_MIN_FERROR, joint=j, value=min_ferror)
        self.ok(Cmd.SET_JOINT_MAX_FERROR, joint=j, value=max_ferror)

    def home_here(self, j):
        """Home joint j where it is (no search: homing sets it homed)."""
        self.ok(Cmd.SET_JOINT_HOMING_PARAMS, joint=j, home_sequence=0)
        self.ok(Cmd.HOME, joint=j)
        for _ in range(2000):
            if self.status.joint[j].flags & JointFlag.HOMED:
                return
            self.hal.step(1)
        raise AssertionError(f"joint {j} did not home")

    def wait_still(self, limit=20000):
        for _ in range(limit // 10):
            self.hal.step(10)
            if self.status.in_position:
                return
        raise AssertionError("the machine did not stop")


@pytest.fixture
def m(hal):
    mach = Machine(hal)
    for j in range(3):
        mach.config_joint(j)
    return mach


def check_limits(trace, name_v, vmax, amax, tol=1e-6):
    v = trace[name_v]
    assert np.abs(v).max() <= vmax * (1 + tol)
    acc = np.diff(v) / DT
    assert np.abs(acc).max() <= amax * (1 + tol) + 1e-9


LOAD_ERRORS = [
    ([], "num_joints=17", "num_joints=17 is out of range (1..16)"),
    ([], "num_dio=65", "num_dio=65 is out of range (1..64)"),
    ([], "num_aio=0", "num_aio=0 is out of range (1..64)"),
    ([], "num_spindles=9", "num_spindles=9 is out of range (1..8)"),
    ([], "num_misc_error=65", "num_misc_error=65 is out of range (0..64)"),
    ([], "num_joints=2 num_extrajoints=3",
     "num_extrajoints=3 is out of range (0..2)"),
    ([], "num_extrajoints=1", "num_extrajoints=1 needs kinematics of type "
     "BOTH"),
    ([], "num_joints=2 unlock_joints_mask=0x4",
     "unlock_joints_mask=0x4 names joints beyond num_joints=2"),
    ([], "traj_period_nsec=1000", "traj_period_nsec=1000 must be 0"),
    (["trivkins"], "", "no kinematics module is loaded (loadrt trivkins "
     "first)"),
    (["homemod"], "", "no homing module is loaded (loadrt homemod first)"),
    (["tpmod"], "", "no trajectory planner module is loaded (loadrt tpmod "
     "first)"),
]


@pytest.mark.parametrize("skip,args,reason", LOAD_ERRORS,
                         ids=[r[2][:30] for r in LOAD_ERRORS])
def test_load_errors(hal, skip, args, reason):
    for mod in ("trivkins", "homemod", "tpmod"):
        if mod not in skip:
            hal.loadrt(mod)
    params = dict(a.split("=") for a in args.split())
    with pytest.raises(halsdk.HalError, match=re.escape(reason)):
        hal.loadrt("motmod", **params)
    # nothing half-loaded: no pins, no threads, and a good load works
    assert _core.find("pin", "motion.enable") is None
    assert "servo-thread" not in hal.command("show thread")
    if not skip:
        hal.loadrt("motmod")
        assert _core.find("pin", "joint.2.pos-cmd") is not None


def test_channel_block_and_status(hal):
    m = Machine(hal, joints=4, num_dio=2, traj_period_nsec=3000000)
    ch = m.ch
    assert (ch.magic, ch.version, ch.size) == (_channel.MAGIC, _channel.VERSION,
                                               C.sizeof(Channel))
    hal.step(5)
    s = m.status
    assert s.heartbeat == 5
    assert ch.status_seq % 2 == 0
    assert (s.num_joints, s.num_joints_loaded, s.num_dio) == (4, 4, 2)
    assert s.servo_period == pytest.approx(0.001)
    assert s.traj_period == pytest.approx(0.003)
    assert s.mode == Mode.FREE and not s.enabled and s.in_position
    assert s.kins_type == KinsType.IDENTITY


# ------------------------------------------------------------ rejections

def test_rejections_have_reasons(m):
    nan = float("nan")
    cases = [
        (dict(cmd=Cmd.JOG_CONT, joint=0, vel=1.0), "JOG_CONT needs motion "
         "enabled"),
        (dict(cmd=Cmd.SET_JOINT_VEL_LIMIT, joint=5, vel=1.0),
         "joint 5 does not exist (num_joints=3)"),
        (dict(cmd=Cmd.SET_JOINT_VEL_LIMIT, joint=0, vel=nan),
         "velocity must be a positive number, got nan"),
        (dict(cmd=Cmd.SET_JOINT_VEL_LIMIT, joint=0, vel=-2.0),
         "velocity must be a positive number, got -2"),
        (dict(cmd=Cmd.SET_JOINT_ACC_LIMIT, joint=-3, acc=1.0),
         "joint -3 does not exist"),
        (dict(cmd=Cmd.SET_JOINT_POSITION_LIMITS, joint=0, min_limit=5.0,
              max_limit=1.0), "min_limit (5) must not be above max_limit"),
        (dict(cmd=Cmd.SET_AXIS_VEL_LIMIT, axis=9, vel=1.0), "axis 9 does not "
         "exist"),
        (dict(cmd=Cmd.SCALE, value=-1.0), "scale must be zero or a positive "
         "number, got -1"),
        (dict(cmd=Cmd.SET_LINE, x=1.0, vel=1.0), "SET_LINE needs coord mode "
         "(now free)"),
        (dict(cmd=Cmd.SET_TELEOP_VECTOR, x=1.0), "SET_TELEOP_VECTOR needs "
         "teleop mode (now free)"),
        (dict(cmd=Cmd.HOME, joint=0), "HOME needs motion enabled"),
        (dict(cmd=Cmd.SET_DOUT, index=4, ival=1), "digital output 4 does not "
         "exist (num_dio=4)"),
        (dict(cmd=Cmd.SET_AOUT, index=0, value=nan), "analog value must be a "
         "finite number"),
        (dict(cmd=Cmd.SET_NUM_JOINTS, ival=4), "SET_NUM_JOINTS: 4 is out of "
         "range (1..3"),
        (dict(cmd=Cmd.SET_PROFILE, ival=7), "7 is not a profile"),
        (dict(cmd=Cmd.SET_TERM_COND, ival=3), "3 is not a termination "
         "condition"),
        (dict(cmd=Cmd.OVERRIDE_LIMITS, ival=2), "OVERRIDE_LIMITS takes 1"),
        (dict(cmd=130), "command 130 is reserved"),
        (dict(cmd=999), "unknown command code 999"),
        (dict(cmd=Cmd.UNHOME, joint=-7), "UNHOME: joint -7"),
    ]
    for kw, reason in cases:
        why = m.no(**kw)
        assert reason in why, (kw, why)
    m.ok(Cmd.ENABLE)
    assert "velocity must be a positive number, got nan" in m.no(
        Cmd.JOG_INCR, joint=0, vel=nan, offset=1.0)
    assert "increment must be a finite number" in m.no(
        Cmd.JOG_INCR, joint=0, vel=1.0, offset=nan)
    assert "velocity must be a nonzero number" in m.no(Cmd.JOG_CONT, joint=1,
                                                        vel=0.0)
    assert "needs a joint" in m.no(Cmd.JOG_CONT, vel=1.0)
    assert "axis jog" not in m.no(Cmd.JOG_CONT, joint=-1, axis=0, vel=1.0)
    hal = m.hal
    hal.setp("motion.jog-inhibit", True)
    assert "motion.jog-inhibit" in m.no(Cmd.JOG_ABS, joint=0, vel=1.0,
                                        offset=1.0)
    hal.setp("motion.jog-inhibit", False)
    hal.setp("motion.homing-inhibit", True)
    assert "motion.homing-inhibit" in m.no(Cmd.HOME, joint=0)
    # nothing moved from all these
    assert m.status.in_position
    assert [m.status.joint[j].pos_cmd for j in range(3)] == [0, 0, 0]


# ------------------------------------------------------------ jogs

def test_jog_incr_is_cumulative_and_within_limits(m):
    m.ok(Cmd.ENABLE)
    assert m.send(Cmd.JOG_INCR, joint=0, vel=5.0, offset=1.0)[0] == Echo.ACCEPTED
    m.hal.step(20)
    m.ok(Cmd.JOG_INCR, joint=0, vel=5.0, offset=1.0)
    m.ok(Cmd.JOG_INCR, joint=1, vel=2.0, offset=-0.5)   # another joint at once
    tr = m.hal.run(1500, record=["joint.0.pos-cmd", "joint.0.vel-cmd",
                                 "joint.1.vel-cmd", "motion.in-position"])
    assert tr["joint.0.pos-cmd"][-1] == 2.0
    assert m.hal.getp("joint.1.pos-cmd") == -0.5
    check_limits(tr, "joint.0.vel-cmd", 5.0, 100.0)
    check_limits(tr, "joint.1.vel-cmd", 2.0, 100.0)
    assert tr["motion.in-position"][-1] and not tr["motion.in-position"][0]


def test_jog_abs_and_cont_respect_soft_limits_when_homed(m):
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_ABS, joint=2, vel=10.0, offset=-3.25)
    m.wait_still()
    assert m.hal.getp("joint.2.pos-cmd") == -3.25
    # unhomed: a continuous jog goes on past the soft limit
    m.ok(Cmd.SET_JOINT_POSITION_LIMITS, joint=0, min_limit=-1.0, max_limit=0.5)
    m.ok(Cmd.JOG_CONT, joint=0, vel=10.0)
    m.hal.step(300)
    assert m.hal.getp("joint.0.pos-cmd") > 0.5
    m.ok(Cmd.ABORT)
    m.wait_still()
    m.ok(Cmd.JOG_ABS, joint=0, vel=10.0, offset=0.0)
    m.wait_still()
    m.home_here(0)
    m.ok(Cmd.JOG_CONT, joint=0, vel=10.0)
    tr = m.hal.run(500, record=["joint.0.pos-cmd", "joint.0.vel-cmd"])
    assert tr["joint.0.pos-cmd"].max() == 0.5
    assert tr["joint.0.pos-cmd"][-1] == 0.5
    check_limits(tr, "joint.0.vel-cmd", 10.0, 100.0)
    assert m.status.on_soft_limit and m.hal.getp("motion.on-soft-limit")
    why = m.no(Cmd.JOG_INCR, joint=0, vel=1.0, offset=0.1)
    assert "joint 0 is at its positive soft limit (0.5)" in why
    assert "positive soft limit" in m.no(Cmd.JOG_ABS, joint=0, vel=1.0,
                                         offset=9.0)
    # an absolute target beyond the soft limit is refused, not clamped
    why = m.no(Cmd.JOG_ABS, joint=0, vel=10.0, offset=-9.0)
    assert "joint 0 target -9 is beyond its negative soft limit (-1)" in why
    m.ok(Cmd.JOG_ABS, joint=0, vel=10.0, offset=-1.0)
    m.wait_still()
    assert m.hal.getp("joint.0.pos-cmd") == -1.0


def test_abort_stops_a_continuous_jog_within_acc(m):
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_CONT, joint=1, vel=-8.0)
    m.hal.step(200)
    assert m.hal.getp("joint.1.kb-jog-active")
    assert m.hal.getp("motion.jog-is-active")
    m.ok(Cmd.ABORT)
    tr = m.hal.run(300, record=["joint.1.vel-cmd"])
    check_limits(tr, "joint.1.vel-cmd", 8.0, 100.0)
    assert tr["joint.1.vel-cmd"][-1] == 0
    assert not m.hal.getp("motion.jog-is-active")


def test_jog_wheel(m):
    m.ok(Cmd.ENABLE)
    hal = m.hal
    hal.set({"joint.0.jog-scale": 0.01, "joint.0.jog-enable": True})
    hal.step(2)
    hal.setp("joint.0.jog-counts", 250)
    tr = hal.run(1000, record=["joint.0.vel-cmd", "joint.0.wheel-jog-active"])
    assert tr["joint.0.wheel-jog-active"][0]
    assert hal.getp("joint.0.pos-cmd") == pytest.approx(2.5, abs=1e-12)
    check_limits(tr, "joint.0.vel-cmd", 10.0, 100.0)


def test_jerk_profile(m):
    m.ok(Cmd.SET_JOINT_JERK_LIMIT, joint=0, jerk=2000.0)
    assert m.status.profile == 1
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_INCR, joint=0, vel=5.0, offset=1.5)
    tr = m.hal.run(1500, record=["joint.0.vel-cmd", "joint.0.acc-cmd"])
    assert m.hal.getp("joint.0.pos-cmd") == pytest.approx(1.5, abs=1e-9)
    check_limits(tr, "joint.0.vel-cmd", 5.0, 100.0)
    jerk = np.diff(np.diff(tr["joint.0.vel-cmd"]) / DT) / DT
    assert np.abs(jerk).max() <= 2000.0 * 1.01
    m.ok(Cmd.SET_PROFILE, ival=Profile.TRAPEZOID)
    assert m.status.profile == 0


# ------------------------------------------------------------ modes

def test_mode_changes(m):
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_CONT, joint=0, vel=1.0)
    m.hal.step(10)
    why = m.no(Cmd.TELEOP)
    assert "cannot change mode while joint 0 moves (now free)" in why
    m.ok(Cmd.ABORT)
    m.wait_still()
    m.ok(Cmd.TELEOP)                     # identity kins: no homing needed
    assert m.status.mode == Mode.TELEOP and m.hal.getp("motion.teleop-mode")
    assert "JOG_CONT of a joint needs free mode (now teleop)" in m.no(
        Cmd.JOG_CONT, joint=0, vel=1.0)
    # teleop: axis jog moves the joint through the kinematics
    m.ok(Cmd.SET_AXIS_VEL_LIMIT, axis=1, vel=4.0)
    m.ok(Cmd.SET_AXIS_ACC_LIMIT, axis=1, acc=40.0)
    m.ok(Cmd.JOG_INCR, joint=-1, axis=1, vel=4.0, offset=1.0)
    tr = m.hal.run(1000, record=["axis.y.pos-cmd", "joint.1.vel-cmd"])
    assert m.hal.getp("joint.1.pos-cmd") == 1.0
    assert tr["axis.y.pos-cmd"][-1] == 1.0
    check_limits(tr, "joint.1.vel-cmd", 4.0, 40.0)
    m.ok(Cmd.SET_TELEOP_VECTOR, y=-2.0)
    m.hal.step(200)
    assert "cannot change mode while the machine moves" in m.no(Cmd.COORD)
    m.ok(Cmd.SET_TELEOP_VECTOR)          # all zero: stop
    m.wait_still()
    m.ok(Cmd.COORD)
    assert m.hal.getp("motion.coord-mode")
    m.ok(Cmd.FREE)
    assert m.status.mode == Mode.FREE


def test_teleop_needs_homing_with_nontrivial_kins(hal):
    m = Machine(hal, joints=3, kins_args=("kinstype=both",))
    assert m.status.kins_type == KinsType.BOTH
    m.ok(Cmd.ENABLE)
    why = m.no(Cmd.TELEOP)
    assert "TELEOP needs all joints homed" in why
    assert "COORD needs all joints homed" in m.no(Cmd.COORD)
    for j in range(3):
        m.home_here(j)
    m.ok(Cmd.COORD)


def test_coord_line_with_interpolation(hal):
    m = _coord_machine(hal, traj_period_nsec=4000000)
    st = m.send(Cmd.SET_LINE, x=3.0, y=-1.0, vel=5.0, ini_maxvel=5.0, acc=50.0,
                id=42, motion_type=MotionType.FEED)
    assert st == (Echo.ACCEPTED, "")
    tr = hal.run(2000, record=["joint.0.pos-cmd", "joint.0.coarse-pos-cmd",
                               "joint.0.vel-cmd", "motion.in-position"])
    assert hal.getp("joint.0.pos-cmd") == pytest.approx(3.0, abs=1e-12)
    assert hal.getp("joint.1.pos-cmd") == pytest.approx(-1.0, abs=1e-12)
    s = m.status
    assert s.motion_id == 42 and s.in_position
    assert s.carte_pos_cmd.x == pytest.approx(3.0, abs=1e-12)
    # interpolation: the coarse position changes every 4th cycle only, the
    # servo position every cycle while moving
    coarse = tr["joint.0.coarse-pos-cmd"][:400]
    fine = tr["joint.0.pos-cmd"][:400]
    assert np.count_nonzero(np.diff(coarse)) <= 400 // 4 + 1
    assert np.count_nonzero(np.diff(fine)) > 300
    assert np.abs(tr["joint.0.vel-cmd"]).max() <= 5.0 * 1.01
    why = m.no(Cmd.SET_LINE, x=float("inf"), vel=1.0, ini_maxvel=1.0, acc=1.0)
    assert "end point X must be a finite number" in why


# ------------------------------------------------------------ positions

def test_motor_offset_and_seven_positions(m):
    m.ok(Cmd.SET_JOINT_MOTOR_OFFSET, joint=1, value=10.0)
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_ABS, joint=1, vel=5.0, offset=2.0)
    m.wait_still()
    hal = m.hal
    assert hal.getp("joint.1.pos-cmd") == 2.0
    assert hal.getp("joint.1.motor-pos-cmd") == 12.0
    assert hal.getp("joint.1.pos-fb") == 2.0
    assert hal.getp("joint.1.motor-offset") == 10.0
    s = m.status
    assert s.carte_pos_cmd.y == 2.0 and s.carte_pos_fb.y == 2.0
    assert s.carte_pos_fb_ok
    assert s.joint[1].motor_pos_cmd == 12.0


def test_ferror_limit_scales_with_speed(hal):
    m = Machine(hal, loop=False)
    m.config_joint(0, vel=10.0, min_ferror=0.1, max_ferror=1.1)
    m.ok(Cmd.ENABLE)
    hal.step(2)
    assert hal.getp("joint.0.f-error-lim") == pytest.approx(0.1)
    # no feedback: the error grows; it trips at the speed-scaled limit
    m.ok(Cmd.JOG_CONT, joint=0, vel=5.0)
    tr = hal.run(400, record=["joint.0.f-error", "joint.0.f-error-lim",
                              "joint.0.vel-cmd", "motion.motion-enabled"])
    assert not tr["motion.motion-enabled"][-1]
    k = int(np.argmin(tr["motion.motion-enabled"]))
    lim = tr["joint.0.f-error-lim"][k - 1]
    assert lim == pytest.approx(0.1 + 1.0 * abs(tr["joint.0.vel-cmd"][k - 1])
                                / 10.0, rel=1e-6)
    assert 0.1 < lim < 1.1
    msgs = m.messages()
    assert any("joint 0 following error" in t for t in msgs), msgs
    assert hal.getp("joint.0.f-errored")
    assert not hal.getp("joint.0.amp-enable-out")


# ------------------------------------------------------------ faults

@pytest.mark.parametrize("pin,text", [
    ("joint.2.amp-fault-in", "amplifier fault on joint 2"),
    ("joint.1.pos-lim-sw-in", "joint 1 on positive hard limit"),
    ("joint.0.neg-lim-sw-in", "joint 0 on negative hard limit"),
    ("motion.enable", "motion.enable went false"),
    ("motion.misc-error-01", "motion.misc-error-01 is true"),
])
def test_faults_disable_and_say_why(hal, pin, text):
    m = Machine(hal, num_misc_error=2)
    for j in range(3):
        m.config_joint(j)
    m.ok(Cmd.ENABLE)
    hal.step(3)
    assert hal.getp("joint.0.amp-enable-out")
    hal.setp(pin, pin != "motion.enable")
    hal.step(2)
    s = m.status
    assert not s.enabled and s.error
    assert not hal.getp("motion.motion-enabled")
    assert not any(hal.getp(f"joint.{j}.amp-enable-out") for j in range(3))
    msgs = m.messages()
    assert len(msgs) == 1 and text in msgs[0]


def test_override_limits_until_the_end_of_the_next_jog(m):
    hal = m.hal
    hal.setp("joint.1.pos-lim-sw-in", True)
    m.ok(Cmd.ENABLE)
    hal.step(2)
    assert not m.status.enabled           # tripped at once
    assert "joint 1 on positive hard limit" in m.messages()[0]
    m.ok(Cmd.OVERRIDE_LIMITS, ival=1)
    m.ok(Cmd.ENABLE)
    hal.step(5)
    assert m.status.enabled and m.status.override_limits
    assert "positive hard limit switch" in m.no(Cmd.JOG_INCR, joint=1, vel=1.0,
                                                offset=0.5)
    m.ok(Cmd.JOG_INCR, joint=1, vel=2.0, offset=-0.5)    # off the switch
    hal.step(100)
    hal.setp("joint.1.pos-lim-sw-in", False)
    m.wait_still()
    assert m.status.enabled
    assert not m.status.override_limits               # ended with the jog
    hal.setp("joint.0.neg-lim-sw-in", True)           # limits work again
    hal.step(2)
    assert not m.status.enabled
    assert "joint 0 on negative hard limit" in m.messages()[0]


def test_amplifier_and_joint_activation(m):
    m.ok(Cmd.ENABLE_AMPLIFIER, joint=2)
    m.hal.step(1)
    assert m.hal.getp("joint.2.amp-enable-out")
    assert not m.hal.getp("joint.1.amp-enable-out")
    m.ok(Cmd.DISABLE_AMPLIFIER, joint=2)
    m.hal.step(1)
    assert not m.hal.getp("joint.2.amp-enable-out")
    m.ok(Cmd.DEACTIVATE_JOINT, joint=1)
    m.ok(Cmd.ENABLE)
    m.hal.step(1)
    assert not m.hal.getp("joint.1.active")
    assert not m.hal.getp("joint.1.amp-enable-out")
    assert m.hal.getp("joint.0.amp-enable-out")
    assert "joint 1 is not active" in m.no(Cmd.JOG_INCR, joint=1, vel=1.0,
                                           offset=1.0)
    m.ok(Cmd.ACTIVATE_JOINT, joint=1)
    m.ok(Cmd.DISABLE)
    assert not m.status.enabled


def test_outputs_offsets_and_scales(m):
    m.ok(Cmd.SET_DOUT, index=3, ival=1)
    m.ok(Cmd.SET_AOUT, index=1, value=-2.5)
    m.ok(Cmd.SET_OFFSET, z=1.25, x=-0.5)
    m.ok(Cmd.SCALE, value=0.5)
    m.hal.step(1)
    assert m.hal.getp("motion.digital-out-03")
    assert m.hal.getp("motion.analog-out-01") == -2.5
    assert m.hal.getp("motion.tooloffset.z") == 1.25
    s = m.status
    assert s.dout == 8 and s.tool_offset.x == -0.5 and s.feed_scale == 0.5
    # the feed scale scales jog speeds
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_INCR, joint=0, vel=4.0, offset=1.0)
    tr = m.hal.run(1000, record=["joint.0.vel-cmd"])
    assert 1.9 < np.abs(tr["joint.0.vel-cmd"]).max() <= 2.0 + 1e-9


def test_disabled_commands_follow_feedback(hal):
    m = Machine(hal, loop=False)
    hal.setp("joint.0.motor-pos-fb", 3.5)
    hal.step(2)
    assert hal.getp("joint.0.pos-cmd") == 3.5
    assert hal.getp("joint.0.motor-pos-cmd") == 3.5
    assert m.status.joint[0].ferror == 0
    assert not math.isnan(hal.getp("axis.x.pos-cmd"))


def _coord_machine(hal, **modparams):
    m = Machine(hal, joints=3, **modparams)
    for j in range(3):
        m.config_joint(j)
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.COORD)
    m.ok(Cmd.SET_VEL_LIMIT, vel=20.0)
    m.ok(Cmd.SET_ACC, acc=100.0)
    return m


def test_coord_pause_resume_and_feed_hold(hal):
    m = _coord_machine(hal)
    m.ok(Cmd.SET_LINE, x=4.0, vel=5.0, ini_maxvel=5.0, acc=50.0, id=1,
         motion_type=MotionType.FEED)
    hal.step(300)
    m.ok(Cmd.PAUSE)
    tr = hal.run(300, record=["joint.0.vel-cmd"])
    check_limits(tr, "joint.0.vel-cmd", 5.0, 50.0)
    assert tr["joint.0.vel-cmd"][-1] == 0
    held = hal.getp("joint.0.pos-cmd")
    assert 0 < held < 4.0 and not m.status.in_position
    m.ok(Cmd.RESUME)
    hal.step(200)
    hal.setp("motion.feed-hold", True)
    tr = hal.run(300, record=["joint.0.vel-cmd"])
    assert tr["joint.0.vel-cmd"][-1] == 0
    check_limits(tr, "joint.0.vel-cmd", 5.0, 50.0)
    hal.setp("motion.feed-hold", False)
    m.wait_still()
    assert hal.getp("joint.0.pos-cmd") == pytest.approx(4.0, abs=1e-12)


def test_coord_circle_and_queue(hal):
    m = _coord_machine(hal)
    m.ok(Cmd.SET_LINE, x=1.0, vel=5.0, ini_maxvel=5.0, acc=50.0, id=1,
         motion_type=MotionType.FEED)
    m.ok(Cmd.SET_CIRCLE, y=1.0, vel=5.0, ini_maxvel=5.0, acc=50.0, id=2,
         motion_type=MotionType.ARC, center=Cart(0, 0, 0), normal=Cart(0, 0, 1))
    assert m.status.queue_depth >= 1
    m.wait_still()
    s = m.status
    assert s.motion_id == 2
    assert s.carte_pos_cmd.x == pytest.approx(0.0, abs=1e-9)
    assert s.carte_pos_cmd.y == pytest.approx(1.0, abs=1e-9)
    assert hal.getp("joint.1.pos-cmd") == pytest.approx(1.0, abs=1e-9)
    assert "normal must not be (0, 0, 0)" in m.no(
        Cmd.SET_CIRCLE, x=1.0, vel=5.0, ini_maxvel=5.0, acc=50.0)


def test_abort_in_coord_empties_the_queue(hal):
    m = _coord_machine(hal)
    for k in range(3):
        m.ok(Cmd.SET_LINE, x=float(k + 1), vel=5.0, ini_maxvel=5.0, acc=50.0,
             id=k + 1, motion_type=MotionType.FEED)
    hal.step(100)
    m.ok(Cmd.ABORT)
    tr = hal.run(400, record=["joint.0.vel-cmd"])
    check_limits(tr, "joint.0.vel-cmd", 5.0, 50.0)
    assert m.status.in_position and m.status.queue_depth == 0
    assert hal.getp("joint.0.pos-cmd") < 1.0


def test_num_joints_and_unhome(m):
    assert "needs motion disabled" not in m.no(Cmd.SET_NUM_JOINTS, ival=0)
    m.ok(Cmd.SET_NUM_JOINTS, ival=2)
    assert m.status.num_joints == 2
    assert "joint 2 does not exist (num_joints=2)" in m.no(
        Cmd.SET_JOINT_VEL_LIMIT, joint=2, vel=1.0)
    m.ok(Cmd.ENABLE)
    assert "SET_NUM_JOINTS needs motion disabled" in m.no(Cmd.SET_NUM_JOINTS,
                                                          ival=3)
    m.home_here(1)
    assert m.hal.getp("joint.1.homed")
    m.ok(Cmd.UNHOME, joint=1)
    m.hal.step(1)
    assert not m.hal.getp("joint.1.homed")


def test_teleop_on_scara(hal):
    """Teleop jogs in Cartesian space move the joints through scarakins."""
    m = Machine(hal, joints=6, kins="scarakins")
    for j in range(6):
        m.config_joint(j, vel=100.0, acc=1000.0, lo=-170.0, hi=170.0)
    m.ok(Cmd.ENABLE)
    assert "TELEOP needs all joints homed" in m.no(Cmd.TELEOP)
    m.ok(Cmd.JOG_ABS, joint=1, vel=100.0, offset=90.0)    # elbow bent
    m.wait_still()
    for j in range(6):
        m.home_here(j)
    m.ok(Cmd.TELEOP)
    s0 = m.status
    for a in (0, 1):
        m.ok(Cmd.SET_AXIS_VEL_LIMIT, axis=a, vel=50.0)
        m.ok(Cmd.SET_AXIS_ACC_LIMIT, axis=a, acc=500.0)
    m.ok(Cmd.JOG_INCR, joint=-1, axis=0, vel=50.0, offset=-20.0)
    tr = hal.run(2000, record=["axis.x.pos-cmd", "axis.y.pos-cmd",
                               "joint.0.pos-cmd", "joint.1.pos-cmd"])
    s = m.status
    assert s.in_position
    assert s.carte_pos_cmd.x == pytest.approx(s0.carte_pos_cmd.x - 20.0,
                                              abs=1e-9)
    # the path is straight in X: Y never moved
    assert np.ptp(tr["axis.y.pos-cmd"]) < 1e-9
    assert np.ptp(tr["joint.0.pos-cmd"]) > 1.0
    assert np.ptp(tr["joint.1.pos-cmd"]) > 1.0
    assert s.carte_pos_fb_ok
    assert s.carte_pos_fb.x == pytest.approx(s.carte_pos_cmd.x, abs=1e-9)
    assert s.carte_pos_fb.y == pytest.approx(s.carte_pos_cmd.y, abs=1e-9)
    axv = np.diff(tr["axis.x.pos-cmd"]) / DT
    assert np.abs(axv).max() <= 50.0 * (1 + 1e-6)
    assert np.abs(np.diff(axv) / DT).max() <= 500.0 * (1 + 1e-6)


def test_probe(hal):
    m = _coord_machine(hal)
    m.ok(Cmd.PROBE, x=5.0, vel=2.0, ini_maxvel=2.0, acc=50.0, id=9,
         motion_type=MotionType.PROBING)
    for _ in range(3000):
        hal.step(1)
        if hal.getp("joint.0.pos-cmd") >= 1.0:
            break
    hal.setp("motion.probe-input", True)
    m.wait_still()
    s = m.status
    assert s.probe_tripped
    assert 1.0 <= s.probed_pos.x < 1.01
    assert hal.getp("joint.0.pos-cmd") < 1.2
    assert "CLEAR_PROBE_FLAG" in m.no(Cmd.PROBE, x=0.0, vel=2.0, ini_maxvel=2.0,
                                      acc=50.0, id=10, motion_type=MotionType.PROBING)
    hal.setp("motion.probe-input", False)
    m.ok(Cmd.CLEAR_PROBE_FLAG)
    assert not m.status.probe_tripped


def test_with_the_python_client(hal):
    """The same machine through halsdk.motion."""
    from halsdk.motion import Motion, Rejected
    Machine(hal)
    mo = Motion.connect(hal)
    mo.set_joint_max_velocity(0, 4.0)
    mo.set_joint_max_acceleration(0, 40.0)
    with pytest.raises(Rejected, match="JOG_INCR needs motion enabled"):
        mo.jog_incr(0, 2.0, 1.0)
    mo.enable()
    mo.jog_incr(0, 2.0, 0.5)
    mo.jog_incr(0, 2.0, 0.5)
    s = mo.wait_inpos()
    assert s.joints[0].pos_cmd == 1.0
    with pytest.raises(Rejected, match="joint 7 does not exist"):
        mo.jog_abs(7, 1.0, 1.0)


def test_fault_during_a_coord_move_then_enable_again(hal):
    m = _coord_machine(hal)
    m.ok(Cmd.SET_LINE, x=4.0, vel=5.0, ini_maxvel=5.0, acc=50.0, id=1,
         motion_type=MotionType.FEED)
    hal.step(300)
    hal.setp("joint.2.amp-fault-in", True)
    hal.step(2)
    assert not m.status.enabled
    assert "amplifier fault on joint 2" in m.messages()[0]
    stopped = hal.getp("joint.0.pos-cmd")
    assert 0 < stopped < 4.0
    hal.setp("joint.2.amp-fault-in", False)
    hal.step(50)
    m.ok(Cmd.ENABLE)
    assert m.status.mode == Mode.COORD and m.status.queue_depth == 0
    hal.step(10)
    assert hal.getp("joint.0.pos-cmd") == stopped    # no jump, no move
    m.ok(Cmd.SET_LINE, x=-1.0, vel=5.0, ini_maxvel=5.0, acc=50.0, id=2,
         motion_type=MotionType.FEED)
    tr = hal.run(2000, record=["joint.0.vel-cmd"])
    check_limits(tr, "joint.0.vel-cmd", 5.0, 50.0)
    assert hal.getp("joint.0.pos-cmd") == pytest.approx(-1.0, abs=1e-12)


def test_jog_inhibit_stops_a_jog(m):
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_CONT, joint=0, vel=5.0)
    m.hal.step(100)
    m.hal.setp("motion.jog-inhibit", True)
    tr = m.hal.run(200, record=["joint.0.vel-cmd"])
    check_limits(tr, "joint.0.vel-cmd", 5.0, 100.0)
    assert tr["joint.0.vel-cmd"][-1] == 0


def test_unload_and_load_again(hal):
    Machine(hal)
    hal.step(3)
    hal.command("delf motion-command-handler servo-thread")
    hal.command("delf motion-controller servo-thread")
    hal.unloadrt("motmod")
    assert _core.find("pin", "motion.enable") is None
    assert "servo-thread" not in hal.command("show thread")
    with pytest.raises(halsdk.HalError):
        _core.shmem_attach("motmod.channel")
    hal.loadrt("motmod", num_joints=2)
    hal.addf("motion-controller", "servo-thread")
    hal.step(1)
    addr, _ = _core.shmem_attach("motmod.channel")
    s = Channel.from_address(addr).status
    assert s.num_joints == 2 and s.heartbeat == 1


def test_homing_with_a_switch(hal):
    """A search/latch homing run through motmod: the free planner moves
    the joint, the motor offset is set, the final move goes to HOME."""
    m = Machine(hal)
    m.config_joint(0, vel=10.0, acc=200.0, lo=-50.0, hi=50.0)
    hal.loadrt("sim_home_switch")
    hal.addf("sim-home-switch.0", "servo-thread")
    hal.command("net fb0 sim-home-switch.0.cur-pos")
    hal.setp("sim-home-switch.0.home-pos", -2.0)
    hal.command("net hsw sim-home-switch.0.home-sw joint.0.home-sw-in")
    m.ok(Cmd.SET_JOINT_HOMING_PARAMS, joint=0, home_sequence=0,
         home_search_vel=-5.0, home_latch_vel=0.5, home_final_vel=5.0,
         home_offset=-10.0, home=-7.0)
    m.ok(Cmd.ENABLE)
    assert m.send(Cmd.HOME, joint=0)[0] == Echo.ACCEPTED
    assert "cannot change mode while a joint is homing" in m.no(Cmd.TELEOP)
    tr = hal.run(8000, record=["joint.0.vel-cmd", "joint.0.homed"])
    assert tr["joint.0.homed"][-1], m.messages()
    check_limits(tr, "joint.0.vel-cmd", 10.0, 200.0)
    m.wait_still()
    s = m.status
    assert hal.getp("joint.0.pos-cmd") == pytest.approx(-7.0, abs=1e-9)
    # the switch releases (latch) at motor position -2 + hysteresis 0.1,
    # which is joint position HOME_OFFSET -10
    assert s.joint[0].motor_offset == pytest.approx(8.1, abs=0.002)
    assert hal.getp("joint.0.motor-pos-cmd") == pytest.approx(
        -7.0 + s.joint[0].motor_offset, abs=1e-9)


def test_teleop_wheel_and_axis_limits(m):
    hal = m.hal
    hal.setp("motion.enable", False)
    assert "ENABLE: motion.enable is false" in m.no(Cmd.ENABLE)
    hal.setp("motion.enable", True)
    m.ok(Cmd.ENABLE)
    for j in range(3):
        m.home_here(j)
    m.ok(Cmd.TELEOP)
    m.ok(Cmd.SET_AXIS_POSITION_LIMITS, axis=2, min_limit=-1.0, max_limit=0.75)
    m.ok(Cmd.SET_AXIS_VEL_LIMIT, axis=2, vel=3.0)
    m.ok(Cmd.SET_AXIS_ACC_LIMIT, axis=2, acc=30.0)
    hal.set({"axis.z.jog-scale": 0.5, "axis.z.jog-enable": True})
    hal.step(2)
    hal.setp("axis.z.jog-counts", 1)
    tr = hal.run(1000, record=["axis.z.pos-cmd", "axis.z.wheel-jog-active"])
    assert tr["axis.z.wheel-jog-active"][0]
    assert hal.getp("joint.2.pos-cmd") == 0.5
    hal.setp("axis.z.jog-counts", 3)             # +1.0: clamped at 0.75
    tr = hal.run(1000, record=["axis.z.pos-cmd"])
    assert tr["axis.z.pos-cmd"].max() == 0.75
    assert hal.getp("joint.2.pos-cmd") == 0.75
    v = np.diff(tr["axis.z.pos-cmd"]) / DT
    assert np.abs(v).max() <= 3.0 * (1 + 1e-6)
    assert "axis Z is at its positive limit (0.75)" in m.no(
        Cmd.JOG_CONT, joint=-1, axis=2, vel=1.0)


def test_locking_joint_waits_for_unlock(hal):
    m = Machine(hal, unlock_joints_mask=0x2)
    m.config_joint(1)
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_INCR, joint=1, vel=5.0, offset=1.0)
    hal.step(50)
    assert hal.getp("joint.1.unlock")
    assert hal.getp("joint.1.pos-cmd") == 0.0         # held while locked
    hal.setp("joint.1.is-unlocked", True)
    tr = hal.run(1000, record=["joint.1.vel-cmd"])
    check_limits(tr, "joint.1.vel-cmd", 5.0, 100.0)
    assert hal.getp("joint.1.pos-cmd") == 1.0
    assert not hal.getp("joint.1.unlock")


# the codes the random records use one time in three
_LIKELY = [int(Cmd[n]) for n in
           "ABORT FREE TELEOP COORD ENABLE HOME JOG_CONT JOG_INCR JOG_ABS "
           "JOG_STOP SET_LINE SET_CIRCLE SET_TELEOP_VECTOR PROBE "
           "SET_NUM_JOINTS SET_JOINT_POSITION_LIMITS SET_JOINT_VEL_LIMIT "
           "SET_JOINT_HOMING_PARAMS SET_JOINT_COMP SET_AXIS_POSITION_LIMITS "
           "SET_TERM_COND SET_PROFILE SET_DOUT SET_AOUT".split()]


def test_random_commands_never_break_it(m):
    """Random records (wild numbers, NaN, inf, any code) are either run
    or rejected with a reason; positions stay finite."""
    rng = np.random.default_rng(6)
    wild = [0.0, 1.0, -1.0, 1e300, -1e300, float("nan"), float("inf"),
            -float("inf"), 5e-324, 3.0]
    ints = [0, 1, -1, 2, 3, 15, 16, -2, 2**31 - 1, -2**31]
    m.ok(Cmd.ENABLE)
    for k in range(1500):
        c = Command()
        c.cmd = int(rng.integers(0, 160)) if k % 3 else int(
            rng.choice(_LIKELY))
        for f, t in Command._fields_:
            if f == "cmd":
                continue
            if t is C.c_double:
                setattr(c, f, float(rng.choice(wild)))
            elif t in (C.c_int32, C.c_uint32):
                v = int(rng.choice(ints))
                setattr(c, f, v & 0xFFFFFFFF if t is C.c_uint32 else v)
        for a in AXES:
            setattr(c.pos, a, float(rng.choice(wild)))
        ch = m.ch
        ch.command = c
        ch.cmd_seq = ch.cmd_seq + 1
        m.hal.step(1)
        assert ch.echo_seq == ch.cmd_seq
        assert ch.echo_status in (Echo.DONE, Echo.ACCEPTED, Echo.REJECTED)
        if ch.echo_status == Echo.REJECTED:
            assert ch.echo_reason, c.cmd
        if k % 50 == 0:
            m.send(Cmd.ENABLE)
            m.send(Cmd.FREE)
    m.hal.step(100)
    s = m.status
    assert s.heartbeat > 1500
    for j in range(3):
        assert math.isfinite(m.hal.getp(f"joint.{j}.pos-cmd"))
        assert math.isfinite(m.hal.getp(f"joint.{j}.motor-pos-cmd"))
    for a in AXES:
        assert math.isfinite(m.hal.getp(f"axis.{a}.pos-cmd"))


def test_backlash_shows_in_motor_pos_cmd(m):
    hal = m.hal
    m.ok(Cmd.SET_JOINT_BACKLASH, joint=0, value=0.1)
    assert "backlash" in m.no(Cmd.SET_JOINT_BACKLASH, joint=0, value=-0.1)
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_INCR, joint=0, vel=5.0, offset=1.0)
    tr = hal.run(1000, record=["joint.0.motor-pos-cmd", "joint.0.pos-fb"])
    assert hal.getp("joint.0.backlash-corr") == pytest.approx(0.05)
    assert hal.getp("joint.0.backlash-filt") == pytest.approx(0.05)
    assert hal.getp("joint.0.motor-pos-cmd") == pytest.approx(1.05)
    assert hal.getp("joint.0.pos-fb") == pytest.approx(1.0)
    mv = np.diff(tr["joint.0.motor-pos-cmd"]) / DT
    assert np.abs(mv).max() <= 1.5 * 5.0 * (1 + 1e-6)
    assert np.abs(np.diff(mv) / DT).max() <= 1.5 * 100.0 * (1 + 1e-6)
    m.ok(Cmd.JOG_INCR, joint=0, vel=5.0, offset=-0.5)
    tr = hal.run(1000, record=["joint.0.motor-pos-cmd", "joint.0.pos-fb"])
    assert hal.getp("joint.0.pos-cmd") == 0.5
    assert hal.getp("joint.0.backlash-filt") == pytest.approx(-0.05)
    assert hal.getp("joint.0.motor-pos-cmd") == pytest.approx(0.45)
    assert np.abs(tr["joint.0.pos-fb"] - 0.5).max() <= 0.5 + 1e-9
    assert m.status.joint[0].backlash_filt == pytest.approx(-0.05)


def test_screw_comp_shows_in_motor_pos_cmd(m):
    hal = m.hal
    for nom, fwd, rev in [(0.0, 0.01, -0.01), (10.0, 0.02, -0.03)]:
        m.ok(Cmd.SET_JOINT_COMP, joint=1, comp=(C.c_double * 3)(nom, fwd, rev))
    why = m.no(Cmd.SET_JOINT_COMP, joint=1, comp=(C.c_double * 3)(5.0, 0, 0))
    assert "nominal position must be greater" in why
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.JOG_ABS, joint=1, vel=10.0, offset=5.0)
    m.wait_still()
    hal.step(200)
    assert hal.getp("joint.1.backlash-filt") == pytest.approx(0.015)
    assert hal.getp("joint.1.motor-pos-cmd") == pytest.approx(5.015)
    m.ok(Cmd.JOG_ABS, joint=1, vel=10.0, offset=4.0)
    m.wait_still()
    hal.step(200)
    assert hal.getp("joint.1.backlash-filt") == pytest.approx(-0.018)
    assert hal.getp("joint.1.motor-pos-cmd") == pytest.approx(4.0 - 0.018)
    assert hal.getp("joint.1.pos-fb") == pytest.approx(4.0)
    m.ok(Cmd.CLEAR_JOINT_COMP, joint=1)
    hal.step(200)
    assert hal.getp("joint.1.motor-pos-cmd") == pytest.approx(4.0)


def test_extra_joint_follows_posthome_cmd(hal):
    m = Machine(hal, joints=4, kins_args=("kinstype=both",),
                num_extrajoints=1)
    m.config_joint(3)
    m.ok(Cmd.ENABLE)
    m.ok(Cmd.SET_JOINT_HOMING_PARAMS, joint=3, home_sequence=0, home_offset=1.0)
    m.ok(Cmd.HOME, joint=3)
    hal.step(500)
    assert hal.getp("joint.3.homed")
    hal.command("unlinkp joint.3.motor-pos-fb")
    hal.setp("joint.3.motor-pos-fb", 77.0)
    hal.setp("joint.3.posthome-cmd", 2.5)
    hal.step(3)
    off = hal.getp("joint.3.motor-offset")
    assert hal.getp("joint.3.pos-cmd") == 2.5
    assert hal.getp("joint.3.motor-pos-cmd") == 2.5 + off
    assert m.status.enabled                  # its feedback is not used
    assert "extra joint 3 can be unhomed only while motion is disabled" \
        in m.no(Cmd.UNHOME, joint=3)
    m.ok(Cmd.DISABLE)
    m.ok(Cmd.UNHOME, joint=3)


def test_coord_stops_at_a_joint_soft_limit(hal):
    """A move inside the axis limits that would take a joint past its own
    soft limit disables motion at the limit, with one message."""
    m = _coord_machine(hal)
    m.ok(Cmd.FREE)
    for j in range(3):
        m.home_here(j)
    m.ok(Cmd.SET_JOINT_POSITION_LIMITS, joint=0, min_limit=-1.0, max_limit=1.0)
    m.ok(Cmd.COORD)
    m.ok(Cmd.SET_LINE, x=3.0, vel=5.0, ini_maxvel=5.0, acc=50.0, id=1,
         motion_type=MotionType.FEED)
    tr = hal.run(1500, record=["joint.0.pos-cmd"])
    assert tr["joint.0.pos-cmd"].max() <= 1.0
    assert not m.status.enabled
    msgs = m.messages()
    assert len(msgs) == 1 and "joint 0 past its positive soft limit" in \
        msgs[0]
