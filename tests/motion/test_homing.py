"""Homing (homemod) on simulated joints, stepped deterministically.

The homing module is driven through its exported table
``halsdk_homing_api`` (components/motion/homing.h) by a small motion-module
stand-in written here with ctypes: each servo cycle it does what motmod
does around homing (motor feedback -> pos_fb, read_inputs, run, the free
planner of each joint, motor_pos_cmd, write_outputs).  The home switches
are ``sim_home_switch`` components in a HAL thread, wired to the
joint.N.home-sw-in pins homemod creates; the index pulse comes from a
simulated encoder (index marks every ``INDEX_PITCH`` of motor travel,
resetting its count at the mark unless told not to).  The motor follows
its command exactly, one cycle late.
"""

from __future__ import annotations

import ctypes as C
import functools
import math

import numpy as np
import pytest
from helpers.fixtures import factory

import halsdk
from halsdk.core import _core
from halsdk.motion import HOME_SEQUENCE_NONE, HomeFlag, JointFlag

# the protocol's numbers (HomeFlag, JointFlag, HOME_SEQUENCE_NONE: the
# home_sequence of a joint not in "home all") come from the compiled
# headers, never typed here

DT = 0.001
PERIOD_NS = 1_000_000
INDEX_PITCH = 1.0           # motor units between index marks
INDEX_PHASE = 0.37          # first mark at this motor position (mod pitch)

# home-state numbers of homemod (docs/homing.rst)
HS_IDLE, HS_LATCH, HS_INDEX, HS_SYNC, HS_FINAL = 0, 8, 9, 11, 12


class FreePlan(C.Structure):
    _fields_ = [("target", C.c_double), ("max_vel", C.c_double),
                ("max_acc", C.c_double), ("max_jerk", C.c_double),
                ("enable", C.c_int), ("profile", C.c_int),
                ("pos", C.c_double), ("vel", C.c_double),
                ("acc", C.c_double), ("active", C.c_int),
                ("impl", C.c_void_p)]


class MotJoint(C.Structure):
    _fields_ = [("index", C.c_int), ("flags", C.c_uint)] + [
        (n, C.c_double) for n in (
            "min_pos_limit", "max_pos_limit", "vel_limit", "acc_limit",
            "jerk_limit", "min_ferror", "max_ferror", "backlash",
            "coarse_pos", "pos_cmd", "vel_cmd", "acc_cmd", "motor_offset",
            "backlash_corr", "backlash_filt", "backlash_vel",
            "motor_pos_cmd", "motor_pos_fb", "pos_fb", "ferror",
            "ferror_limit", "ferror_high_mark")] + [
        ("pos_limit_sw", C.c_int), ("neg_limit_sw", C.c_int),
        ("free_tp", FreePlan),
        ("kb_jog_active", C.c_int), ("wheel_jog_active", C.c_int)]


class HomeParams(C.Structure):
    _fields_ = [("home_offset", C.c_double), ("home", C.c_double),
                ("home_search_vel", C.c_double),
                ("home_latch_vel", C.c_double),
                ("home_final_vel", C.c_double),
                ("home_sequence", C.c_int), ("volatile_home", C.c_int),
                ("flags", C.c_uint)]


_why = (C.c_int, C.c_int, C.c_char_p, C.c_int)


class HomingApi(C.Structure):
    _fields_ = [
        ("version", C.c_int),
        ("init", C.CFUNCTYPE(C.c_int, C.c_int, C.c_double, C.c_int, C.c_int,
                             C.POINTER(MotJoint))),
        ("read_inputs", C.CFUNCTYPE(None)),
        ("write_outputs", C.CFUNCTYPE(None)),
        ("set_params", C.CFUNCTYPE(C.c_int, C.c_int, C.POINTER(HomeParams),
                                   C.c_char_p, C.c_int)),
        ("start", C.CFUNCTYPE(*_why)),
        ("unhome", C.CFUNCTYPE(*_why)),
        ("abort", C.CFUNCTYPE(None)),
        ("run", C.CFUNCTYPE(C.c_int)),
        ("is_homed", C.CFUNCTYPE(C.c_int, C.c_int)),
        ("is_homing", C.CFUNCTYPE(C.c_int, C.c_int)),
        ("all_homed", C.CFUNCTYPE(C.c_int)),
        ("state", C.CFUNCTYPE(C.c_int, C.c_int)),
        ("ignores_limits", C.CFUNCTYPE(C.c_int, C.c_int)),
        ("take_error", C.CFUNCTYPE(C.c_char_p)),
    ]


