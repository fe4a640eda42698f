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
    Cmd,
    InputWait,
    Motion,
    MotionError,
    MotionTimeout,
    QueueRejected,
    Rejected,
    homing_fields,
)
from halsdk.motion.ini import MotionConfig, MotionIniError, read_motion_ini
from halsdk.motion.status import (
    AxisStatus,
    JointStatus,
    KinsType,
    Mode,
    MotionType,
    OrientState,
    Pose,
    Profile,
    SpindleStatus,
    Status,
    TermCond,
)

__all__ = ["Motion", "Rejected", "QueueRejected", "MotionError",
           "MotionTimeout", "Cmd", "InputWait", "Status", "JointStatus",
           "AxisStatus", "SpindleStatus", "OrientState", "Mode", "KinsType",
           "MotionType", "Profile", "TermCond", "Pose", "homing_fields",
           "MotionConfig", "MotionIniError", "read_motion_ini"]
