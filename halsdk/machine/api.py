"""The in-process Python API of a machine: :class:`Machine`.

Shaped after the reference ``linuxcnc`` module: the command methods
(``state``, ``mode``, ``home``, ``jog``, ``mdi``, ``program_open`` ...)
play ``linuxcnc.command``, :meth:`Machine.status` ``linuxcnc.stat`` and
:meth:`Machine.errors` ``linuxcnc.error_channel``.

A :class:`Machine` is the task code (:class:`TaskController`) driven by
its owner: every method issues the command and, where it waits, runs
task cycles itself.  When the machine's threads are not running in real
time every cycle steps the servo thread once, so a whole session is
deterministic.  Other processes reach the same task code through the
channels of ``halsdk run`` (:func:`halsdk.machine.connect`, ``import
linuxcnc``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Optional

from halsdk.machine.controller import (
    AUTO_PAUSE,
    AUTO_RESUME,
    AUTO_RUN,
    AUTO_STEP,
    JOG_CONTINUOUS,
    JOG_INCREMENT,
    JOG_STOP,
    KIND_NAMES,
    RCS_ERROR,
    TaskController,
    Ticket,
)
from halsdk.machine.iocontrol import IoControl
from halsdk.machine.task import InterpState, MachineError, TaskMode, TaskState

__all__ = ["Machine", "MachineStatus"]


@dataclass(frozen=True)
class MachineStatus:
    """A snapshot of the machine (the reference's ``stat`` fields)."""
    task_state: TaskState
    task_mode: TaskMode
    interp_state: InterpState
    estop: bool
    enabled: bool
    paused: bool
    file: str
    current_line: int           #: line of the running move (motion)
    read_line: int              #: last line the interpreter executed
    position: tuple             #: commanded position, machine coordinates
    actual_position: tuple
    homed: tuple
    tool_in_spindle: int
    pocket_prepped: int
    tool_offset: tuple
    g5x_index: int
    g5x_offset: tuple
    g92_offset: tuple
    mist: bool
    flood: bool
    feedrate: float             #: feed override scale
    rapidrate: float            #: rapid override scale
    tool_changes: int
    motion: Any                 #: the full :class:`halsdk.motion.Status`


class Machine(TaskController):
    """Control of one machine from the process that owns it.

    :param hal: the :class:`halsdk.Hal` hosting the machine.
    :param motion: a connected :class:`halsdk.motion.Motion`.
    :param io: the :class:`IoControl`; when None one is created with
        ``tool_table`` and its poll added to ``thread``.
    :param units: the machine's length unit, "mm" or "inch".

    Every command method raises :class:`MachineError` with the reason
    when the command is refused or fails.
    """

    @classmethod
    def from_launcher(cls, launcher: Any, io: Optional[IoControl] = None,
                      thread: str = "servo-thread") -> Machine:
        """A machine for a started :class:`halsdk.machine.launcher.Launcher`:
        the tool table from [EMCIO]TOOL_TABLE (RANDOM_TOOLCHANGER),
        units from [TRAJ]LINEAR_UNITS, [RS274NGC] from the INI file."""
        hal, motion, io, units = launcher.controller_parts(io, thread)
        machine = cls(hal, motion, io, units=units, thread=thread)
        machine.configure_from_ini(launcher.ini)
        return machine

    # -- waiting -----------------------------------------------------------

    def _tick(self) -> None:
        if self.motion.stepping:
            self.hal.step(1, thread=self.thread)
        else:
            time.sleep(0.001)

    def _wait(self, ticket: Ticket, timeout: Optional[float]) -> None:
        """Run cycles until ``ticket`` is finished; raise its error."""
        period = self.motion.status().servo_period or 0.001
        n = None if timeout is None else max(1, round(timeout / period))
        while not ticket.done:
            if n is not None:
                if n <= 0:
                    raise MachineError(f"{ticket.name}: not done within "
                                       f"{timeout:g} s")
                n -= 1
            self.update()
        self._raise(ticket)

    @staticmethod
    def _raise(ticket: Ticket) -> None:
        if ticket.state == RCS_ERROR:
            raise MachineError(ticket.error or f"{ticket.name} failed")

    def _do(self, name: str, wait: bool = True,
            timeout: Optional[float] = None, **args: Any) -> Ticket:
        ticket = self.issue(name, args)
        self._raise(ticket)
        if wait:
            self._wait(ticket, timeout)
        return ticket

    # -- the error channel ---------------------------------------------------

    def errors(self) -> list[tuple[str, str]]:
        """Messages since the last call, oldest first, as ``(kind, text)``:
        kind "error" (motion, I/O controller, interpreter and machine
        errors), "text" or "display" (G-code MSG comments)."""
        return [(KIND_NAMES.get(k, "error"), text)
                for k, text in self.take_messages()]

    # -- state and mode --------------------------------------------------

    def state(self, state: TaskState | int) -> None:
        """``command.state``: ESTOP, ESTOP_RESET, ON or OFF."""
        self._do("state", state=int(state), timeout=None)

    def mode(self, mode: TaskMode | int) -> None:
        """``command.mode``: MANUAL, AUTO or MDI (only while idle)."""
        self._do("mode", mode=int(mode))

    # -- manual ----------------------------------------------------------

    def home(self, joint: int = -1, wait: bool = True,
             timeout: Optional[float] = 120.0) -> None:
        """``command.home``: home ``joint`` (-1: all, in sequence); with
        ``wait``, until homed (``timeout`` seconds, simulated when
        stepping: a search across a long axis takes a while)."""
        self._do("home", joint=joint)
        if wait:
            self.motion.wait_homed(None if joint < 0 else [joint],
                                   timeout=timeout)

    def unhome(self, joint: int = -1) -> None:
        """``command.unhome``."""
        self._do("unhome", joint=joint)

    def jog(self, joint: int, vel: float, distance: Optional[float] = None,
            *, wait: bool = True) -> None:
        """Jog ``joint`` at ``vel`` by ``distance`` (None: continuously
        until :meth:`jog_stop`): ``command.jog`` JOG_INCREMENT and
        JOG_CONTINUOUS."""
        if distance is None:
            self._do("jog", action=JOG_CONTINUOUS, joint_mode=True,
                     index=joint, velocity=vel)
            return
        self._do("jog", action=JOG_INCREMENT, joint_mode=True, index=joint,
                 velocity=abs(vel), distance=distance)
        if wait:
            self.motion.wait_inpos()

    def jog_stop(self, joint: int) -> None:
        self._do("jog", action=JOG_STOP, joint_mode=True, index=joint)

    # -- MDI -------------------------------------------------------------

    def mdi(self, line: str, wait: bool = True) -> None:
        """``command.mdi``: run one line in MDI mode; with ``wait`` until
        its moves are done (the reference's ``wait_complete``)."""
        self._do("mdi", wait=wait, line=line)

    # -- programs --------------------------------------------------------

    def program_open(self, path: str) -> None:
        """``command.program_open``."""
        self._do("program_open", path=path)

    def program_run(self, start_line: int = 0, wait: bool = False,
                    timeout: float = 600.0) -> None:
        """``command.auto(AUTO_RUN, start_line)``: start the open program
        (lines before ``start_line`` are read but not executed).  The
        program advances in :meth:`update` / :meth:`run_for` /
        :meth:`wait_program` (with ``wait``: to its end)."""
        self._program_ticket = self._do("auto", wait=False, action=AUTO_RUN,
                                        line=start_line)
        if wait:
            self.wait_program(timeout)

    def pause(self) -> None:
        """``command.auto(AUTO_PAUSE)``: feed hold of the running moves."""
        self._do("auto", action=AUTO_PAUSE)

    def resume(self) -> None:
        """``command.auto(AUTO_RESUME)``: continue after pause or M0/M1."""
        self._do("auto", action=AUTO_RESUME)

    def step(self) -> None:
        """``command.auto(AUTO_STEP)``: while paused, execute the next
        block (its moves run, then the program holds again); while motion
        is in feed hold, let it run one move (motion's step)."""
        self._do("auto", action=AUTO_STEP)

    def abort(self) -> None:
        """``command.abort``: stop moves, spindle, coolant and tool
        handshakes; the interpreter goes idle (the machine stays on)."""
        self._do("abort")

    def update(self) -> None:
        """One cycle: carry out what the interpreter asked as far as
        motion allows, step the servo thread once (when stepped), notice
        the end of the program.  Raises MachineError when an error stopped
        the program or the MDI line in this cycle."""
        error = self.cycle()
        self._tick()
        if error is not None:
            raise MachineError(error)

    def run_for(self, seconds: float) -> None:
        """Run :meth:`update` for ``seconds`` (of servo time when
        stepped)."""
        period = self.motion.status().servo_period or 0.001
        for _ in range(max(1, round(seconds / period))):
            self.update()

    def wait_program(self, timeout: float = 600.0) -> None:
        """Run until the program ended and its moves are done; raises
        MachineError when it stopped on an error or M0 paused it."""
        period = self.motion.status().servo_period or 0.001
        for _ in range(max(1, round(timeout / period))):
            if self.task.interp_state is InterpState.IDLE:
                ticket = getattr(self, "_program_ticket", None)
                if ticket is not None:
                    self._raise(ticket)
                return
            if self._m0_paused:
                raise MachineError("the program paused (M0/M1): resume()")
            self.update()
        raise MachineError(f"the program did not end within {timeout:g} s")

    # -- overrides -------------------------------------------------------

    def feed_override(self, scale: float) -> None:
        """``command.feedrate``."""
        self._do("feedrate", scale=scale)

    def rapid_override(self, scale: float) -> None:
        """``command.rapidrate``."""
        self._do("rapidrate", scale=scale)

    # -- tool table ------------------------------------------------------

    def save_tool_table(self, path: Optional[str] = None) -> None:
        self.io.table.save(path)

    # -- status ----------------------------------------------------------

    def status(self) -> MachineStatus:
        """``stat.poll()``: a snapshot."""
        self._collect()
        st = self.motion.status()
        table = self.io.table
        prepped = table.selected_pocket
        return MachineStatus(
            task_state=self.task.state, task_mode=self.task.mode,
            interp_state=self.task.interp_state,
            estop=self.task.state is TaskState.ESTOP,
            enabled=st.enabled, paused=st.paused, file=self.file,
            current_line=st.program_line, read_line=self.interp.line,
            position=tuple(st.carte_pos_cmd),
            actual_position=tuple(st.carte_pos_fb),
            homed=tuple(st.homed), tool_in_spindle=table.tool_in_spindle,
            pocket_prepped=-1 if prepped is None else prepped,
            tool_offset=tuple(st.tool_offset),
            g5x_index=self.executor.g5x_index,
            g5x_offset=tuple(self.executor.g5x_offset),
            g92_offset=tuple(self.executor.g92_offset),
            mist=bool(self.io["coolant-mist"]),
            flood=bool(self.io["coolant-flood"]),
            feedrate=st.feed_scale, rapidrate=st.rapid_scale,
            tool_changes=self.io.changes, motion=st)
