"""The numbers of the motion controller's protocol, as enums.

``components/motion/channel.h`` (with ``homing.h``, ``mot_joint.h`` and
``freeplan.h``) is the one source of these numbers: the compiled
extension :mod:`halsdk.motion._channel` takes them from the headers and
this module only gives them Python names.  A number is never typed here.

Each enum lists its members by name (so that type checkers and readers
see them) and takes every value from the extension's dict of the same
group; tests/motion/test_protocol.py checks that the names listed here
are exactly the header's, in both directions.
"""

from __future__ import annotations

import enum

from halsdk.motion import _channel

__all__ = ["Cmd", "Echo", "Mode", "TermCond", "MotionType", "KinsType",
           "OrientState", "Profile", "ProbeFlag", "HomeFlag", "JointFlag",
           "HOME_SEQUENCE_NONE", "CMD_LAST"]


class Cmd(enum.IntEnum):
    """Command codes (channel.h enum mot_cmd; part of the protocol)."""

    ABORT = _channel.CMD["ABORT"]
    FREE = _channel.CMD["FREE"]
    TELEOP = _channel.CMD["TELEOP"]
    COORD = _channel.CMD["COORD"]
    ENABLE = _channel.CMD["ENABLE"]
    DISABLE = _channel.CMD["DISABLE"]
    ENABLE_AMPLIFIER = _channel.CMD["ENABLE_AMPLIFIER"]
    DISABLE_AMPLIFIER = _channel.CMD["DISABLE_AMPLIFIER"]
    ACTIVATE_JOINT = _channel.CMD["ACTIVATE_JOINT"]
    DEACTIVATE_JOINT = _channel.CMD["DEACTIVATE_JOINT"]
    PAUSE = _channel.CMD["PAUSE"]
    RESUME = _channel.CMD["RESUME"]
    STEP = _channel.CMD["STEP"]
    SCALE = _channel.CMD["SCALE"]
    RAPID_SCALE = _channel.CMD["RAPID_SCALE"]
    OVERRIDE_LIMITS = _channel.CMD["OVERRIDE_LIMITS"]
    HOME = _channel.CMD["HOME"]
    UNHOME = _channel.CMD["UNHOME"]
    JOG_CONT = _channel.CMD["JOG_CONT"]
    JOG_INCR = _channel.CMD["JOG_INCR"]
    JOG_ABS = _channel.CMD["JOG_ABS"]
    JOG_STOP = _channel.CMD["JOG_STOP"]
    SET_LINE = _channel.CMD["SET_LINE"]
    SET_CIRCLE = _channel.CMD["SET_CIRCLE"]
    SET_TELEOP_VECTOR = _channel.CMD["SET_TELEOP_VECTOR"]
    PROBE = _channel.CMD["PROBE"]
    CLEAR_PROBE_FLAG = _channel.CMD["CLEAR_PROBE_FLAG"]
    SET_NUM_JOINTS = _channel.CMD["SET_NUM_JOINTS"]
    SET_JOINT_POSITION_LIMITS = _channel.CMD["SET_JOINT_POSITION_LIMITS"]
    SET_JOINT_VEL_LIMIT = _channel.CMD["SET_JOINT_VEL_LIMIT"]
    SET_JOINT_ACC_LIMIT = _channel.CMD["SET_JOINT_ACC_LIMIT"]
    SET_JOINT_JERK_LIMIT = _channel.CMD["SET_JOINT_JERK_LIMIT"]
    SET_JOINT_MIN_FERROR = _channel.CMD["SET_JOINT_MIN_FERROR"]
    SET_JOINT_MAX_FERROR = _channel.CMD["SET_JOINT_MAX_FERROR"]
    SET_JOINT_HOMING_PARAMS = _channel.CMD["SET_JOINT_HOMING_PARAMS"]
    SET_JOINT_BACKLASH = _channel.CMD["SET_JOINT_BACKLASH"]
    SET_JOINT_COMP = _channel.CMD["SET_JOINT_COMP"]
    CLEAR_JOINT_COMP = _channel.CMD["CLEAR_JOINT_COMP"]
    SET_JOINT_MOTOR_OFFSET = _channel.CMD["SET_JOINT_MOTOR_OFFSET"]
    SET_AXIS_POSITION_LIMITS = _channel.CMD["SET_AXIS_POSITION_LIMITS"]
    SET_AXIS_VEL_LIMIT = _channel.CMD["SET_AXIS_VEL_LIMIT"]
    SET_AXIS_ACC_LIMIT = _channel.CMD["SET_AXIS_ACC_LIMIT"]
    SET_AXIS_JERK_LIMIT = _channel.CMD["SET_AXIS_JERK_LIMIT"]
    SET_VEL = _channel.CMD["SET_VEL"]
    SET_VEL_LIMIT = _channel.CMD["SET_VEL_LIMIT"]
    SET_ACC = _channel.CMD["SET_ACC"]
    SET_TERM_COND = _channel.CMD["SET_TERM_COND"]
    SET_OFFSET = _channel.CMD["SET_OFFSET"]
    SET_PROFILE = _channel.CMD["SET_PROFILE"]
    SET_DOUT = _channel.CMD["SET_DOUT"]
    SET_AOUT = _channel.CMD["SET_AOUT"]
    SET_FEED_HOLD_ENABLE = _channel.CMD["SET_FEED_HOLD_ENABLE"]
    SET_ADAPTIVE_FEED_ENABLE = _channel.CMD["SET_ADAPTIVE_FEED_ENABLE"]
    SET_LINEAR_UNITS = _channel.CMD["SET_LINEAR_UNITS"]
    SPINDLE_ON = _channel.CMD["SPINDLE_ON"]
    SPINDLE_OFF = _channel.CMD["SPINDLE_OFF"]
    SPINDLE_INCREASE = _channel.CMD["SPINDLE_INCREASE"]
    SPINDLE_DECREASE = _channel.CMD["SPINDLE_DECREASE"]
    SPINDLE_ORIENT = _channel.CMD["SPINDLE_ORIENT"]
    SPINDLE_BRAKE_ENGAGE = _channel.CMD["SPINDLE_BRAKE_ENGAGE"]
    SPINDLE_BRAKE_RELEASE = _channel.CMD["SPINDLE_BRAKE_RELEASE"]
    SPINDLE_SYNC_LINE = _channel.CMD["SPINDLE_SYNC_LINE"]
    RIGID_TAP = _channel.CMD["RIGID_TAP"]