def plan_update(fp: FreePlan, dt: float) -> None:
    """A trapezoidal free planner with the freeplan.h contract: goes to
    target under max_vel/max_acc while enable, else stops; active while
    moving; lands exactly on the target."""
    a = fp.max_acc
    if fp.enable:
        d = fp.target - fp.pos
        if d == 0.0 and fp.vel == 0.0:
            fp.active = 0
            return
        vdes = math.copysign(min(fp.max_vel, math.sqrt(2 * a * abs(d))), d)
        vel = fp.vel + max(-a * dt, min(a * dt, vdes - fp.vel))
        step = vel * dt
        if step * d >= 0 and abs(step) >= abs(d):
            fp.pos, fp.vel, fp.active = fp.target, 0.0, 0
            return
        fp.pos += step
        fp.vel = vel
        fp.active = 1
    else:
        if fp.vel == 0.0:
            fp.active = 0
            return
        fp.vel -= max(-a * dt, min(a * dt, fp.vel))
        fp.pos += fp.vel * dt
        fp.active = 1 if fp.vel != 0.0 else 0


class Rig:
    """n simulated joints: homemod + sim_home_switch + motion stand-in."""

    def __init__(self, hal, n: int, switch=(), vel=10.0, acc=100.0,
                 limits=(-10.0, 10.0), start=None):
        self.hal = hal
        self.n = n
        hal.loadrt("homemod")
        self.api = HomingApi.from_address(
            _core.symbol_address("halsdk_homing_api"))
        assert self.api.version == 1
        self.j = (MotJoint * n)()
        for k in range(n):
            jt = self.j[k]
            jt.index = k
            jt.flags = JointFlag.ACTIVE
            jt.min_pos_limit, jt.max_pos_limit = limits
            jt.vel_limit = vel
            jt.acc_limit = acc
            jt.free_tp.max_acc = acc
            jt.free_tp.max_vel = vel
        self.cid = _core.comp_new("homerig", _core.COMP_USER)
        assert self.api.init(self.cid, DT, n, 0, self.j) == 0
        _core.comp_ready(self.cid)
        hal.loadrt("sim_home_switch", count=n)
        hal.newthread("servo", PERIOD_NS)
        for k in range(n):
            hal.addf(f"sim-home-switch.{k}", "servo")
            hal.net(f"sw{k}", f"sim-home-switch.{k}.home-sw",
                    f"joint.{k}.home-sw-in")
            # the switches' own index timer is not used (the encoder below)
            hal.setp(f"sim-home-switch.{k}.index-delay-ms", 0)
        for k, pos in enumerate(switch):
            hal.setp(f"sim-home-switch.{k}.home-pos", pos)
        self.cur = [_core.find("pin", f"sim-home-switch.{k}.cur-pos")
                    for k in range(n)]
        self.ie = [_core.find("pin", f"joint.{k}.index-enable")
                   for k in range(n)]
        self.raw = [0.0] * n            # physical motor position
        self.base = [0.0] * n           # encoder count origin
        self.index_on = [True] * n      # marks exist
        self.reset = [True] * n         # encoder resets at the mark
        self.index_hit = [None] * n     # raw position of the last mark used
        for k, p in enumerate(start or ()):
            self.raw[k] = p
            self.j[k].motor_pos_cmd = p
            self.j[k].pos_cmd = self.j[k].coarse_pos = p
            self.j[k].free_tp.pos = self.j[k].free_tp.target = p
        self.cycle = 0

    # -- configuration and commands --
    def params(self, k, **kw) -> int:
        p = HomeParams(home_sequence=HOME_SEQUENCE_NONE)
        for key, v in kw.items():
            setattr(p, key, v)
        self.why = C.create_string_buffer(200)
        return self.api.set_params(k, C.byref(p), self.why, 200)

    def reason(self) -> str:
        return self.why.value.decode()

    def start(self, k) -> int:
        self.why = C.create_string_buffer(200)
        return self.api.start(k, self.why, 200)

    def unhome(self, k) -> int:
        self.why = C.create_string_buffer(200)
        return self.api.unhome(k, self.why, 200)

    def error(self) -> str:
        return self.api.take_error().decode()

    # -- one servo cycle --
    def _encoder(self, k, old, new):
        """Index marks crossed from old to new while index-enable is set:
        clear it (and restart the count at the mark)."""
        if not (self.index_on[k] and self.ie[k].value) or old == new:
            return
        lo, hi = min(old, new), max(old, new)
        m = math.floor((hi - INDEX_PHASE) / INDEX_PITCH) * INDEX_PITCH \
            + INDEX_PHASE
        if m < lo or (m == lo and new > old) or (m == hi and new < old):
            return
        if new < old:       # moving down: the first mark below old
            m = math.ceil((lo - INDEX_PHASE) / INDEX_PITCH) * INDEX_PITCH \
                + INDEX_PHASE
        self.ie[k].setp(False)
        self.index_hit[k] = m
        if self.reset[k]:
            self.base[k] = m

    def step(self):
        api = self.api
        for k in range(self.n):
            jt = self.j[k]
            old = self.raw[k]
            # the motor follows its command (in encoder counts)
            self.raw[k] = jt.motor_pos_cmd + self.base[k]
            self._encoder(k, old, self.raw[k])
            self.cur[k].setp(self.raw[k])
        self.hal.step(1)                        # home switches
        for k in range(self.n):
            jt = self.j[k]
            jt.motor_pos_fb = self.raw[k] - self.base[k]
            jt.pos_fb = jt.motor_pos_fb - jt.motor_offset
        api.read_inputs()
        busy = api.run()
        for k in range(self.n):
            jt = self.j[k]
            plan_update(jt.free_tp, DT)
            jt.pos_cmd = jt.coarse_pos = jt.free_tp.pos
            jt.vel_cmd = jt.free_tp.vel
            jt.motor_pos_cmd = jt.pos_cmd + jt.motor_offset
            jt.ferror = jt.pos_cmd - jt.pos_fb
        api.write_outputs()
        self.cycle += 1
        return busy

    def run(self, cycles=20000):
        """Step until homing ends; returns per-joint traces."""
        tr = {k: {"state": [], "vel": [], "pos": [], "homing": [],
                  "ferror": []}
              for k in range(self.n)}
        for _ in range(cycles):
            busy = self.step()
            for k in range(self.n):
                jt = self.j[k]
                t = tr[k]
                t["state"].append(self.api.state(k))
                t["vel"].append(jt.free_tp.vel)
                t["pos"].append(jt.pos_cmd)
                t["homing"].append(self.api.is_homing(k))
                t["ferror"].append(jt.ferror)
            if not busy:
                break
        else:
            raise AssertionError("homing did not end")
        return {k: {n: np.array(v) for n, v in t.items()}
                for k, t in tr.items()}


