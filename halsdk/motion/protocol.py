"""The numbers of the motion controller's protocol, as enums.

``components/motion/channel.h`` (with ``homing.h``, ``mot_joint.h`` and
``freeplan.h``) is the one source of these numbers: the compiled
extension :mod:`halsdk.motion._channel` takes them from the headers and
this module only gives them Python names.  A number is never typed here.
"""

from __future__ import annotations

import enum

from halsdk.motion import _channel

__all__ = ["Cmd", "Echo", "Mode", "TermCond", "MotionType", "KinsType",
           "OrientState", "Profile", "ProbeFlag", "HomeFlag", "JointFlag",
           "HOME_SEQUENCE_NONE", "CMD_LAST"]


def _doc(cls: type, text: str) -> type:
    cls.__doc__ = text
    return cls


Cmd = _doc(enum.IntEnum("Cmd", _channel.CMD, module=__name__),
           "Command codes (channel.h enum mot_cmd; part of the protocol).")
Echo = _doc(enum.IntEnum("Echo", _channel.ECHO, module=__name__),
            "echo_status of a command (channel.h enum mot_echo): DONE "
            "carried out completely, ACCEPTED started (goes on in later "
            "cycles), REJECTED nothing done.")
Mode = _doc(enum.IntEnum("Mode", _channel.MODE, module=__name__),
            "Operating mode of the motion controller: FREE (joints move on "
            "their own: jogs, homing), TELEOP (axis velocities through "
            "kinematics), COORD (the trajectory planner runs queued "
            "moves).")
TermCond = _doc(enum.IntEnum("TermCond", _channel.TERM, module=__name__),
                "What the planner does at the end of a coordinated move: "
                "STOP exact stop (G61.1), EXACT exact path (G61), BLEND "
                "blend within a tolerance (G64 P).")
MotionType = _doc(enum.IntEnum("MotionType", _channel.MOTION_TYPE,
                               module=__name__),
                  "Kind of a coordinated move (also on "
                  "``motion.motion-type``).")
KinsType = _doc(enum.IntEnum("KinsType", _channel.KINS_TYPE,
                             module=__name__),
                "kinematicsType() of the loaded kinematics module.")
OrientState = _doc(enum.IntEnum("OrientState", _channel.ORIENT_STATE,
                                module=__name__),
                   "State of a spindle orient (M19): RUNNING "
                   "spindle.N.orient is true, waiting for is-oriented; DONE "
                   "oriented, locked and braked; FAULT spindle.N.orient-fault "
                   "was not 0.")
Profile = _doc(enum.IntEnum("Profile", _channel.PROFILE, module=__name__),
               "Profile of the free and teleop planners (freeplan.h).")
ProbeFlag = _doc(enum.IntFlag("ProbeFlag", _channel.PROBE, module=__name__),
                 "Bits of a PROBE command's ival (channel.h MOT_PROBE_*).")
HomeFlag = _doc(enum.IntFlag("HomeFlag", _channel.HOME_FLAGS,
                             module=__name__),
                "Bits of SET_JOINT_HOMING_PARAMS home_flags (homing.h "
                "HOME_*).")
JointFlag = _doc(enum.IntFlag("JointFlag", _channel.JOINT_FLAGS,
                              module=__name__),
                 "Bits of a joint's status flags (mot_joint.h "
                 "MOT_JOINT_*).")

#: home_sequence of a joint whose HOME_SEQUENCE is not set (homing.h)
HOME_SEQUENCE_NONE: int = _channel.HOME_SEQ_NONE
#: every command code is below this (channel.h MOT_CMD_LAST)
CMD_LAST: int = _channel.CMD_LAST