class Echo(enum.IntEnum):
    """echo_status of a command (channel.h enum mot_echo): DONE carried
    out completely, ACCEPTED started (goes on in later cycles), REJECTED
    nothing done."""

    NONE = _channel.ECHO["NONE"]
    DONE = _channel.ECHO["DONE"]
    ACCEPTED = _channel.ECHO["ACCEPTED"]
    REJECTED = _channel.ECHO["REJECTED"]


class Mode(enum.IntEnum):
    """Operating mode of the motion controller: FREE (joints move on their
    own: jogs, homing), TELEOP (axis velocities through kinematics), COORD
    (the trajectory planner runs queued moves)."""

    FREE = _channel.MODE["FREE"]
    TELEOP = _channel.MODE["TELEOP"]
    COORD = _channel.MODE["COORD"]


class TermCond(enum.IntEnum):
    """What the planner does at the end of a coordinated move: STOP exact
    stop (G61.1), EXACT exact path (G61), BLEND blend within a tolerance
    (G64 P)."""

    STOP = _channel.TERM["STOP"]
    EXACT = _channel.TERM["EXACT"]
    BLEND = _channel.TERM["BLEND"]


class MotionType(enum.IntEnum):
    """Kind of a coordinated move (also on ``motion.motion-type``)."""

    NONE = _channel.MOTION_TYPE["NONE"]
    TRAVERSE = _channel.MOTION_TYPE["TRAVERSE"]
    FEED = _channel.MOTION_TYPE["FEED"]
    ARC = _channel.MOTION_TYPE["ARC"]
    TOOLCHANGE = _channel.MOTION_TYPE["TOOLCHANGE"]
    PROBING = _channel.MOTION_TYPE["PROBING"]
    INDEXROTARY = _channel.MOTION_TYPE["INDEXROTARY"]