@pytest.fixture
def rig(hal):
    with factory(functools.partial(Rig, hal),
                 lambda r: _core.comp_exit(r.cid)) as make:
        yield make


def physical(r, k, pos):
    """Motor (raw) position of joint position pos after homing."""
    return pos + r.j[k].motor_offset + r.base[k]


# ---------------------------------------------------------------- pins


def test_pins_made_with_reference_names_and_directions(hal, rig):
    rig(2)
    want = {"home-sw-in": ("bit", "IN"), "homing": ("bit", "OUT"),
            "homed": ("bit", "OUT"), "home-state": ("s32", "OUT"),
            "index-enable": ("bit", "IO")}
    for k in range(2):
        for name, (typ, d) in want.items():
            pin = _core.find("pin", f"joint.{k}.{name}")
            assert pin is not None, name
            assert _core.TYPE_NAMES[pin.type] == typ
            assert _core.DIR_NAMES[pin.direction].replace("I/O", "IO") \
                == d


# ------------------------------------------------ switch latch variants


@pytest.mark.parametrize("latch", [0.5, -0.5])
def test_switch_latch_sets_offset_and_final_move(hal, rig, latch):
    """Search up at 5 to a switch at 3.2, latch at +-0.5 (same or opposite
    direction), HOME_OFFSET 4 at the latch point, final move to HOME 1."""
    r = rig(1, switch=[3.2])
    hyst = 0.1
    assert r.params(0, home_offset=4.0, home=1.0, home_search_vel=5.0,
                    home_latch_vel=latch, home_final_vel=2.0,
                    home_sequence=0) == 0, r.reason()
    assert r.start(0) == 0, r.reason()
    tr = r.run()[0]
    assert r.api.is_homed(0) and not r.api.is_homing(0)
    assert r.error() == ""
    jt = r.j[0]
    # final position exactly HOME
    assert jt.pos_cmd == 1.0 and jt.free_tp.pos == 1.0
    # the joint coordinate of the switch edge is HOME_OFFSET, to within
    # one servo period of motion at latch speed
    trip = 3.2 if latch > 0 else 3.2 - hyst
    assert abs((trip - jt.motor_offset) - 4.0) <= abs(latch) * DT + 1e-9
    # the latch phase ran at the latch speed, nothing above the limits
    lat = tr["state"] == HS_LATCH
    assert lat.any()
    assert np.abs(tr["vel"][lat]).max() <= abs(latch) + 1e-12
    assert np.abs(tr["vel"]).max() <= 5.0 + 1e-12
    fin = tr["state"] == HS_FINAL
    assert np.abs(tr["vel"][fin]).max() == pytest.approx(2.0)
    assert _core.find("pin", "joint.0.homed").value is True
    assert _core.find("pin", "joint.0.homing").value is False


def test_motor_command_continuous_through_homing(hal, rig):
    r = rig(1, switch=[-2.0])
    assert r.params(0, home_offset=-1.0, home=0.0, home_search_vel=-4.0,
                    home_latch_vel=1.0, home_sequence=0) == 0, r.reason()
    assert r.start(0) == 0
    motor = []
    for _ in range(20000):
        busy = r.step()
        motor.append(r.j[0].motor_pos_cmd)
        if not busy:
            break
    d = np.abs(np.diff(motor))
    # no step anywhere: never faster than the fastest move (the final
    # move at the joint's max speed 10)
    assert d.max() <= 10.0 * DT + 1e-9
    assert d[:-1].max() > 9.9 * DT
    assert r.j[0].pos_cmd == 0.0
    assert abs((-2.0 + 0.1 - r.j[0].motor_offset) - (-1.0)) <= 1.0 * DT


