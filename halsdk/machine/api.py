"""The Python control API of a machine: :class:`Machine`.

Shaped after the reference ``linuxcnc`` module: the command methods
(``state``, ``mode``, ``home``, ``jog``, ``mdi``, ``program_open`` ...)
play ``linuxcnc.command``, :meth:`Machine.status` ``linuxcnc.stat`` and
:meth:`Machine.errors` ``linuxcnc.error_channel``.  When the machine's
threads are not running in real time every wait steps the servo thread,
so a whole session is deterministic.
"""

from __future__ import annotations

import copy
import os
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Optional

from halsdk.errors import HalError
from halsdk.gcode import GCodeError, Parameters, Program
from halsdk.gcode.cutter_radius import CutterComp
from halsdk.gcode.interp import Interpreter
from halsdk.machine.executor import Executor
from halsdk.machine.iocontrol import IoControl
from halsdk.machine.task import InterpState, MachineError, Task, TaskMode, TaskState
from halsdk.machine.tooltable import ToolTable

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


class Machine:
    """Control of one machine.

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
        self.units = units
        self._errors: list[tuple[str, str]] = []
        self.executor = Executor(motion, io, hal, thread=thread,
                                 message=self._message, pause=self._m0)
        self.interp = self._new_interp()
        self.file = ""
        self._program: Optional[Program] = None
        self._blocks: Optional[Iterator[Any]] = None
        self._start_line = 0
        self._m0_paused = False
        self._source = "<mdi>"

    @classmethod
    def from_launcher(cls, launcher: Any, io: Optional[IoControl] = None,
                      thread: str = "servo-thread") -> Machine:
        """A machine for a started :class:`halsdk.machine.launcher.Launcher`:
        the tool table from [EMCIO]TOOL_TABLE (RANDOM_TOOLCHANGER),
        units from [TRAJ]LINEAR_UNITS."""
        ini = launcher.ini
        if launcher.motion is None:
            raise MachineError(f"{ini.path}: the HAL files load no motion "
                               "module (motmod)")
        if io is None and launcher.io is not None:
            io = launcher.io            # made before the HAL files ran
        if io is None:
            name = ini.get("EMCIO", "TOOL_TABLE")
            random = str(ini.get("EMCIO", "RANDOM_TOOLCHANGER") or "0"
                         ).strip() not in ("0", "")
            table = ToolTable(random=random)
            if name:
                path = name if os.path.isabs(name) else os.path.join(
                    os.path.dirname(os.path.abspath(ini.path)), name)
                table = ToolTable.load(path, random=random)
            io = IoControl(table)
            io.attach(launcher.hal, thread)
        units = str(ini.get("TRAJ", "LINEAR_UNITS") or "mm").strip().lower()
        units = "inch" if units in ("inch", "in", "imperial") else "mm"
        machine = cls(launcher.hal, launcher.motion, io, units=units,
                      thread=thread)
        folder = os.path.dirname(os.path.abspath(ini.path))
        paths = ini.get("RS274NGC", "SUBROUTINE_PATH")
        if paths:
            machine.subroutine_path = [
                os.path.join(folder, p.strip()) for p in paths.split(":")
                if p.strip()]
        name = ini.get("RS274NGC", "PARAMETER_FILE")
        if name:
            machine.parameter_file = os.path.join(folder, name)
            if os.path.exists(machine.parameter_file):
                machine.params.load(machine.parameter_file)
        return machine

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
                             units=self.units)
        interp.pos = list(self.executor.pos)
        self.executor.interp = interp
        return interp

    # -- the error channel ---------------------------------------------------

    def _message(self, kind: str, text: str) -> None:
        self._errors.append((kind, text))

    def errors(self) -> list[tuple[str, str]]:
        """Messages since the last call, oldest first, as ``(kind, text)``:
        kind "error" (motion, I/O controller, interpreter and machine
        errors) or "display" (G-code MSG comments)."""
        self._collect()
        out, self._errors = self._errors, []
        return out

    def _collect(self) -> None:
        for text in self.motion.errors():
            self._errors.append(("error", text))
        if self.io.error:
            self._errors.append(("error", self.io.error))
            self.io.error = None
        if self.task.sync():
            self._stop_program()

    # -- state and mode --------------------------------------------------

    def state(self, state: TaskState | int) -> None:
        """``command.state``: ESTOP, ESTOP_RESET, ON or OFF."""
        if TaskState(state) in (TaskState.ESTOP, TaskState.OFF):
            self._stop_program()
        self.task.set_state(state)
        if TaskState(state) is TaskState.ON:
            self.executor.resync()
            self.interp.pos = list(self.executor.pos)

    def mode(self, mode: TaskMode | int) -> None:
        """``command.mode``: MANUAL, AUTO or MDI (only while idle)."""
        self.task.set_mode(mode)
        if self.task.mode is not TaskMode.MANUAL:
            self.executor.resync()
            self.interp.pos = list(self.executor.pos)

    # -- manual ----------------------------------------------------------

    def home(self, joint: int = -1, wait: bool = True,
             timeout: Optional[float] = 120.0) -> None:
        """``command.home``: home ``joint`` (-1: all, in sequence); with
        ``wait``, until homed (``timeout`` seconds, simulated when
        stepping: a search across a long axis takes a while)."""
        self.task.require_mode(TaskMode.MANUAL, "home")
        self.motion.home(joint)
        if wait:
            self.motion.wait_homed(None if joint < 0 else [joint],
                                   timeout=timeout)

    def jog(self, joint: int, vel: float, distance: Optional[float] = None,
            *, wait: bool = True) -> None:
        """Jog ``joint`` at ``vel`` by ``distance`` (None: continuously
        until :meth:`jog_stop`): ``command.jog`` JOG_INCREMENT and
        JOG_CONTINUOUS."""
        self.task.require_mode(TaskMode.MANUAL, "jog")
        if distance is None:
            self.motion.jog_cont(joint, vel)
            return
        self.motion.jog_incr(joint, abs(vel), distance)
        if wait:
            self.motion.wait_inpos()

    def jog_stop(self, joint: int) -> None:
        self.task.require_mode(TaskMode.MANUAL, "jog stop")
        self.motion.jog_stop(joint)

    # -- MDI -------------------------------------------------------------

    def mdi(self, line: str, wait: bool = True) -> None:
        """``command.mdi``: run one line in MDI mode; with ``wait`` until
        its moves are done (the reference's ``wait_complete``)."""
        self.task.require_mode(TaskMode.MDI, "MDI")
        self.task.require_idle("MDI")
        self.task.interp_state = InterpState.READING
        self.interp.ended = False
        self._source = "<mdi>"
        try:
            self._guard(lambda: self._run_all(
                Program(line, "<mdi>", self.params).blocks()))
            if wait:
                self._guard(self.motion.wait_done)
        finally:
            self.task.interp_state = InterpState.IDLE

    def _run_all(self, blocks: Iterator[Any]) -> None:
        for block in blocks:
            self._pump_all()
            self.interp.execute(block)
            if self.interp.ended:
                break
        self._pump_all()

    def _pump_all(self) -> None:
        while not self.executor.pump():
            self._tick()

    def _tick(self) -> None:
        if self.motion.stepping:
            self.hal.step(1, thread=self.thread)
        else:
            time.sleep(0.001)

    def _guard(self, fn: Any) -> Any:
        """Run fn; on an error stop the machine's moves, turn it off
        (motion disabled), report it and raise it as MachineError."""
        try:
            return fn()
        except GCodeError as e:
            text = str(e)
        except HalError as e:
            text = f"{self._source}:{self.interp.line}: {e}"
        self._errors.append(("error", text))
        self._stop_program()
        # bad input leaves the machine safe: motion off until turned on
        if self.task.state is TaskState.ON:
            self.task.set_state(TaskState.OFF)
        raise MachineError(text)

    # -- programs --------------------------------------------------------

    def program_open(self, path: str) -> None:
        """``command.program_open``."""
        self.task.require_idle("program open")
        self._program = Program.from_file(path, self.params,
                                          self.subroutine_path)
        self.file = path
        self._blocks = None

    def program_run(self, start_line: int = 0, wait: bool = False,
                    timeout: float = 600.0) -> None:
        """``command.auto(AUTO_RUN, start_line)``: start the open program
        (lines before ``start_line`` are read but not executed).  The
        program advances in :meth:`update` / :meth:`run_for` /
        :meth:`wait_program` (with ``wait``: to its end)."""
        self.task.require_mode(TaskMode.AUTO, "program run")
        self.task.require_idle("program run")
        if self._program is None:
            raise MachineError("program run refused: no program open")
        # read again: a run starts from the file as it is now
        program = Program.from_file(self.file, self.params,
                                    self.subroutine_path)
        self._blocks = program.blocks()
        self._source = self.file
        self._start_line = start_line
        self.interp.ended = False
        self.executor.ended = False
        self.executor.resync()
        self.interp.pos = list(self.executor.pos)
        self.task.interp_state = InterpState.READING
        if wait:
            self.wait_program(timeout)

    def _m0(self) -> None:
        self._m0_paused = True
        self.task.interp_state = InterpState.PAUSED

    def pause(self) -> None:
        """``command.auto(AUTO_PAUSE)``: feed hold of the running moves."""
        if self.task.interp_state is InterpState.IDLE:
            raise MachineError("pause refused: nothing runs")
        self.motion.pause()
        self.task.interp_state = InterpState.PAUSED

    def resume(self) -> None:
        """``command.auto(AUTO_RESUME)``: continue after pause or M0/M1."""
        if self.task.interp_state is not InterpState.PAUSED:
            raise MachineError("resume refused: not paused")
        self._m0_paused = False
        self.motion.resume()
        self.task.interp_state = (InterpState.READING if self._blocks
                                  else InterpState.IDLE)

    def step(self) -> None:
        """``command.auto(AUTO_STEP)``: while paused, execute the next
        block (its moves run, then the program holds again); while motion
        is in feed hold, let it run one move (motion's step)."""
        if self.task.interp_state is not InterpState.PAUSED:
            raise MachineError("step refused: pause first")
        if self.motion.status().paused:
            self.motion.step()
            return
        if self._blocks is not None:
            self._m0_paused = False
            self.task.interp_state = InterpState.READING
            self._advance()
            if self.task.interp_state is InterpState.READING:
                self._m0_paused = True
                self.task.interp_state = InterpState.PAUSED

    def abort(self) -> None:
        """``command.abort``: stop moves, spindle, coolant and tool
        handshakes; the interpreter goes idle (the machine stays on)."""
        self._stop_program()
        if self.task.state is TaskState.ON:
            try:
                self.motion.spindle_off()
            except HalError:
                pass
            self.io.mist(False)
            self.io.flood(False)

    def _stop_program(self) -> None:
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
        if self._m0_paused or \
                self.task.interp_state is not InterpState.READING:
            return False
        if self.interp.ended:
            self._finish()
            return False
        if self.motion.queue_free() < 2:
            return False
        block = self._guard(lambda: next(self._blocks, None))
        if block is None:
            self._finish()
            return False
        if block.line < self._start_line:
            return True
        self._guard(lambda: self.interp.execute(block))
        return True

    def _finish(self) -> None:
        self._blocks = None
        self._guard(self.interp.comp.stop)
        self.task.interp_state = InterpState.WAITING

    def update(self) -> None:
        """One cycle: carry out what the interpreter asked as far as
        motion allows, step the servo thread once (when stepped), notice
        the end of the program."""
        self._collect()
        while self._advance():
            pass
        self._tick()
        if self.task.interp_state is InterpState.WAITING:
            if self._guard(self.executor.pump) and self.executor.at_rest():
                self.task.interp_state = InterpState.IDLE

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
                return
            if self._m0_paused:
                raise MachineError("the program paused (M0/M1): resume()")
            self.update()
        raise MachineError(f"the program did not end within {timeout:g} s")

    # -- overrides -------------------------------------------------------

    def feed_override(self, scale: float) -> None:
        """``command.feedrate``."""
        self.motion.set_feed_scale(scale)

    def rapid_override(self, scale: float) -> None:
        """``command.rapidrate``."""
        self.motion.set_rapid_scale(scale)

    # -- tool table ------------------------------------------------------

    def set_tool_offsets(self, tool: int, **data: Any) -> None:
        """``command.tool_offset``: change tool data (see
        :meth:`ToolTable.set_offsets`); the table file is saved."""
        self.task.require_idle("tool table edit")
        self.io.set_offsets(tool, **data)
        self.interp.tools.set_offsets(tool, **data)

    def load_tool_table(self, path: Optional[str] = None) -> None:
        """``command.load_tool_table``: re-read the tool table file."""
        self.task.require_idle("tool table load")
        path = path or self.io.table.path
        if not path:
            raise MachineError("load tool table: no file")
        new = ToolTable.load(path, random=self.io.table.random)
        self.io.table = new
        tools = copy.deepcopy(new)
        tools.path = None
        self.interp.tools = tools

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
