"""The status snapshot of the motion controller as frozen dataclasses.

:meth:`halsdk.motion.Motion.status` returns a :class:`Status`: one
consistent copy of what motmod published at the end of one servo cycle.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from halsdk.motion.protocol import (
    JointFlag,
    KinsType,
    Mode,
    MotionType,
    OrientState,
    Profile,
    TermCond,
)

__all__ = ["Status", "JointStatus", "AxisStatus", "SpindleStatus", "Pose",
           "Mode", "KinsType", "MotionType", "OrientState", "Profile",
           "TermCond", "AXES"]

AXES = "xyzabcuvw"


class Pose(NamedTuple):
    """A position (or velocity) in the nine axes."""
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    a: float = 0.0
    b: float = 0.0
    c: float = 0.0
    u: float = 0.0
    v: float = 0.0
    w: float = 0.0


# bits of the joint flags (mot_joint.h)
JOINT_ACTIVE = int(JointFlag.ACTIVE)
JOINT_ENABLED = int(JointFlag.ENABLED)
JOINT_INPOS = int(JointFlag.INPOS)
JOINT_ERROR = int(JointFlag.ERROR)
JOINT_POS_SOFT = int(JointFlag.POS_SOFT)
JOINT_NEG_SOFT = int(JointFlag.NEG_SOFT)
JOINT_POS_HARD = int(JointFlag.POS_HARD)
JOINT_NEG_HARD = int(JointFlag.NEG_HARD)
JOINT_FERROR = int(JointFlag.FERROR)
JOINT_FAULT = int(JointFlag.FAULT)
JOINT_HOMING = int(JointFlag.HOMING)
JOINT_HOMED = int(JointFlag.HOMED)


@dataclass(frozen=True)
class JointStatus:
    """One joint.  Positions in joint units, velocities per second."""
    index: int
    pos_cmd: float              #: commanded position after interpolation
    pos_fb: float               #: feedback position (joint coordinates)
    vel: float                  #: commanded velocity
    acc: float                  #: commanded acceleration
    ferror: float               #: pos_cmd - pos_fb
    ferror_limit: float         #: the following error limit at this speed
    ferror_high_mark: float
    motor_pos_cmd: float        #: pos_cmd + compensation + motor offset
    motor_pos_fb: float
    motor_offset: float         #: set by homing
    backlash_corr: float        #: backlash and screw correction applied
    min_pos_limit: float
    max_pos_limit: float
    vel_limit: float
    acc_limit: float
    jerk_limit: float
    min_ferror: float
    max_ferror: float
    backlash: float
    free_target: float          #: target of the free planner
    free_active: bool           #: the free planner moves
    jog_active: bool
    home_state: int             #: the number on joint.N.home-state
    flags: int                  #: raw MOT_JOINT_* bits
    active: bool
    enabled: bool               #: amplifier enabled
    in_position: bool
    error: bool                 #: a limit, ferror or fault
    on_pos_soft_limit: bool
    on_neg_soft_limit: bool
    on_pos_limit: bool          #: pos-lim-sw-in is true
    on_neg_limit: bool          #: neg-lim-sw-in is true
    ferror_exceeded: bool
    faulted: bool               #: amp-fault-in is true
    homing: bool
    homed: bool

    @classmethod
    def from_dict(cls, index: int, d: dict) -> JointStatus:
        f = d["flags"]
        return cls(
            index=index, pos_cmd=d["pos_cmd"], pos_fb=d["pos_fb"],
            vel=d["vel_cmd"], acc=d["acc_cmd"], ferror=d["ferror"],
            ferror_limit=d["ferror_limit"],
            ferror_high_mark=d["ferror_high_mark"],
            motor_pos_cmd=d["motor_pos_cmd"],
            motor_pos_fb=d["motor_pos_fb"], motor_offset=d["motor_offset"],
            backlash_corr=d["backlash_filt"],
            min_pos_limit=d["min_pos_limit"],
            max_pos_limit=d["max_pos_limit"], vel_limit=d["vel_limit"],
            acc_limit=d["acc_limit"], jerk_limit=d["jerk_limit"],
            min_ferror=d["min_ferror"], max_ferror=d["max_ferror"],
            backlash=d["backlash"], free_target=d["free_target"],
            free_active=d["free_active"], jog_active=d["jog_active"],
            home_state=d["home_state"], flags=f,
            active=bool(f & JOINT_ACTIVE), enabled=bool(f & JOINT_ENABLED),
            in_position=bool(f & JOINT_INPOS), error=bool(f & JOINT_ERROR),
            on_pos_soft_limit=bool(f & JOINT_POS_SOFT),
            on_neg_soft_limit=bool(f & JOINT_NEG_SOFT),
            on_pos_limit=bool(f & JOINT_POS_HARD),
            on_neg_limit=bool(f & JOINT_NEG_HARD),
            ferror_exceeded=bool(f & JOINT_FERROR),
            faulted=bool(f & JOINT_FAULT), homing=bool(f & JOINT_HOMING),
            homed=bool(f & JOINT_HOMED))


@dataclass(frozen=True)
class AxisStatus:
    """One Cartesian axis (X .. W)."""
    letter: str
    pos_cmd: float
    vel: float
    teleop_pos: float
    teleop_vel: float
    teleop_target: float
    teleop_active: bool
    jog_active: bool
    min_pos_limit: float
    max_pos_limit: float
    vel_limit: float
    acc_limit: float
    jerk_limit: float

    @classmethod
    def from_dict(cls, letter: str, d: dict) -> AxisStatus:
        return cls(letter=letter, pos_cmd=d["pos_cmd"], vel=d["vel_cmd"],
                   teleop_pos=d["teleop_pos"], teleop_vel=d["teleop_vel"],
                   teleop_target=d["teleop_target"],
                   teleop_active=d["teleop_active"],
                   jog_active=d["jog_active"],
                   min_pos_limit=d["min_pos_limit"],
                   max_pos_limit=d["max_pos_limit"],
                   vel_limit=d["vel_limit"], acc_limit=d["acc_limit"],
                   jerk_limit=d["jerk_limit"])


@dataclass(frozen=True)
class SpindleStatus:
    """One spindle."""
    index: int
    on: bool                    #: spindle.N.on
    direction: int              #: 1 forward, -1 reverse, 0 stopped
    speed: float                #: spindle.N.speed-out, rpm (signed)
    speed_in: float             #: spindle.N.speed-in, rev/s
    revs: float                 #: spindle.N.revs
    at_speed: bool
    brake: bool
    locked: bool                #: oriented and held
    orient_state: OrientState
    orient_angle: float
    orient_fault: int
    inhibit: bool
    amp_fault: bool
    css_factor: float           #: CSS surface speed (0: off)

    @classmethod
    def from_dict(cls, index: int, d: dict) -> SpindleStatus:
        return cls(index=index, on=d["on"], direction=d["direction"],
                   speed=d["speed"], speed_in=d["speed_in"],
                   revs=d["revs"], at_speed=d["at_speed"],
                   brake=d["brake"], locked=d["locked"],
                   orient_state=_enum(OrientState, d["orient_state"]),
                   orient_angle=d["orient_angle"],
                   orient_fault=d["orient_fault"], inhibit=d["inhibit"],
                   amp_fault=d["amp_fault"], css_factor=d["css_factor"])


def _enum(cls, value):
    try:
        return cls(value)
    except ValueError:
        return value


@dataclass(frozen=True)
class Status:
    """A consistent snapshot of the motion controller (one servo cycle)."""
    heartbeat: int              #: servo cycles run so far
    mode: Mode
    enabled: bool
    in_position: bool           #: nothing moves
    homed: tuple                #: per joint in use
    all_homed: bool
    homing: bool
    joints: tuple               #: JointStatus of the joints in use
    axes: tuple                 #: AxisStatus of X .. W
    carte_pos_cmd: Pose
    carte_pos_fb: Pose
    carte_pos_fb_ok: bool       #: carte_pos_fb comes from forward kins
    current_vel: float          #: path velocity of the coord planner
    distance_to_go: float
    queue_depth: int
    motion_id: int
    motion_type: MotionType
    paused: bool
    probing: bool
    probe_tripped: bool
    probed_pos: Pose
    feed_scale: float
    rapid_scale: float
    override_limits: bool
    on_soft_limit: bool
    error: bool                 #: a fault disabled motion since ENABLE
    coord_error: bool
    num_joints: int
    num_joints_loaded: int
    num_extrajoints: int
    kins_type: KinsType
    profile: Profile
    term_cond: TermCond
    tolerance: float
    requested_vel: float
    vel_limit: float
    acc_limit: float
    tool_offset: Pose
    servo_period: float
    traj_period: float
    num_dio: int
    num_aio: int
    num_spindles: int
    dout: int
    din: int
    program_line: int           #: line of the running move (0: idle)
    feed_hold_enabled: bool     #: M53: motion.feed-hold applies
    adaptive_enabled: bool      #: M52: motion.adaptive-feed applies
    feed_hold: bool             #: feed hold in force now
    feed_inhibit: bool          #: motion.feed-inhibit is true
    adaptive_feed: float        #: motion.adaptive-feed
    feed_upm: float             #: motion.feed-upm
    linear_units: float         #: mm per length unit (0: not set)
    ain: tuple                  #: motion.analog-in-NN
    aout: tuple                 #: motion.analog-out-NN
    spindles: tuple             #: SpindleStatus of each spindle
    spindle_wait: int           #: the planner waits: 1 at-speed, 2 index
    at_speed_wait: bool         #: a feed move waits for spindle at-speed
    queue_taken: int            #: move-queue records motmod took (mod 2**32)
    errors: tuple               #: messages not yet taken by errors()

    @classmethod
    def from_dict(cls, d: dict, errors: tuple = ()) -> Status:
        n = max(0, min(d["num_joints"], len(d["joints"])))
        joints = tuple(JointStatus.from_dict(i, j)
                       for i, j in enumerate(d["joints"][:n]))
        axes = tuple(AxisStatus.from_dict(AXES[i], a)
                     for i, a in enumerate(d["axes"]))
        return cls(
            heartbeat=d["heartbeat"], mode=_enum(Mode, d["mode"]),
            enabled=d["enabled"], in_position=d["in_position"],
            homed=tuple(j.homed for j in joints),
            all_homed=d["all_homed"], homing=d["homing"],
            joints=joints, axes=axes,
            carte_pos_cmd=Pose(*d["carte_pos_cmd"]),
            carte_pos_fb=Pose(*d["carte_pos_fb"]),
            carte_pos_fb_ok=d["carte_pos_fb_ok"],
            current_vel=d["current_vel"],
            distance_to_go=d["distance_to_go"],
            queue_depth=d["queue_depth"], motion_id=d["motion_id"],
            motion_type=_enum(MotionType, d["motion_type"]),
            paused=d["paused"], probing=d["probing"],
            probe_tripped=d["probe_tripped"],
            probed_pos=Pose(*d["probed_pos"]),
            feed_scale=d["feed_scale"], rapid_scale=d["rapid_scale"],
            override_limits=d["override_limits"],
            on_soft_limit=d["on_soft_limit"], error=d["error"],
            coord_error=d["coord_error"], num_joints=d["num_joints"],
            num_joints_loaded=d["num_joints_loaded"],
            num_extrajoints=d["num_extrajoints"],
            kins_type=_enum(KinsType, d["kins_type"]),
            profile=_enum(Profile, d["profile"]),
            term_cond=_enum(TermCond, d["term_cond"]),
            tolerance=d["tolerance"], requested_vel=d["requested_vel"],
            vel_limit=d["vel_limit"], acc_limit=d["acc_limit"],
            tool_offset=Pose(*d["tool_offset"]),
            servo_period=d["servo_period"], traj_period=d["traj_period"],
            num_dio=d["num_dio"], num_aio=d["num_aio"],
            num_spindles=d["num_spindles"], dout=d["dout"], din=d["din"],
            program_line=d["program_line"],
            feed_hold_enabled=d["feed_hold_enabled"],
            adaptive_enabled=d["adaptive_enabled"],
            feed_hold=d["feed_hold"], feed_inhibit=d["feed_inhibit"],
            adaptive_feed=d["adaptive_feed"], feed_upm=d["feed_upm"],
            linear_units=d["linear_units"], ain=tuple(d["ain"]),
            aout=tuple(d["aout"]),
            spindles=tuple(SpindleStatus.from_dict(i, sp)
                           for i, sp in enumerate(d["spindles"])),
            queue_taken=d["queue_taken"],
            spindle_wait=d["spindle_wait"],
            at_speed_wait=d["queue_held"],
            errors=tuple(errors))
