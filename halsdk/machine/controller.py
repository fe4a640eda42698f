"""The task controller: the one implementation of the machine's commands.

A :class:`TaskController` owns the interpreter, the canon executor, the
I/O controller and the motion client of one machine.  Nothing in here
waits: :meth:`TaskController.issue` starts a command and returns its
:class:`Ticket` at once, and :meth:`TaskController.cycle`, called every
task cycle by its driver, advances the interpreter and the canon queue and
finishes the tickets whose work is done.  Two drivers reach it:

* :class:`halsdk.machine.Machine`, in the process that owns the machine
  (tests, programs): each method issues a command and, when asked to,
  runs cycles until its ticket is finished;
* :class:`halsdk.machine.runner.TaskRunner`, the task thread of
  ``halsdk run``: commands come from the command channel, the snapshot of
  :meth:`TaskController.snapshot` goes to the status channel and
  :meth:`TaskController.take_messages` to the error channel.

A ticket is finished as the reference's task finishes the command (its
``wait_complete`` returns): at once for most commands, when the line's
moves are done for ``mdi``, when the program ended for ``auto`` RUN, when
the I/O controller answered for the E-stop reset.  A refused command (not
allowed in this state or mode) finishes with RCS_ERROR and the reason,
also posted on the error channel: the reference ignores many silently.
"""

from __future__ import annotations

import copy
import math
import os
from collections import deque
from collections.abc import Iterator
from typing import Any, Callable, Optional

from halsdk.channels.constants import (
    AUTO_FORWARD,
    AUTO_PAUSE,
    AUTO_RESUME,
    AUTO_REVERSE,
    AUTO_RUN,
    AUTO_STEP,
    EXEC_DONE,
    EXEC_WAITING_FOR_DELAY,
    EXEC_WAITING_FOR_IO,
    EXEC_WAITING_FOR_MOTION,
    EXEC_WAITING_FOR_SYSTEM_CMD,
    JOG_CONTINUOUS,
    JOG_INCREMENT,
    JOG_STOP,
    KIND_NAMES,
    NML_DISPLAY,
    NML_ERROR,
    NML_TEXT,
    OPERATOR_DISPLAY,
    OPERATOR_ERROR,
    OPERATOR_TEXT,
    RCS_DONE,
    RCS_ERROR,
    RCS_EXEC,
    SPINDLE_CONSTANT,
    SPINDLE_DECREASE,
    SPINDLE_FORWARD,
    SPINDLE_INCREASE,
    SPINDLE_OFF,
    SPINDLE_REVERSE,
    TRAJ_MODE_COORD,
    TRAJ_MODE_FREE,
    TRAJ_MODE_TELEOP,
)
from halsdk.errors import HalError
from halsdk.gcode import GCodeError, Parameters, Program
from halsdk.gcode.cutter_radius import CutterComp
from halsdk.gcode.interp import Interpreter
from halsdk.gcode.program import MAX_IDLE_TIME, MAX_ITERATIONS
from halsdk.gcode.remap import configure as configure_remap
from halsdk.machine.executor import Executor
from halsdk.machine.iocontrol import IoControl
from halsdk.machine.snapshot import build_snapshot
from halsdk.machine.task import (
    InterpState,
    MachineError,
    Task,
    TaskMode,
    TaskState,
)
from halsdk.machine.tooltable import ToolTable
from halsdk.machine.usermcode import find_user_m, search_path

__all__ = ["TaskController", "Ticket", "RCS_DONE", "RCS_EXEC", "RCS_ERROR",
           "OPERATOR_ERROR", "OPERATOR_TEXT", "OPERATOR_DISPLAY",
           "NML_ERROR", "NML_TEXT", "NML_DISPLAY", "KIND_NAMES"]

Finished = Optional[Callable[[], bool]]


class Ticket:
    """One command in the task: its name, the client's serial number,
    its state (RCS_EXEC while it runs, then RCS_DONE or RCS_ERROR) and,
    for RCS_ERROR, the reason."""

    __slots__ = ("name", "serial", "state", "error", "owner", "_finished")

    def __init__(self, name: str, serial: int = 0, owner: Any = None):
        self.name = name
        self.serial = serial
        self.owner = owner              # the channel's peer, or None
        self.state = RCS_EXEC
        self.error: Optional[str] = None
        self._finished: Finished = None

    @property
    def done(self) -> bool:
        return self.state != RCS_EXEC

    def __repr__(self) -> str:
        return (f"Ticket({self.name!r}, serial={self.serial}, "
                f"state={self.state}, error={self.error!r})")


class _Job:
    """What the interpreter runs: an MDI line or a program."""

    def __init__(self, ticket: Optional[Ticket], source: str):
        self.ticket = ticket
        self.source = source
        self.error: Optional[str] = None


def subroutine_path(ini: Any) -> list[str]:
    """[RS274NGC]SUBROUTINE_PATH of ``ini``: its folders (``:`` between
    them), relative to the INI file's folder."""
    folder = os.path.dirname(os.path.abspath(ini.path))
    paths = ini.get("RS274NGC", "SUBROUTINE_PATH")
    return [os.path.join(folder, p.strip())
            for p in str(paths or "").split(":") if p.strip()]