def test_switch_closed_at_start_backs_off_first(hal, rig):
    r = rig(1, switch=[1.0], start=[1.5])
    assert r.params(0, home_offset=0.0, home=-1.0, home_search_vel=3.0,
                    home_latch_vel=0.2, home_sequence=0) == 0
    r.step()
    assert _core.find("pin", "joint.0.home-sw-in").value is True
    assert r.start(0) == 0
    tr = r.run()[0]
    assert r.api.is_homed(0), r.error()
    assert tr["pos"].min() < 1.0 - 0.1        # it left the switch first
    assert abs((1.0 - r.j[0].motor_offset) - 0.0) <= 0.2 * DT + 1e-9
    assert r.j[0].pos_cmd == -1.0


# ---------------------------------------------------------- index


@pytest.mark.parametrize("reset", [True, False])
def test_switch_then_index(hal, rig, reset):
    r = rig(1, switch=[2.0])
    r.reset[0] = reset
    flags = HomeFlag.USE_INDEX | (0 if reset else HomeFlag.INDEX_NO_ENCODER_RESET)
    assert r.params(0, home_offset=0.5, home=0.0, home_search_vel=4.0,
                    home_latch_vel=-0.3, home_sequence=0, flags=flags) == 0
    assert r.start(0) == 0
    tr = r.run()[0]
    assert r.api.is_homed(0), r.error()
    m = r.index_hit[0]
    # latch moves down off the switch (released at 1.9), then the first
    # mark below that: 1.37
    assert m == pytest.approx(1.37)
    jt = r.j[0]
    # joint coordinate of the mark = HOME_OFFSET
    mark_joint = (m - r.base[0]) - jt.motor_offset
    if reset:
        assert mark_joint == pytest.approx(0.5, abs=1e-12)
    else:
        assert abs(mark_joint - 0.5) <= 0.3 * DT + 1e-9
    assert jt.pos_cmd == 0.0
    idx = tr["state"] == HS_INDEX
    assert idx.any()
    assert np.abs(tr["vel"][idx]).max() <= 0.3 + 1e-12
    assert _core.find("pin", "joint.0.index-enable").value is False
    # feedback continuous: the encoder reset did not show as a jump in
    # the joint's following error (one cycle of motion at most)
    assert np.abs(tr["ferror"]).max() <= 10.0 * DT + 1e-9


def test_index_only_when_search_vel_zero(hal, rig):
    r = rig(1, start=[0.2])
    assert r.params(0, home_offset=3.0, home=2.0, home_latch_vel=0.25,
                    home_sequence=0, flags=HomeFlag.USE_INDEX) == 0
    assert r.start(0) == 0
    tr = r.run()[0]
    assert r.api.is_homed(0), r.error()
    assert r.index_hit[0] == pytest.approx(0.37)
    assert r.j[0].motor_offset == pytest.approx(-3.0)
    assert r.j[0].pos_cmd == 2.0
    assert (tr["state"] == HS_INDEX).any()


def test_index_pulse_not_found(hal, rig):
    r = rig(3, limits=(0.0, 2.0))
    r.index_on[2] = False
    assert r.params(2, home_latch_vel=1.0, home_sequence=0,
                    flags=HomeFlag.USE_INDEX) == 0
    assert r.start(2) == 0
    r.run()
    assert not r.api.is_homed(2)
    assert r.error() == "joint 2 index pulse not found"
    assert r.error() == ""                       # taken
    assert _core.find("pin", "joint.2.index-enable").value is False


# ------------------------------------------------- special home types


def test_immediate_home(hal, rig):
    r = rig(1, start=[5.0])
    assert r.params(0, home_offset=1.0, home=0.0, home_sequence=0) == 0
    assert r.start(0) == 0
    r.run()
    assert r.api.is_homed(0)
    # the place where it stood is HOME_OFFSET: motor 5 is joint 1
    assert 5.0 - r.j[0].motor_offset == 1.0
    assert r.j[0].pos_cmd == 0.0


def test_no_final_move_ends_near_the_latch_point(hal, rig):
    r = rig(1, switch=[1.0])
    assert r.params(0, home_offset=3.0, home=0.0, home_search_vel=2.0,
                    home_latch_vel=0.2, home_sequence=0,
                    flags=HomeFlag.NO_FINAL_MOVE) == 0
    r.start(0)
    tr = r.run()[0]
    assert r.api.is_homed(0)
    assert not (tr["state"] == HS_FINAL).any()
    # stopped from latch speed: just past HOME_OFFSET
    assert 3.0 <= r.j[0].pos_cmd <= 3.0 + 0.2 ** 2 / 100 + 0.2 * DT


