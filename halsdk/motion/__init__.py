"""halsdk.motion: the Python client of the motion controller (motmod).

Example (a simulated machine stepped deterministically)::

    from halsdk.motion import Motion

    m = Motion.connect(hal)         # hal: the halsdk.Hal of the instance
    m.enable()
    m.jog_incr(0, vel=10, dist=1.5)
    st = m.wait_inpos()
    print(st.joints[0].pos_cmd)

See docs/motion.rst for the commands and the status.
"""

from halsdk.motion.client import (
    EnableFailed,
    InputWait,
    Motion,
    MotionError,
    MotionTimeout,
    QueueRejected,
    Rejected,
)
from halsdk.motion.ini import (
    MotionConfig,
    MotionIniError,
    homing_fields,
    read_motion_ini,
)
from halsdk.motion.protocol import (
    HOME_SEQUENCE_NONE,
    Cmd,
    Echo,
    HomeFlag,
    JointFlag,
    KinsType,
    Mode,
    MotionType,
    OrientState,
    ProbeFlag,
    Profile,
    TermCond,
)
from halsdk.motion.status import (
    AxisStatus,
    JointStatus,
    Pose,
    SpindleStatus,
    Status,
)

__all__ = ["Motion", "Rejected", "EnableFailed", "QueueRejected",
           "MotionError", "MotionTimeout", "Cmd", "Echo", "InputWait", "Status",
           "JointStatus", "AxisStatus", "SpindleStatus", "OrientState",
           "Mode", "KinsType", "MotionType", "Profile", "TermCond", "Pose",
           "HomeFlag", "JointFlag", "ProbeFlag", "HOME_SEQUENCE_NONE",
           "homing_fields", "MotionConfig", "MotionIniError",
           "read_motion_ini"]