def _ini_flag(ini: Any, key: str, default: bool) -> bool:
    """[RS274NGC]key as a 0/1 flag; ``default`` when absent."""
    text = ini.get("RS274NGC", key)
    if text is None or not str(text).strip():
        return default
    try:
        return float(str(text).split()[0]) != 0
    except ValueError:
        raise MachineError(f"{ini.where('RS274NGC', key)}: {key} "
                           f"'{text}' is not 0 or 1") from None


def _ini_limit(ini: Any, key: str, default: float, whole: bool) -> float:
    """The halsdk-specific [RS274NGC]key: a number above 0 (a whole one
    when ``whole``); ``default`` when the key is absent."""
    text = ini.get("RS274NGC", key)
    if text is None or not str(text).strip():
        return default
    try:
        value = float(str(text).split()[0])
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0) or \
            whole and not value.is_integer():
        what = "a whole number above 0" if whole else \
            "a number of seconds above 0"
        raise MachineError(f"{ini.where('RS274NGC', key)}: {key} "
                           f"'{text}' is not {what}")
    return value


class TaskController:
    """The task level of one machine (see the module docstring).

    :param hal: the :class:`halsdk.Hal` hosting the machine.
    :param motion: a connected :class:`halsdk.motion.Motion`.
    :param io: the :class:`IoControl`; when None one is created with
        ``tool_table`` and its poll added to ``thread``.
    :param units: the machine's length unit, "mm" or "inch".
    """

    def __init__(self, hal: Any, motion: Any, io: Optional[IoControl] = None,
                 *, tool_table: Optional[ToolTable] = None,
                 units: str = "mm", thread: str = "servo-thread") -> None:
        self.hal = hal
        self.motion = motion
        self.thread = thread
        if io is None:
            io = IoControl(tool_table or ToolTable())
            io.attach(hal, thread)
        self.io = io
        self.task = Task(motion, io)
        self.params = Parameters()
        #: [RS274NGC]SUBROUTINE_PATH: folders searched for o<name> call
        self.subroutine_path: list[str] = []
        #: [RS274NGC]PARAMETER_FILE: persistent parameters (var file)
        self.parameter_file: Optional[str] = None
        #: the bounds of runaway control flow of every program and MDI
        #: line run (halsdk-specific [RS274NGC]HALSDK_MAX_ITERATIONS and
        #: HALSDK_MAX_IDLE_TIME; see :class:`halsdk.gcode.Program`)
        self.max_iterations = MAX_ITERATIONS
        self.max_idle_time = MAX_IDLE_TIME
        #: the INI file of the machine (status ``ini_filename``)
        self.ini_filename = ""
        self.units = units
        self._messages: deque[tuple[int, str]] = deque(maxlen=1000)
        #: the folders searched for user M-codes M100-M199, first to last
        #: ([DISPLAY]PROGRAM_PREFIX and [RS274NGC]USER_M_PATH)
        self.user_m_path: list[str] = []
        #: whether programs read HAL items as #<_hal[name]>
        #: ([RS274NGC]HAL_PIN_VARS, on by default as in LinuxCNC 2.9)
        self.hal_pin_vars = True
        self.executor = Executor(motion, io, hal, thread=thread,
                                 message=self._canon_message,
                                 pause=self._m0)
        self.interp = self._new_interp()
        self.file = ""
        self._program: Optional[Program] = None
        self._blocks: Optional[Iterator[Any]] = None
        self._start_line = 0
        self._m0_paused = False
        self._job: Optional[_Job] = None
        self._running: Optional[Program] = None     # its call level
        self._mdi_queue: deque[tuple[str, Ticket]] = deque()
        self._inflight: list[Ticket] = []
        self._tool_state: tuple = ()
        #: bumped whenever the tool table changed (status channel)
        self.tool_generation = 0
        #: the serial and state of the latest command (status echo)
        self.echo_serial = 0
        self.echo_state = RCS_DONE
        #: task cycles run
        self.heartbeat = 0
        self.optional_stop = True
        self.block_delete = False
        self.debug = 0
        self.last_command = ""
        self.feed_scale = 1.0
        self.feed_override_enabled = True
        self.spindle_scale = [1.0] * 8
        self.spindle_override_enabled = [True] * 8
        self.max_velocity = 0.0
        #: X=1, Y=2, Z=4, A=8 ... of the axes in use ([TRAJ]COORDINATES)
        self.axis_mask = 7

    # -- set-up ------------------------------------------------------------

    def configure_from_ini(self, ini: Any) -> None:
        """[RS274NGC]SUBROUTINE_PATH and PARAMETER_FILE, relative to the
        INI file's folder; the parameters are read from the file.  The
        halsdk-specific [RS274NGC]HALSDK_MAX_ITERATIONS and
        HALSDK_MAX_IDLE_TIME set the bounds of runaway control flow."""
        self.ini_filename = os.path.abspath(ini.path)
        #: #<_ini[SECTION]KEY> of programs reads this file
        self.ini_lookup = ini.get
        self.interp.ini = ini.get
        coords = str(ini.get("TRAJ", "COORDINATES") or "").upper()
        letters = [c for c in coords if c in "XYZABCUVW"]
        if letters:
            self.axis_mask = sum(1 << "XYZABCUVW".index(c)
                                 for c in set(letters))
        folder = os.path.dirname(self.ini_filename)
        self.executor.folder = folder       # LOGOPEN/PROBEOPEN names
        self.subroutine_path = subroutine_path(ini) or self.subroutine_path
        self.max_iterations = int(_ini_limit(
            ini, "HALSDK_MAX_ITERATIONS", self.max_iterations, True))
        self.max_idle_time = _ini_limit(
            ini, "HALSDK_MAX_IDLE_TIME", self.max_idle_time, False)
        # REMAP= lines and the [PYTHON] plugin (halsdk.gcode.remap): kept
        # for the interpreters made after a reset
        try:
            # its warnings (a code with no modalgroup=) go to the
            # operator, as the reference's text messages
            self._remap = configure_remap(
                self.interp, ini, self.subroutine_path,
                lambda warning: self.post(OPERATOR_TEXT, str(warning)))
        except GCodeError as exc:
            raise MachineError(str(exc)) from None
        self.user_m_path = search_path(folder,
                                       ini.get("DISPLAY", "PROGRAM_PREFIX"),
                                       ini.get("RS274NGC", "USER_M_PATH"))
        self.user_m_timeout = _ini_limit(
            ini, "HALSDK_USER_M_TIMEOUT", self.user_m_timeout, False)
        self.hal_pin_vars = _ini_flag(ini, "HAL_PIN_VARS", True)
        name = ini.get("RS274NGC", "PARAMETER_FILE")
        if name:
            self.parameter_file = os.path.join(folder, name)
            if os.path.exists(self.parameter_file):
                self.params.load(self.parameter_file)

    def save_parameters(self) -> None:
        """Write the persistent parameters to [RS274NGC]PARAMETER_FILE
        (atomically), as LinuxCNC does when it exits."""
        if self.parameter_file:
            self.params.save(self.parameter_file)

    def _new_interp(self) -> Interpreter:
        tools = copy.deepcopy(self.io.table)
        tools.path = None           # the I/O controller's copy is saved
        interp = Interpreter(self.params, tools, self.executor,
                             random_toolchanger=self.io.table.random,
                             units=self.units,
                             ini=getattr(self, "ini_lookup", None))
        interp.pos = list(self.executor.pos)
        interp.task = True              # #<_task>: the machine's interpreter
        interp.remap = getattr(self, "_remap", None)
        interp.user_m = self._user_m
        interp.hal_value = self._hal_value
        self.executor.interp = interp
        return interp

    @property
    def user_m_timeout(self) -> float:
        """Seconds a user M-code may run before it is killed and the
        program aborted ([RS274NGC]HALSDK_USER_M_TIMEOUT)."""
        return self.executor.user_m_timeout

    @user_m_timeout.setter
    def user_m_timeout(self, seconds: float) -> None:
        if not (math.isfinite(seconds) and seconds > 0):
            raise ValueError(f"user_m_timeout must be above 0, not "
                             f"{seconds!r}")
        self.executor.user_m_timeout = float(seconds)

    def _user_m(self, number: int) -> Optional[str]:
        """The executable of M<number> on the M-code search path."""
        return find_user_m(number, self.user_m_path)

    def _hal_value(self, name: str) -> Optional[float]:
        """``#<_hal[name]>``: the value of the pin, param or signal of
        that name now, None when there is none (or the feature is off)."""
        if not self.hal_pin_vars:
            return None
        for kind in ("pin", "param", "signal"):
            item = self.hal.find(kind, name)
            if item is not None:
                return float(item.value)
        return None

    # -- the error channel ---------------------------------------------------

    def post(self, kind: int, text: str) -> None:
        """Queue a message for the error channel."""
        self._messages.append((kind, text))

    def _canon_message(self, kind: str, text: str) -> None:
        self.post(OPERATOR_DISPLAY if kind == "display" else OPERATOR_TEXT
                  if kind == "text" else OPERATOR_ERROR, text)

    def take_messages(self) -> list[tuple[int, str]]:
        """The messages since the last call, oldest first, as
        ``(kind, text)`` with the reference's kind numbers."""
        self._collect()
        out = list(self._messages)
        self._messages.clear()
        return out

    def _collect(self) -> None:
        for text in self.motion.errors():
            self.post(OPERATOR_ERROR, text)
            if self._job is not None and self._job.error is None:
                # motion dropped the job's moves (a move it refused, a
                # following error): the job fails, as in the reference
                self._job.error = text
        if self.io.error:
            self.post(OPERATOR_ERROR, self.io.error)
            self.io.error = None
        if self.task.sync():
            self._stop_program("the machine left ON (E-stop)")

    # -- commands --------------------------------------------------------

    def issue(self, name: str, args: Optional[dict] = None, *,
              serial: int = 0, owner: Any = None) -> Ticket:
        """Start command ``name`` with ``args`` (the names of
        :data:`halsdk.channels.cmdproto.COMMANDS`); never waits.  A refused
        command comes back finished with RCS_ERROR, its reason posted on
        the error channel."""
        ticket = Ticket(name, serial, owner)
        self.echo_serial, self.echo_state = serial, RCS_EXEC
        handler = getattr(self, "_cmd_" + name, None)
        try:
            if handler is None:
                raise MachineError(f"unknown command '{name}'")
            ticket._finished = handler(ticket, **(args or {}))
        except (MachineError, GCodeError) as e:
            self._fail(ticket, str(e))
            return ticket
        except HalError as e:
            self._fail(ticket, f"{name}: {e}")
            return ticket
        if ticket._finished is None:
            self._finish(ticket, RCS_DONE)
        else:
            self._inflight.append(ticket)
        return ticket

    def _fail(self, ticket: Ticket, text: str) -> None:
        ticket.error = text
        self.post(OPERATOR_ERROR, text)
        self._finish(ticket, RCS_ERROR)

    def _finish(self, ticket: Ticket, state: int) -> None:
        ticket.state = state
        if ticket.serial == self.echo_serial:
            self.echo_state = state
        if ticket in self._inflight:
            self._inflight.remove(ticket)

    def _check_tickets(self) -> None:
        for ticket in list(self._inflight):
            finished = ticket._finished
            try:
                if finished is not None and finished():
                    self._finish(ticket, RCS_DONE)
            except (MachineError, HalError) as e:
                if ticket.error is None:
                    self._fail(ticket, str(e))
                else:
                    self._finish(ticket, RCS_ERROR)

    # -- state and mode ----------------------------------------------------

    def _cmd_state(self, t: Ticket, state: int) -> Finished:
        try:
            target = TaskState(state)
        except ValueError:
            raise MachineError(f"state {state}: not a machine state (1 "
                               "E-stop, 2 E-stop reset, 3 off, 4 on)"
                               ) from None
        if target in (TaskState.ESTOP, TaskState.OFF):
            self._stop_program("aborted: the machine was turned off"
                               if target is TaskState.OFF else
                               "aborted: E-stop")
        wait = self.task.request_state(target)
        if target is TaskState.ON:
            self.executor.resync()
            self.interp.pos = list(self.executor.pos)
        return wait

    def _cmd_mode(self, t: Ticket, mode: int) -> Finished:
        try:
            self.task.set_mode(TaskMode(mode))
        except ValueError:
            raise MachineError(f"mode {mode}: not a mode (1 manual, 2 "
                               "auto, 3 MDI)") from None
        if self.task.mode is not TaskMode.MANUAL:
            self.executor.resync()
            self.interp.pos = list(self.executor.pos)
        return None

    # -- manual ----------------------------------------------------------

    def _joint(self, joint: int, what: str, allow_all: bool = True) -> int:
        n = self.motion.status().num_joints
        if joint == -1 and allow_all:
            return joint
        if not 0 <= joint < n:
            raise MachineError(f"{what}: joint {joint} does not exist "
                               f"(the machine has joints 0 to {n - 1})")
        return joint

    def _cmd_home(self, t: Ticket, joint: int = -1) -> Finished:
        self.task.require_mode(TaskMode.MANUAL, "home")
        self.task.require_idle("home")
        self.motion.home(self._joint(joint, "home"))
        return None

    def _cmd_unhome(self, t: Ticket, joint: int = -1) -> Finished:
        self.task.require_mode(TaskMode.MANUAL, "unhome")
        self.motion.unhome(self._joint(joint, "unhome"))
        return None

    def _cmd_jog(self, t: Ticket, action: int, joint_mode: bool = True,
                 index: int = 0, velocity: float = 0.0,
                 distance: float = 0.0) -> Finished:
        self.task.require_mode(TaskMode.MANUAL, "jog")
        teleop = not joint_mode
        if teleop:
            if not 0 <= index < 9:
                raise MachineError(f"jog: axis index {index} is not 0 to 8 "
                                   "(X Y Z A B C U V W)")
            target: Any = "xyzabcuvw"[index]
        else:
            target = self._joint(index, "jog", allow_all=False)
        if action == JOG_STOP:
            self.motion.jog_stop(target, teleop=teleop)
        elif action == JOG_CONTINUOUS:
            self.motion.jog_cont(target, velocity, teleop=teleop)
        elif action == JOG_INCREMENT:
            # the increment's sign gives the direction, as in the reference
            self.motion.jog_incr(target, abs(velocity),
                                 distance if velocity >= 0 else -distance,
                                 teleop=teleop)
        else:
            raise MachineError(f"jog: action {action} is not JOG_STOP (0), "
                               "JOG_CONTINUOUS (1) or JOG_INCREMENT (2)")
        return None

    def _cmd_override_limits(self, t: Ticket) -> Finished:
        self.task.require_mode(TaskMode.MANUAL, "override limits")
        self.motion.override_limits(True)
        return None

    def _cmd_teleop_enable(self, t: Ticket, on: bool) -> Finished:
        self.task.require_on("teleop enable")
        if on:
            self.motion.teleop()
        else:
            self.motion.free()
        return None

    def _cmd_traj_mode(self, t: Ticket, mode: int) -> Finished:
        self.task.require_on("trajectory mode")
        if mode == TRAJ_MODE_FREE:
            self.motion.free()
        elif mode == TRAJ_MODE_COORD:
            self.motion.coord()
        elif mode == TRAJ_MODE_TELEOP:
            self.motion.teleop()
        else:
            raise MachineError(f"trajectory mode {mode}: not 1 (free), 2 "
                               "(coord) or 3 (teleop)")
        return None

    # -- MDI -------------------------------------------------------------

    def _cmd_mdi(self, t: Ticket, line: str) -> Finished:
        self.task.require_mode(TaskMode.MDI, "MDI")
        if len(line) > 254:
            raise MachineError("MDI: the line is longer than 254 "
                               "characters")
        if self.task.interp_state is InterpState.PAUSED:
            raise MachineError("MDI refused: the interpreter is PAUSED "
                               "(resume or abort first)")
        if self._job is not None or self._mdi_queue:
            self._mdi_queue.append((line, t))     # runs after the others
        else:
            self._start_mdi(line, t)

        def finished() -> bool:
            return t.done
        return finished

    def _start_mdi(self, line: str, t: Ticket) -> None:
        job = _Job(t, "<mdi>")
        program = Program(line, "<mdi>", self.params,
                          block_delete=self.block_delete,
                          max_iterations=self.max_iterations,
                          max_idle_time=self.max_idle_time)
        self._running = program
        self.interp.program = program     # M73: its call level
        self._start_job(job, program.blocks())
        self.last_command = line

    def _start_job(self, job: _Job, blocks: Iterator[Any],
                   start_line: int = 0) -> None:
        self._job = job
        self._blocks = blocks
        self._start_line = start_line
        self.interp.ended = False
        self.executor.ended = False
        self.executor.resync()
        self.interp.pos = list(self.executor.pos)
        self.task.interp_state = InterpState.READING

    def _end_job(self, error: Optional[str] = None) -> None:
        job, self._job = self._job, None
        if job is None:
            return
        if error is None:
            error = job.error
        if job.ticket is not None and not job.ticket.done:
            if error is None:
                self._finish(job.ticket, RCS_DONE)
            else:
                job.ticket.error = error
                self._finish(job.ticket, RCS_ERROR)

    # -- programs --------------------------------------------------------

    def _cmd_program_open(self, t: Ticket, path: str) -> Finished:
        self.task.require_idle("program open")
        try:
            self._program = Program.from_file(path, self.params,
                                              self.subroutine_path)
        except OSError as e:
            raise MachineError(f"program open: {path}: {e.strerror}"
                               ) from None
        self.file = os.path.abspath(path)
        self._blocks = None
        return None

    def _cmd_auto(self, t: Ticket, action: int, line: int = 0) -> Finished:
        if action == AUTO_RUN:
            return self._run(t, line)
        if action == AUTO_PAUSE:
            self._pause()
        elif action == AUTO_RESUME:
            self._resume()
        elif action == AUTO_STEP:
            self._step()
        elif action in (AUTO_REVERSE, AUTO_FORWARD):
            raise MachineError("auto: reverse run is not supported")
        else:
            raise MachineError(f"auto: action {action} is not AUTO_RUN (0),"
                               " AUTO_PAUSE (1), AUTO_RESUME (2) or "
                               "AUTO_STEP (3)")
        return None

    def _run(self, t: Ticket, start_line: int) -> Finished:
        self.task.require_mode(TaskMode.AUTO, "program run")
        self.task.require_idle("program run")
        if self._program is None:
            raise MachineError("program run refused: no program open")
        # read again: a run starts from the file as it is now
        try:
            program = Program.from_file(self.file, self.params,
                                        self.subroutine_path,
                                        block_delete=self.block_delete,
                                        max_iterations=self.max_iterations,
                                        max_idle_time=self.max_idle_time)
        except OSError as e:
            raise MachineError(f"program run: {self.file}: {e.strerror}"
                               ) from None
        self._running = program
        self.interp.program = program     # M73: its call level
        self._start_job(_Job(t, self.file), program.blocks(), start_line)

        def finished() -> bool:
            return t.done
        return finished

    def _m0(self) -> None:
        self._m0_paused = True
        self.task.interp_state = InterpState.PAUSED

    def _pause(self) -> None:
        if self.task.interp_state is InterpState.IDLE:
            raise MachineError("pause refused: nothing runs")
        self.motion.pause()
        self.task.interp_state = InterpState.PAUSED

    def _resume(self) -> None:
        if self.task.interp_state is not InterpState.PAUSED:
            raise MachineError("resume refused: not paused")
        self._m0_paused = False
        self.motion.resume()
        self.task.interp_state = (InterpState.READING if self._blocks
                                  else InterpState.WAITING if self._job
                                  else InterpState.IDLE)

    def _step(self) -> None:
        if self.task.interp_state is not InterpState.PAUSED:
            raise MachineError("step refused: pause first")
        if self.motion.status().paused:
            self.motion.step()
            return
        if self._blocks is not None:
            self._m0_paused = False
            self.task.interp_state = InterpState.READING
            self._advance()             # one block
            if self.task.interp_state is InterpState.READING:
                self._m0_paused = True
                self.task.interp_state = InterpState.PAUSED

    def _cmd_abort(self, t: Ticket) -> Finished:
        self._stop_program("aborted")
        self._mdi_queue_fail("aborted")
        if self.task.state is TaskState.ON:
            try:
                self.motion.spindle_off()
            except HalError:
                pass
            self.io.mist(False)
            self.io.flood(False)
        return None

    def _mdi_queue_fail(self, why: str) -> None:
        while self._mdi_queue:
            _line, ticket = self._mdi_queue.popleft()
            ticket.error = why
            self._finish(ticket, RCS_ERROR)

    def _stop_program(self, why: str = "aborted") -> None:
        self._blocks = None
        self._m0_paused = False
        try:
            self.motion.abort()
        except HalError:
            pass
        self.io.abort()
        self.executor.clear()
        self.interp.comp = CutterComp(self.executor.emit)
        self.task.interp_state = InterpState.IDLE
        self.executor.resync()
        self.interp.pos = list(self.executor.pos)
        self._end_job(why)
        if why != "aborted":
            self._mdi_queue_fail(why)

    def _guard(self, fn: Callable[[], Any]) -> Any:
        """Run fn; on an error stop the machine's moves, turn it off
        (motion disabled), report it and raise it as MachineError."""
        try:
            return fn()
        except GCodeError as e:
            text = str(e)
        except HalError as e:
            source = self._job.source if self._job else "<mdi>"
            text = f"{source}:{self.interp.line}: {e}"
        self.post(OPERATOR_ERROR, text)
        self._stop_program(text)
        # bad input leaves the machine safe: motion off until turned on
        if self.task.state is TaskState.ON:
            self.task.set_state(TaskState.OFF)
        raise MachineError(text)

    def _advance(self) -> bool:
        """Carry out pending commands and execute one block if the
        program may go on; False when it cannot now (paused, waiting for
        motion or the I/O controller, queue full, ended)."""
        if self._blocks is None:
            return False
        if self.task.interp_state not in (InterpState.READING,
                                          InterpState.PAUSED):
            return False
        # commands of blocks already read go on even while paused
        if not self._guard(self.executor.pump):
            return False
        if self._job is not None and self._job.error is not None:
            self._stop_program(self._job.error)     # motion failed it
            return False
        if self._m0_paused or \
                self.task.interp_state is not InterpState.READING:
            return False
        if self.interp.ended:
            self._finish_reading()
            return False
        if self.motion.queue_free() < 2:
            return False
        blocks = self._blocks
        block = self._guard(lambda: next(blocks, None))
        if block is None:
            self._finish_reading()
            return False
        if block.line < self._start_line:
            return True
        self._guard(lambda: self.interp.execute(block))
        return True

    def _guarded_advance(self) -> Optional[str]:
        try:
            while self._advance():
                pass
        except MachineError as e:
            return str(e)
        return None

    def _finish_reading(self) -> None:
        self._blocks = None
        self._guard(self.interp.comp.stop)
        self.task.interp_state = InterpState.WAITING

    # -- the cycle -------------------------------------------------------

    def cycle(self) -> Optional[str]:
        """One task cycle: collect messages, advance the interpreter and
        the canon queue as far as motion allows, notice the end of a job,
        start a queued MDI line, finish the tickets whose work is done.
        Returns the text of an error that stopped a job in this cycle."""
        self.heartbeat += 1
        self._collect()
        error = self._guarded_advance()
        if error is None and self.task.interp_state is InterpState.WAITING:
            try:
                if self._guard(lambda: self.executor.pump()
                               and self.executor.at_rest()):
                    self.task.interp_state = InterpState.IDLE
                    self._end_job()
            except MachineError as e:
                error = str(e)
        if self._job is not None and \
                self.task.interp_state is InterpState.IDLE:
            self._end_job()
        if self._job is None and self._mdi_queue and \
                self.task.interp_state is InterpState.IDLE:
            line, ticket = self._mdi_queue.popleft()
            if self.task.mode is TaskMode.MDI and \
                    self.task.state is TaskState.ON:
                self._start_mdi(line, ticket)
            else:
                self._fail(ticket, "MDI refused: the machine left MDI mode "
                           "or was turned off")
        self._check_tickets()
        return error

    # -- overrides and settings ------------------------------------------

    def _cmd_feedrate(self, t: Ticket, scale: float) -> Finished:
        if not scale >= 0:
            raise MachineError(f"feedrate: {scale} is not a scale >= 0")
        self.feed_scale = scale
        if self.feed_override_enabled:
            self.motion.set_feed_scale(scale)
        return None

    def _cmd_rapidrate(self, t: Ticket, scale: float) -> Finished:
        if not 0 <= scale <= 1:
            raise MachineError(f"rapidrate: {scale} is not a scale from 0 "
                               "to 1")
        self.motion.set_rapid_scale(scale)
        return None

    def _cmd_maxvel(self, t: Ticket, velocity: float) -> Finished:
        if not velocity > 0:
            raise MachineError(f"maxvel: {velocity} is not a velocity > 0")
        self.motion.set_vel_limit(velocity)
        self.max_velocity = velocity
        return None

    def _spindle_index(self, spindle: int, what: str) -> int:
        n = max(self.motion.status().num_spindles, 1)
        if not 0 <= spindle < n:
            raise MachineError(f"{what}: spindle {spindle} does not exist "
                               f"(the machine has {n})")
        return spindle

    def _cmd_spindleoverride(self, t: Ticket, scale: float,
                             spindle: int = 0) -> Finished:
        self._spindle_index(spindle, "spindle override")
        if not scale >= 0:
            raise MachineError(f"spindle override: {scale} is not a scale "
                               ">= 0")
        self.spindle_scale[spindle] = scale
        self._apply_spindle_scale(spindle)
        return None

    def _apply_spindle_scale(self, spindle: int) -> None:
        scale = self.spindle_scale[spindle] \
            if self.spindle_override_enabled[spindle] else 1.0
        self.executor.spindle_scale = scale if spindle == 0 else \
            self.executor.spindle_scale
        st = self.motion.status()
        if st.spindles and spindle < len(st.spindles) and \
                st.spindles[spindle].on and spindle == 0 and \
                self.executor.spindle_dir:
            self.motion.spindle_on(self.executor.spindle_dir *
                                   self.executor.speed * scale, spindle)

    def _cmd_spindle(self, t: Ticket, direction: int, speed: float = 0.0,
                     spindle: int = 0, wait_for_speed: bool = False
                     ) -> Finished:
        self.task.require_on("spindle")
        self._spindle_index(spindle, "spindle")
        st = self.motion.status()
        current = st.spindles[spindle].speed if st.spindles else 0.0
        if direction == SPINDLE_OFF:
            if spindle == 0:
                self.executor.spindle_dir = 0
            self.motion.spindle_off(spindle)
        elif direction in (SPINDLE_FORWARD, SPINDLE_REVERSE):
            if spindle == 0:
                self.executor.spindle_dir = direction
                self.executor.speed = abs(speed)
            scale = self.spindle_scale[spindle] \
                if self.spindle_override_enabled[spindle] else 1.0
            self.motion.spindle_on(direction * abs(speed) * scale, spindle)
        elif direction in (SPINDLE_INCREASE, SPINDLE_DECREASE):
            if current == 0:
                raise MachineError("spindle increase/decrease refused: the "
                                   "spindle is off")
            step = 100.0 if direction == SPINDLE_INCREASE else -100.0
            mag = max(abs(current) + step, 0.0)
            self.motion.spindle_on(mag if current > 0 else -mag, spindle)
        elif direction == SPINDLE_CONSTANT:
            pass
        else:
            raise MachineError(f"spindle: direction {direction} is not "
                               "SPINDLE_FORWARD, SPINDLE_REVERSE, "
                               "SPINDLE_OFF, SPINDLE_INCREASE, "
                               "SPINDLE_DECREASE or SPINDLE_CONSTANT")
        return None

    def _cmd_brake(self, t: Ticket, engage: bool, spindle: int = 0
                   ) -> Finished:
        self.motion.spindle_brake(engage, spindle)
        return None

    def _cmd_flood(self, t: Ticket, on: bool) -> Finished:
        self.task.require_on("flood")
        self.io.flood(bool(on))
        return None

    def _cmd_mist(self, t: Ticket, on: bool) -> Finished:
        self.task.require_on("mist")
        self.io.mist(bool(on))
        return None

    def _cmd_lube(self, t: Ticket, on: bool) -> Finished:
        self.task.require_on("lube")
        self.io.lube(bool(on))
        return None

    def _cmd_set_digital_output(self, t: Ticket, index: int, value: bool
                                ) -> Finished:
        self.motion.set_dout(index, bool(value))
        return None

    def _cmd_set_analog_output(self, t: Ticket, index: int, value: float
                               ) -> Finished:
        self.motion.set_aout(index, float(value))
        return None

    def _cmd_set_optional_stop(self, t: Ticket, on: bool) -> Finished:
        self.optional_stop = self.executor.optional_stop = bool(on)
        return None

    def _cmd_set_block_delete(self, t: Ticket, on: bool) -> Finished:
        self.block_delete = bool(on)
        return None

    def _cmd_set_feed_override(self, t: Ticket, on: bool) -> Finished:
        # M48/M49 from a client: while disabled the feed scale is 1
        self.feed_override_enabled = bool(on)
        self.motion.set_feed_scale(self.feed_scale if on else 1.0)
        return None

    def _cmd_set_spindle_override(self, t: Ticket, on: bool,
                                  spindle: int = 0) -> Finished:
        self._spindle_index(spindle, "spindle override")
        self.spindle_override_enabled[spindle] = bool(on)
        self._apply_spindle_scale(spindle)
        return None

    def _cmd_set_feed_hold(self, t: Ticket, on: bool) -> Finished:
        self.motion.set_feed_hold_enable(bool(on))
        return None

    def _cmd_set_adaptive_feed(self, t: Ticket, on: bool) -> Finished:
        self.motion.set_adaptive_feed_enable(bool(on))
        return None

    def _cmd_set_max_limit(self, t: Ticket, axis: int, limit: float
                           ) -> Finished:
        self._axis_limit(axis, None, limit)
        return None

    def _cmd_set_min_limit(self, t: Ticket, axis: int, limit: float
                           ) -> Finished:
        self._axis_limit(axis, limit, None)
        return None

    def _axis_limit(self, axis: int, low: Optional[float],
                    high: Optional[float]) -> None:
        if not 0 <= axis < 9:
            raise MachineError(f"axis limit: axis index {axis} is not 0 to "
                               "8 (X Y Z A B C U V W)")
        a = self.motion.status().axes[axis]
        self.motion.set_axis_limits(
            axis, a.min_pos_limit if low is None else low,
            a.max_pos_limit if high is None else high)

    def _cmd_debug(self, t: Ticket, level: int) -> Finished:
        self.debug = int(level)
        return None

    # -- messages ----------------------------------------------------------

    def _cmd_text_msg(self, t: Ticket, text: str) -> Finished:
        self.post(OPERATOR_TEXT, text)
        return None

    def _cmd_error_msg(self, t: Ticket, text: str) -> Finished:
        self.post(OPERATOR_ERROR, text)
        return None

    def _cmd_display_msg(self, t: Ticket, text: str) -> Finished:
        self.post(OPERATOR_DISPLAY, text)
        return None

    # -- tool table and interpreter ----------------------------------------

    def _cmd_tool_offset(self, t: Ticket, tool: int, z: float = 0.0,
                         x: float = 0.0, diameter: float = 0.0,
                         frontangle: float = 0.0, backangle: float = 0.0,
                         orientation: int = 0) -> Finished:
        pocket = self.io.table.pocket_of(tool)
        if pocket is None:
            raise MachineError(f"tool offset: tool {tool} is not in the "
                               "tool table")
        offset = list(self.io.table.entry(pocket).offset)
        offset[0], offset[2] = x, z
        self.set_tool_offsets(tool, offset=tuple(offset), diameter=diameter,
                              frontangle=frontangle, backangle=backangle,
                              orientation=orientation)
        return None

    def set_tool_offsets(self, tool: int, **data: Any) -> None:
        """Change tool data (see :meth:`ToolTable.set_offsets`); the table
        file is saved."""
        self.task.require_idle("tool table edit")
        self.io.set_offsets(tool, **data)
        self.interp.tools.set_offsets(tool, **data)

    def _cmd_load_tool_table(self, t: Ticket) -> Finished:
        self.load_tool_table()
        return None

    def load_tool_table(self, path: Optional[str] = None) -> None:
        """Re-read the tool table file."""
        self.task.require_idle("tool table load")
        path = path or self.io.table.path
        if not path:
            raise MachineError("load tool table: no file")
        new = ToolTable.load(path, random=self.io.table.random)
        self.io.table = new
        tools = copy.deepcopy(new)
        tools.path = None
        self.interp.tools = tools

    def _cmd_reset_interpreter(self, t: Ticket) -> Finished:
        self.task.require_idle("interpreter reset")
        self.executor.clear()
        self.interp = self._new_interp()
        return None

    def _cmd_task_plan_sync(self, t: Ticket) -> Finished:
        self.save_parameters()
        return None

    _cmd_task_plan_synch = _cmd_task_plan_sync

    # -- status ----------------------------------------------------------

    def tool_table_changed(self) -> bool:
        """True (and :attr:`tool_generation` bumped) when the tool table
        changed since the last call."""
        table = self.io.table
        state = (id(table), tuple(table.pockets()))
        if state != self._tool_state:
            self._tool_state = state
            self.tool_generation += 1
            return True
        return False

    def tool_entries(self) -> list[dict]:
        """The tool table in the reference's order: entry 0 the tool in
        the spindle (id -1 when none), then every pocket's tool."""
        out = []
        for pocket, e in self.io.table.pockets():
            if pocket and e.empty:
                continue
            d: dict[str, Any] = {
                # the reference: -1 for an empty spindle (tool 0 is none)
                "id": e.tool if not e.empty and (pocket or e.tool > 0)
                else -1,
                "diameter": e.diameter, "frontangle": e.frontangle,
                "backangle": e.backangle, "orientation": e.orientation,
                "pocket": e.pocket, "comment": e.comment}
            for letter, value in zip("xyzabcuvw", e.offset):
                d[letter + "offset"] = value
            out.append(d)
        return out

    def call_level(self) -> int:
        """Subroutine depth of the running program or MDI line."""
        if self._running is None or self._job is None:
            return 0
        return self._running.call_level

    def delay_left(self) -> float:
        """Seconds left of the dwell (G4) being carried out."""
        ex = self.executor
        if ex.pending and type(ex.pending[0]).__name__ == "Dwell" and \
                ex.phase == 1:
            st = self.motion.status()
            return max(0.0, (ex.until - st.heartbeat) * st.servo_period)
        return 0.0

    def exec_state(self) -> int:
        """The reference's EXEC_* number of what the task waits for."""
        if not self.executor.pending:
            return EXEC_DONE
        name = type(self.executor.pending[0]).__name__
        if name == "Dwell":
            return EXEC_WAITING_FOR_DELAY
        if name in ("ChangeTool", "SelectTool", "ChangeToolNumber"):
            return EXEC_WAITING_FOR_IO
        if name == "UserMCode" and self.executor.phase:
            return EXEC_WAITING_FOR_SYSTEM_CMD      # M100-M199 running
        return EXEC_WAITING_FOR_MOTION

    def snapshot(self) -> dict:
        """The status channel's fields (:mod:`halsdk.channels.statusfields`)
        as a dict."""
        return build_snapshot(self)
