"""The numbers the task channels carry, with the values of the
reference's ``linuxcnc`` module (``linuxcnc.RCS_DONE`` ...), in one place
for the task, its clients and the compat module."""

from __future__ import annotations

# command states (``linuxcnc.RCS_*``)
RCS_DONE = 1
RCS_EXEC = 2
RCS_ERROR = 3

# message kinds of the error channel (``linuxcnc.NML_*``, ``OPERATOR_*``)
NML_ERROR = 1
NML_TEXT = 2
NML_DISPLAY = 3
OPERATOR_ERROR = 11
OPERATOR_TEXT = 12
OPERATOR_DISPLAY = 13
#: kind number -> its word ("error", "text", "display")
KIND_NAMES = {NML_ERROR: "error", NML_TEXT: "text", NML_DISPLAY: "display",
              OPERATOR_ERROR: "error", OPERATOR_TEXT: "text",
              OPERATOR_DISPLAY: "display"}

# what the task waits for (``linuxcnc.EXEC_*``)
EXEC_ERROR = 1
EXEC_DONE = 2
EXEC_WAITING_FOR_MOTION = 3
EXEC_WAITING_FOR_MOTION_QUEUE = 4
EXEC_WAITING_FOR_IO = 5
EXEC_WAITING_FOR_MOTION_AND_IO = 7
EXEC_WAITING_FOR_DELAY = 8
EXEC_WAITING_FOR_SYSTEM_CMD = 9
EXEC_WAITING_FOR_SPINDLE_ORIENTED = 10

# jog actions, auto actions, spindle directions, trajectory modes
JOG_STOP, JOG_CONTINUOUS, JOG_INCREMENT = 0, 1, 2
AUTO_RUN, AUTO_PAUSE, AUTO_RESUME, AUTO_STEP = 0, 1, 2, 3
AUTO_REVERSE, AUTO_FORWARD = 4, 5
SPINDLE_FORWARD, SPINDLE_REVERSE, SPINDLE_OFF = 1, -1, 0
SPINDLE_INCREASE, SPINDLE_DECREASE, SPINDLE_CONSTANT = 10, 11, 12
TRAJ_MODE_FREE, TRAJ_MODE_COORD, TRAJ_MODE_TELEOP = 1, 2, 3