@pytest.mark.parametrize("mode,final", [(1, True), (2, False)])
def test_absolute_encoder(hal, rig, mode, final):
    r = rig(1, start=[7.0])
    flags = HomeFlag.ABSOLUTE_ENCODER | (HomeFlag.NO_FINAL_MOVE if mode == 2 else 0)
    assert r.params(0, home_offset=2.0, home=1.0, home_search_vel=5.0,
                    home_latch_vel=1.0, home_sequence=0, flags=flags) == 0
    r.step()
    assert r.start(0) == 0
    tr = r.run()[0]
    assert r.api.is_homed(0)
    assert 7.0 - r.j[0].motor_offset == 2.0   # feedback was HOME_OFFSET
    assert r.j[0].pos_cmd == (1.0 if final else 2.0)
    assert (len(tr["state"]) < 5) == (not final)
    # a homed absolute joint is not homed again
    assert r.start(0) < 0 and "absolute encoder" in r.reason()


# ------------------------------------------------------- sequences


def test_home_all_runs_sequences_in_order(hal, rig):
    r = rig(3, switch=[1.0, 1.5, 2.0])
    for k, seq in enumerate((0, 1, 1)):
        assert r.params(k, home_offset=0.0, home=0.0, home_search_vel=5.0,
                        home_latch_vel=0.5, home_sequence=seq) == 0
    assert r.start(-1) == 0, r.reason()
    tr = r.run()
    assert r.api.all_homed()
    first = {k: np.argmax(tr[k]["homing"]) for k in range(3)}
    last = {k: len(tr[k]["homing"]) - np.argmax(tr[k]["homing"][::-1])
            for k in range(3)}
    assert first[0] == 0
    assert first[1] == first[2] >= last[0]      # 1, 2 after 0, together
    assert last[1] != last[2]                   # not synchronized


def test_single_joint_must_wait_for_lower_sequence(hal, rig):
    r = rig(2)
    r.params(0, home_sequence=0)
    r.params(1, home_sequence=1)
    assert r.start(1) < 0
    assert r.reason() == ("joint 1 (HOME_SEQUENCE 1) cannot home before "
                          "joint 0 (HOME_SEQUENCE 0) is homed")
    assert r.start(0) == 0
    r.run()
    assert r.start(1) == 0
    r.run()
    assert r.api.all_homed()


def test_synchronized_final_moves(hal, rig):
    """Joints 1, 2 in sequence -1: homed together by home all, or by
    homing one of them; final moves start in one cycle and end
    together."""
    r = rig(3, switch=[1.0, 1.0, 3.0], vel=20.0, acc=200.0)
    r.params(0, home_sequence=0)
    for k in (1, 2):
        assert r.params(k, home_offset=2.0, home=-6.0, home_search_vel=6.0,
                        home_latch_vel=0.5, home_final_vel=4.0 + k,
                        home_sequence=-2) == 0
    r.params(0, home_sequence=0)
    assert r.start(0) == 0
    r.run()
    assert r.start(2) == 0, r.reason()          # takes joint 1 along
    assert r.api.is_homing(1)
    tr = r.run()
    assert r.api.is_homed(1) and r.api.is_homed(2)
    fin = {k: np.flatnonzero(tr[k]["state"] == HS_FINAL) for k in (1, 2)}
    assert fin[1][0] == fin[2][0]               # started together
    end = {k: fin[k][-1] for k in (1, 2)}
    dur = end[1] - fin[1][0]
    assert abs(end[1] - end[2]) <= 0.03 * dur  # ended together
    # both went to HOME exactly, speeds within their HOME_FINAL_VEL
    for k in (1, 2):
        assert r.j[k].pos_cmd == -6.0
        assert np.abs(tr[k]["vel"][fin[k]]).max() <= 4.0 + k + 1e-12
    assert (tr[1]["state"] == HS_SYNC).any() or (tr[2]["state"] ==
                                                 HS_SYNC).any()


def test_home_all_refuses_gaps_and_bad_start(hal, rig):
    r = rig(3)
    r.params(0, home_sequence=0)
    r.params(1, home_sequence=2)
    assert r.start(-1) < 0
    assert "gap" in r.reason() and "1" in r.reason()
    r.params(0, home_sequence=2)
    r.params(1, home_sequence=3)
    assert r.start(-1) < 0
    assert "must start at 0 or 1" in r.reason()
    r2 = r
    for k in range(3):
        r2.params(k, home_sequence=HOME_SEQUENCE_NONE)
    assert r.start(-1) < 0 and "no joint has a HOME_SEQUENCE" in r.reason()


def test_home_all_skips_unsequenced_joints(hal, rig):
    r = rig(2)
    r.params(0, home_sequence=0)
    r.params(1)                                 # not in home all
    assert r.start(-1) == 0
    r.run()
    assert r.api.is_homed(0) and not r.api.is_homed(1)
    assert not r.api.all_homed()


def test_home_all_skips_inactive_joints(hal, rig):
    r = rig(3)
    for k in range(3):
        r.params(k, home_sequence=k)
    r.j[1].flags = 0                            # DEACTIVATE_JOINT
    assert r.start(-1) == 0, r.reason()
    r.run()
    assert [r.api.is_homed(k) for k in range(3)] == [1, 0, 1]
    assert r.api.all_homed()                    # the active ones
    assert r.start(1) < 0 and r.reason() == "joint 1 is not active"
    r.unhome(2)
    assert r.start(2) == 0, r.reason()          # joint 1 is not in the way