class KinsType(enum.IntEnum):
    """kinematicsType() of the loaded kinematics module."""

    IDENTITY = _channel.KINS_TYPE["IDENTITY"]
    FORWARD_ONLY = _channel.KINS_TYPE["FORWARD_ONLY"]
    INVERSE_ONLY = _channel.KINS_TYPE["INVERSE_ONLY"]
    BOTH = _channel.KINS_TYPE["BOTH"]


class OrientState(enum.IntEnum):
    """State of a spindle orient (M19): RUNNING spindle.N.orient is true,
    waiting for is-oriented; DONE oriented, locked and braked; FAULT
    spindle.N.orient-fault was not 0."""

    NONE = _channel.ORIENT_STATE["NONE"]
    RUNNING = _channel.ORIENT_STATE["RUNNING"]
    DONE = _channel.ORIENT_STATE["DONE"]
    FAULT = _channel.ORIENT_STATE["FAULT"]


class Profile(enum.IntEnum):
    """Profile of the free and teleop planners (freeplan.h)."""

    TRAPEZOID = _channel.PROFILE["TRAPEZOID"]
    JERK = _channel.PROFILE["JERK"]


class ProbeFlag(enum.IntFlag):
    """Bits of a PROBE command's ival (channel.h MOT_PROBE_*)."""

    NO_ERROR = _channel.PROBE["NO_ERROR"]
    AWAY = _channel.PROBE["AWAY"]


class HomeFlag(enum.IntFlag):
    """Bits of SET_JOINT_HOMING_PARAMS home_flags (homing.h HOME_*)."""

    IGNORE_LIMITS = _channel.HOME_FLAGS["IGNORE_LIMITS"]
    USE_INDEX = _channel.HOME_FLAGS["USE_INDEX"]
    IS_SHARED = _channel.HOME_FLAGS["IS_SHARED"]
    UNLOCK_FIRST = _channel.HOME_FLAGS["UNLOCK_FIRST"]
    ABSOLUTE_ENCODER = _channel.HOME_FLAGS["ABSOLUTE_ENCODER"]
    NO_REHOME = _channel.HOME_FLAGS["NO_REHOME"]
    NO_FINAL_MOVE = _channel.HOME_FLAGS["NO_FINAL_MOVE"]
    INDEX_NO_ENCODER_RESET = _channel.HOME_FLAGS["INDEX_NO_ENCODER_RESET"]


class JointFlag(enum.IntFlag):
    """Bits of a joint's status flags (mot_joint.h MOT_JOINT_*)."""

    ACTIVE = _channel.JOINT_FLAGS["ACTIVE"]
    ENABLED = _channel.JOINT_FLAGS["ENABLED"]
    INPOS = _channel.JOINT_FLAGS["INPOS"]
    ERROR = _channel.JOINT_FLAGS["ERROR"]
    POS_SOFT = _channel.JOINT_FLAGS["POS_SOFT"]
    NEG_SOFT = _channel.JOINT_FLAGS["NEG_SOFT"]
    POS_HARD = _channel.JOINT_FLAGS["POS_HARD"]
    NEG_HARD = _channel.JOINT_FLAGS["NEG_HARD"]
    FERROR = _channel.JOINT_FLAGS["FERROR"]
    FAULT = _channel.JOINT_FLAGS["FAULT"]
    HOMING = _channel.JOINT_FLAGS["HOMING"]
    HOMED = _channel.JOINT_FLAGS["HOMED"]


#: home_sequence of a joint whose HOME_SEQUENCE is not set (homing.h)
HOME_SEQUENCE_NONE: int = _channel.HOME_SEQ_NONE
#: every command code is below this (channel.h MOT_CMD_LAST)
CMD_LAST: int = _channel.CMD_LAST
