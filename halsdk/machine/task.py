"""Machine states and operating modes (the task level of the machine).

States follow the I/O controller's E-stop chain::

    ESTOP --estop_reset--> ESTOP_RESET --on--> ON --off--> ESTOP_RESET
    any --estop, or iocontrol.0.emc-enable-in FALSE--> ESTOP

Leaving ON (off or E-stop) disables motion, which also drops the
amplifier enables.  Modes: MANUAL (jog, home), AUTO (programs), MDI
(single lines); a mode change is allowed only while no program or MDI
line runs.  Every refusal raises :class:`MachineError` saying why.
"""

from __future__ import annotations

import enum
from typing import Any, Callable, Optional

from halsdk.errors import HalError
from halsdk.machine.iocontrol import IoState

__all__ = ["InterpState", "MachineError", "Task", "TaskMode", "TaskState"]


class MachineError(HalError, RuntimeError):
    """A machine command refused in the current state or mode, or a
    program that stopped on an error."""


class TaskState(enum.IntEnum):
    """The numbers of the reference's STATE_* constants."""
    ESTOP = 1
    ESTOP_RESET = 2
    OFF = 3          # accepted as a request; reported as ESTOP_RESET
    ON = 4


class TaskMode(enum.IntEnum):
    """The numbers of the reference's MODE_* constants."""
    MANUAL = 1
    AUTO = 2
    MDI = 3


class InterpState(enum.IntEnum):
    """The numbers of the reference's INTERP_* constants."""
    IDLE = 1
    READING = 2
    PAUSED = 3
    WAITING = 4


class Task:
    """State and mode of one machine: ``motion`` is a connected
    :class:`halsdk.motion.Motion`, ``io`` an :class:`IoControl` whose
    ``poll`` runs every servo cycle."""

    def __init__(self, motion: Any, io: Any) -> None:
        self.motion = motion
        self.io = io
        self.mode = TaskMode.MANUAL
        self.interp_state = InterpState.IDLE
        self._was_on = False

    # -- state -------------------------------------------------------------

    @property
    def state(self) -> TaskState:
        s = self.io.state
        if s is IoState.ON:
            return TaskState.ON
        if s is IoState.ESTOP_RESET:
            return TaskState.ESTOP_RESET
        return TaskState.ESTOP

    def sync(self) -> bool:
        """Follow the I/O controller: when it left ON by itself (external
        E-stop), disable motion.  Returns True when that happened."""
        if self._was_on and self.io.state is not IoState.ON:
            self._was_on = False
            self._disable()
            return True
        return False

    def _disable(self) -> None:
        try:
            self.motion.abort()
        except HalError:
            pass
        self.motion.disable()
        self.interp_state = InterpState.IDLE

    def set_state(self, state: TaskState | int) -> None:
        """Request ``state`` (the reference's ``command.state``) and wait
        for the I/O controller's answer to an E-stop reset."""
        finished = self.request_state(state)
        if finished is not None:
            self.motion.wait_for(
                lambda _st: self.io.state is not IoState.RESETTING,
                what="the E-stop reset (iocontrol.0.emc-enable-in)")
            finished()

    def request_state(self, state: TaskState | int
                      ) -> Optional[Callable[[], bool]]:
        """Request ``state`` without waiting.  Returns None when it is
        reached, else (E-stop reset) a function that is True once the I/O
        controller answered and raises MachineError when the reset
        failed."""
        state = TaskState(state)
        if state is TaskState.ESTOP:
            self.io.estop()
            self._was_on = False
            self._disable()
        elif state is TaskState.ESTOP_RESET:
            if self.state is TaskState.ON:
                raise MachineError("E-stop reset refused: the machine is "
                                   "on (turn it off first)")
            if self.state is TaskState.ESTOP_RESET:
                return None
            self.io.estop_reset()
            return self._reset_answered
        elif state is TaskState.ON:
            if self.state is TaskState.ESTOP:
                raise MachineError("machine on refused: the machine is in "
                                   "E-stop (reset the E-stop first)")
            if self.state is TaskState.ON:
                return None
            self.io.machine_on()
            try:
                self.motion.enable()
            except HalError as e:
                # motmod refused, or a fault (amplifier, hard limit, ...)
                # disabled motion at once: the machine stays off
                self.io.machine_off()
                raise MachineError("machine on failed: "
                                   + getattr(e, "reason", str(e))) from e
            self._was_on = True
            self._apply_mode(self.mode)
        else:                                   # OFF
            if self.state is TaskState.ON:
                self.io.machine_off()
                self._was_on = False
                self._disable()
        return None

    def _reset_answered(self) -> bool:
        if self.io.state is IoState.RESETTING:
            return False
        if self.io.state is not IoState.ESTOP_RESET:
            raise MachineError(
                "E-stop reset failed: " + (self.io.error or
                                           "emc-enable-in stayed FALSE"))
        return True

    def require_on(self, what: str) -> None:
        self.sync()
        if self.state is not TaskState.ON:
            raise MachineError(f"{what} refused: the machine is not on "
                               f"(state {self.state.name})")

    # -- mode --------------------------------------------------------------

    def set_mode(self, mode: TaskMode | int) -> None:
        """Request ``mode`` (the reference's ``command.mode``)."""
        mode = TaskMode(mode)
        if mode is self.mode:
            return
        if self.interp_state is not InterpState.IDLE:
            raise MachineError(f"mode {mode.name} refused: the interpreter "
                               f"is {self.interp_state.name} (abort or "
                               "wait for the end first)")
        if self.state is TaskState.ON:
            self._apply_mode(mode)
        self.mode = mode

    def _apply_mode(self, mode: TaskMode) -> None:
        if mode is TaskMode.MANUAL:
            self.motion.free()
        else:
            self.motion.coord()

    def require_mode(self, mode: TaskMode, what: str) -> None:
        self.require_on(what)
        if self.mode is not mode:
            raise MachineError(f"{what} refused: needs {mode.name} mode "
                               f"(the machine is in {self.mode.name})")

    def require_idle(self, what: str) -> None:
        if self.interp_state is not InterpState.IDLE:
            raise MachineError(f"{what} refused: the interpreter is "
                               f"{self.interp_state.name}")