# ----------------------------------------------------- shared, limits


def test_shared_switch_closed_refuses(hal, rig):
    r = rig(1, switch=[0.5], start=[1.0])
    r.params(0, home_search_vel=1.0, home_latch_vel=0.1, home_sequence=0,
             flags=HomeFlag.IS_SHARED)
    r.step()
    assert r.start(0) < 0
    assert r.reason() == ("joint 0 home switch already closed at start of "
                          "search (HOME_IS_SHARED)")
    assert not r.api.is_homing(0)


def test_shared_switch_closed_when_its_sequence_starts(hal, rig):
    """Joint 1 (shared switch) is checked when its sequence starts: the
    switch of its neighbour closes it meanwhile; home all fails."""
    r = rig(2, switch=[0.5, 0.5], start=[0.0, 0.0])
    hal.unlinkp("joint.1.home-sw-in")
    hal.linkps("joint.1.home-sw-in", "sw0")     # one wire, two joints
    r.params(0, home_offset=0.0, home=0.5, home_search_vel=1.0,
             home_latch_vel=0.1, home_sequence=0, flags=HomeFlag.IS_SHARED,
             home_final_vel=1.0)
    # joint 0 ends on the switch (HOME = switch point)
    r.params(1, home_search_vel=1.0, home_latch_vel=0.1, home_sequence=1,
             flags=HomeFlag.IS_SHARED)
    assert r.start(-1) == 0
    r.run()
    assert r.api.is_homed(0) and not r.api.is_homed(1)
    assert r.error() == ("home all stopped at sequence 1: joint 1 home "
                         "switch already closed at start of search "
                         "(HOME_IS_SHARED)")


def test_ignore_limits_only_while_homing(hal, rig):
    r = rig(2, switch=[1.0, 1.0])
    for k in range(2):
        r.params(k, home_search_vel=2.0, home_latch_vel=0.5,
                 home_sequence=0, flags=HomeFlag.IGNORE_LIMITS if k == 0 else 0)
    assert not r.api.ignores_limits(0)
    r.start(-1)
    r.step()
    assert r.api.ignores_limits(0) and not r.api.ignores_limits(1)
    r.run()
    assert not r.api.ignores_limits(0)


def test_search_without_switch_fails_at_end_of_travel(hal, rig):
    r = rig(2, switch=[0, 50.0], limits=(-1.0, 1.0), vel=20)
    r.params(1, home_search_vel=10.0, home_latch_vel=1.0, home_sequence=0)
    assert r.start(1) == 0
    tr = r.run()[1]
    assert r.error() == ("joint 1 homing: search ended without finding the "
                         "switch")
    assert not r.api.is_homed(1)
    # it went past the soft limit by the full travel (2), not further
    assert tr["pos"].max() == pytest.approx(3.0)


# -------------------------------------------- abort, unhome, volatile


def test_abort_stops_and_leaves_unhomed(hal, rig):
    r = rig(1, switch=[5.0])
    r.params(0, home_search_vel=2.0, home_latch_vel=0.5, home_sequence=0)
    r.start(0)
    for _ in range(300):
        r.step()
    assert r.api.is_homing(0)
    r.api.abort()
    assert not r.api.is_homing(0) and not r.api.is_homed(0)
    assert r.error() == "homing aborted (joint 0)"
    assert r.j[0].free_tp.enable == 0
    for _ in range(100):
        r.step()
    assert r.j[0].free_tp.vel == 0.0            # decelerated, stopped
    assert r.api.state(0) == HS_IDLE
    assert _core.find("pin", "joint.0.homing").value is False


def test_unhome_and_volatile(hal, rig):
    r = rig(3)
    for k in range(3):
        r.params(k, home_sequence=0, volatile_home=(k == 1))
    r.start(-1)
    r.run()
    assert r.api.all_homed()
    assert r.unhome(-2) == 0                    # machine off
    assert [r.api.is_homed(k) for k in range(3)] == [1, 0, 1]
    assert r.unhome(2) == 0
    assert [r.api.is_homed(k) for k in range(3)] == [1, 0, 0]
    assert r.j[2].flags & JointFlag.HOMED == 0
    assert r.unhome(-1) == 0 and not r.api.is_homed(0)
    assert r.unhome(5) < 0 and r.reason() == \
        "joint 5 does not exist (num_joints=3)"


def test_no_rehome(hal, rig):
    r = rig(1)
    r.params(0, home_sequence=0, flags=HomeFlag.NO_REHOME)
    r.start(0)
    r.run()
    assert r.start(0) < 0 and "HOME_NO_REHOME" in r.reason()
    assert r.start(-1) == 0                     # home all skips it
    r.unhome(0)
    assert r.start(0) == 0


# --------------------------------------------------------- bad input


@pytest.mark.parametrize("kw,words", [
    ({"home_offset": math.nan}, "HOME_OFFSET is not a finite"),
    ({"home_search_vel": math.inf, "home_latch_vel": 1}, "HOME_SEARCH_VEL"),
    ({"home_search_vel": 2.0}, "HOME_LATCH_VEL is 0"),
    ({"flags": HomeFlag.USE_INDEX}, "HOME_USE_INDEX needs a nonzero"),
    ({"home": 11.0}, "outside the soft limits"),
    ({"home_sequence": 40}, "HOME_SEQUENCE 40 is out of range"),
    ({"flags": 0x1000}, "unknown homing flags"),
])
def test_set_params_refusals(hal, rig, kw, words):
    r = rig(2)
    assert r.params(1, **kw) < 0
    assert words in r.reason() and r.reason().startswith("joint 1")


def test_bad_joint_numbers_and_busy(hal, rig):
    r = rig(2, switch=[3.0])
    assert r.params(2) < 0 and "does not exist" in r.reason()
    assert r.start(7) < 0 and "does not exist" in r.reason()
    assert r.start(-5) < 0
    assert r.api.state(99) == 0 and r.api.is_homed(-3) == 0
    r.params(0, home_search_vel=1.0, home_latch_vel=0.1)
    r.start(0)
    r.step()
    assert r.params(0) < 0 and "is homing" in r.reason()
    assert r.start(1) < 0 and "in progress" in r.reason()
    assert r.unhome(0) < 0 and "abort" in r.reason()
    r.api.abort()
    j = r.j[1]
    j.flags = 0
    assert r.start(1) < 0 and r.reason() == "joint 1 is not active"


def test_homemod_loads_alone_and_api_is_inert(hal):
    hal.loadrt("homemod")
    api = HomingApi.from_address(_core.symbol_address("halsdk_homing_api"))
    why = C.create_string_buffer(100)
    assert api.start(0, why, 100) < 0
    assert "not initialized" in why.value.decode()
    assert api.run() == 0
    api.read_inputs()
    api.write_outputs()
    api.abort()
    assert api.take_error() == b""
    with pytest.raises(halsdk.HalError):
        hal.loadrt("homemod")


# ============================================ with the real motion module
#
# motmod + homemod + tpmod + trivkins, commanded through halsdk.motion.
# A Python function in the servo thread (before the motion functions) is
# the motor and its encoder: the motor follows motor-pos-cmd one cycle
# late; the encoder has index marks like the stand-in above.


class SimMotors:
    def __init__(self, hal, n):
        self.n = n
        self.cmd = [_core.find("pin", f"joint.{k}.motor-pos-cmd")
                    for k in range(n)]
        self.fb = [_core.find("pin", f"joint.{k}.motor-pos-fb")
                   for k in range(n)]
        self.ie = [_core.find("pin", f"joint.{k}.index-enable")
                   for k in range(n)]
        self.cur = [_core.find("pin", f"sim-home-switch.{k}.cur-pos")
                    for k in range(n)]
        self.raw = [0.0] * n
        self.base = [0.0] * n
        self.hit = [None] * n
        self.cid = _core.comp_new("simmotors", _core.COMP_USER)
        _core.export_python("simmotors", self, self.cid)
        _core.comp_ready(self.cid)

    def __call__(self, period):
        for k in range(self.n):
            old = self.raw[k]
            new = self.raw[k] = self.cmd[k].value + self.base[k]
            if self.ie[k].value and new != old:
                if new > old:
                    m = math.floor(new - INDEX_PHASE) + INDEX_PHASE
                    found = old < m <= new
                else:
                    m = math.ceil(new - INDEX_PHASE) + INDEX_PHASE
                    found = new <= m < old
                if found:
                    self.ie[k].setp(False)
                    self.hit[k] = m
                    self.base[k] = m
            self.fb[k].setp(self.raw[k] - self.base[k])
            self.cur[k].setp(self.raw[k])


@pytest.fixture
def machine(hal):
    import halsdk.motion as motion

    def make(n, switches, joints):
        for mod in ("trivkins", "homemod", "tpmod"):
            hal.loadrt(mod)
        hal.loadrt("motmod", servo_period_nsec=PERIOD_NS, num_joints=n)
        hal.loadrt("sim_home_switch", count=n)
        sim = SimMotors(hal, n)
        hal.addf("simmotors", "servo-thread")
        for k in range(n):
            hal.addf(f"sim-home-switch.{k}", "servo-thread")
            hal.net(f"sw{k}", f"sim-home-switch.{k}.home-sw",
                    f"joint.{k}.home-sw-in")
            hal.setp(f"sim-home-switch.{k}.home-pos", switches[k])
            hal.setp(f"sim-home-switch.{k}.index-delay-ms", 0)
        hal.addf("motion-command-handler", "servo-thread")
        hal.addf("motion-controller", "servo-thread")
        m = motion.Motion.connect(hal)
        m.configure(joints)
        m.enable()
        m.free()
        return m, sim
    return make


def _joint(**kw):
    d = dict(MIN_LIMIT=-10, MAX_LIMIT=10, MAX_VELOCITY=20,
             MAX_ACCELERATION=200, FERROR=1, MIN_FERROR=0.5)
    d.update(kw)
    return d


def _run_until_idle(hal, n, limit=20000, chunk=500):
    names = [f"joint.{k}.{p}" for k in range(n)
             for p in ("homing", "home-state", "vel-cmd", "pos-cmd")]
    parts = []
    for _ in range(limit // chunk):
        tr = hal.run(chunk, record=names)
        parts.append(tr)
        if not any(tr[f"joint.{k}.homing"][-1] for k in range(n)):
            break
    return {nm: np.concatenate([p[nm] for p in parts]) for nm in names}


@pytest.mark.parametrize("profile", ["trapezoid", "jerk"])
def test_motmod_home_all_sequence_and_sync(hal, machine, profile):
    """Joint 0 in sequence 1, joints 1, 2 synchronized in sequence -2:
    0 homes first, then 1 and 2 together, final moves together; exact
    positions; speeds within the homing speeds."""
    keys = dict(HOME_SEARCH_VEL=5, HOME_LATCH_VEL=-0.5, HOME_OFFSET=1.0,
                MAX_JERK=5000)
    m, sim = machine(3, [2.0, 3.0, 4.0], [
        _joint(HOME=0.0, HOME_SEQUENCE=1, HOME_FINAL_VEL=3, **keys),
        _joint(HOME=-2.0, HOME_SEQUENCE=-2, HOME_FINAL_VEL=4, **keys),
        _joint(HOME=-3.0, HOME_SEQUENCE=-2, HOME_FINAL_VEL=6, **keys)])
    m.disable()
    m.set_profile(profile)
    m.enable()
    m.home(-1)
    tr = _run_until_idle(hal, 3)
    st = m.status()
    assert [j.homed for j in st.joints] == [True, True, True], m.errors()
    assert m.errors() == []
    assert [j.pos_cmd for j in st.joints] == [0.0, -2.0, -3.0]
    for k, sw in enumerate((2.0, 3.0, 4.0)):
        # released at sw - hysteresis moving down at 0.5: HOME_OFFSET there
        off = hal.getp(f"joint.{k}.motor-offset")
        assert abs((sw - 0.1 - off) - 1.0) <= 0.5 * DT + 1e-9
    homing = {k: tr[f"joint.{k}.homing"] for k in range(3)}
    end0 = np.flatnonzero(homing[0])[-1]
    start1 = np.flatnonzero(homing[1])[0]
    assert start1 == np.flatnonzero(homing[2])[0] > end0
    fin = {k: np.flatnonzero(tr[f"joint.{k}.home-state"] == HS_FINAL)
           for k in (1, 2)}
    assert fin[1][0] == fin[2][0]
    assert abs(int(fin[1][-1]) - int(fin[2][-1])) <= \
        0.03 * (fin[1][-1] - fin[1][0])
    for k, final in enumerate((3.0, 4.0, 6.0)):
        v = np.abs(tr[f"joint.{k}.vel-cmd"])
        assert v.max() <= max(5.0, final) + 1e-9
        fin = tr[f"joint.{k}.home-state"] == HS_FINAL
        assert v[fin].max() <= final + 1e-9
        assert v[~fin].max() <= 5.0 + 1e-9
        lat = tr[f"joint.{k}.home-state"] == HS_LATCH
        assert v[lat].max() <= 0.5 + 1e-9


def test_motmod_index_with_encoder_reset(hal, machine):
    m, sim = machine(1, [2.0], [_joint(
        HOME_SEARCH_VEL=5, HOME_LATCH_VEL=-0.5, HOME_OFFSET=1.0, HOME=0.0,
        HOME_SEQUENCE=0, HOME_USE_INDEX=1)])
    m.home(0)
    _run_until_idle(hal, 1)
    assert m.errors() == []
    st = m.status()
    assert st.joints[0].homed and st.joints[0].pos_cmd == 0.0
    assert sim.hit[0] == pytest.approx(1.37)
    # the index is encoder position 0; joint position HOME_OFFSET there
    assert hal.getp("joint.0.motor-offset") == pytest.approx(-1.0,
                                                              abs=1e-12)


def test_motmod_fault_aborts_homing(hal, machine):
    m, sim = machine(1, [5.0], [_joint(
        HOME_SEARCH_VEL=2, HOME_LATCH_VEL=0.5, HOME_SEQUENCE=0)])
    m.home(0)
    hal.run(200)
    assert hal.getp("joint.0.homing")
    hal.setp("joint.0.amp-fault-in", True)
    hal.run(5)
    st = m.status()
    assert not st.joints[0].homed and not hal.getp("joint.0.homing")
    errs = m.errors()
    assert any("homing aborted (joint 0)" in e for e in errs), errs
