"""Carrying out canonical commands on the machine.

:class:`Executor` is the :class:`~halsdk.gcode.canon.Canon` the machine
gives its interpreter.  The interpreter's commands are kept in order in
:attr:`Executor.pending`; :meth:`Executor.pump`, called every cycle by the
machine, carries them out.  Moves go into the motion queue at once, so the
interpreter runs ahead of motion; a command that needs the machine at rest
or gives a result to the interpreter (tool change, M61, probe, input wait,
spindle, coolant, dwell, pause, program end) waits until the queue has
drained, and everything after it waits behind it, as in the reference's
task.  The
machine reads no new block while commands are pending, so probe and input
results reach the parameters before the next line is evaluated.  Nothing
in here blocks: a waiting command is tried again at the next pump.
"""

from __future__ import annotations

import math
import os
from collections import deque
from typing import IO, Any, Callable, Optional

from halsdk.gcode import canon as C
from halsdk.machine.iocontrol import ToolState
from halsdk.machine.task import MachineError
from halsdk.machine.usermcode import DEFAULT_TIMEOUT, UserMError, UserMRun
from halsdk.motion.status import TermCond

__all__ = ["Executor", "ExecutorError"]


class ExecutorError(MachineError):
    """A canonical command the machine could not carry out."""


TERM = {"exact_path": TermCond.EXACT, "exact_stop": TermCond.STOP,
        "blend": TermCond.BLEND}
#: commands that wait for the move queue to drain
AT_REST = frozenset({"Probe", "Dwell", "Coolant", "ChangeTool",
                     "SpindleOn", "SpindleOff", "SpindleSpeed",
                     "ChangeToolNumber", "WaitInput", "ProgramPause",
                     "OptionalPause", "ProgramEnd", "UserMCode"})
#: plane -> (first, second, normal axis index)
PLANE_AXES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}


class Executor(C.Canon):
    """Runs canonical commands on ``motion`` and ``io``.

    ``message(kind, text)`` receives operator messages; ``pause()`` is
    called for M0 (and M1 when :attr:`optional_stop`).
    """

    def __init__(self, motion: Any, io: Any, hal: Any = None, *,
                 thread: str = "servo-thread",
                 message: Optional[Callable[[str, str], None]] = None,
                 pause: Optional[Callable[[], None]] = None) -> None:
        self.motion = motion
        self.io = io
        self.hal = hal
        self.thread = thread
        self.interp: Any = None
        self.message = message or (lambda kind, text: None)
        self.pause = pause or (lambda: None)
        self.optional_stop = True
        self.pos = list(motion.status().carte_pos_cmd)
        self.speed = 0.0
        self.spindle_dir = 0
        #: the spindle override of spindle 0 (1: none)
        self.spindle_scale = 1.0
        self.g5x_index = 1
        self.g5x_offset: tuple[float, ...] = (0.0,) * 9
        self.g92_offset: tuple[float, ...] = (0.0,) * 9
        self.tool_offset: tuple[float, ...] = (0.0,) * 9
        self.ended = False
        self.probes = 0
        #: commands emitted by the interpreter and not yet carried out
        self.pending: deque[C.Command] = deque()
        self._phase = 0
        self._until = 0
        self._last_bit = False
        #: seconds a user M-code (M100-M199) may run
        self.user_m_timeout = DEFAULT_TIMEOUT
        self._user_m: Optional[UserMRun] = None
        #: the folder relative LOGOPEN/PROBEOPEN names are in (the INI
        #: file's, as the reference's task runs there; '' the current one)
        self.folder = ""
        self._log: Optional[IO[str]] = None
        self._probe_log: Optional[IO[str]] = None
        self._last_record: Optional[tuple[float, ...]] = None

    # -- helpers -----------------------------------------------------------

    @property
    def phase(self) -> int:
        """0 before the first command waiting; 1 once it started."""
        return self._phase

    @property
    def until(self) -> int:
        """The motion heartbeat a dwell or an input wait ends at."""
        return self._until

    def resync(self) -> None:
        """Take the position from motion (after an abort or a jog)."""
        self.pos = list(self.motion.status_dict()["carte_pos_cmd"])

    def _rapid_vel(self) -> float:
        v = self.motion.status_dict()["vel_limit"]
        return v if v > 0 else 1e9

    def at_rest(self) -> bool:
        """The move queue is drained and nothing moves."""
        d = self.motion.status_dict()       # one snapshot per look
        if not d["enabled"]:
            raise ExecutorError("motion is disabled")
        return self.motion.moves_done(d)

    def _io_idle(self) -> bool:
        if self.io.tool_state is not ToolState.IDLE:
            return False
        if self.io.error:
            error, self.io.error = self.io.error, None
            raise ExecutorError(error)
        return True

    def clear(self) -> None:
        """Forget the pending commands (abort)."""
        self.pending.clear()
        self._phase = 0
        if self._user_m is not None:
            self._user_m.kill()
            self._user_m = None

    def _feed(self, feed: float, line: int) -> float:
        if not feed > 0:
            raise ExecutorError("feed move with feed rate 0 (no F word)")
        return feed / 60.0

    # -- dispatch ----------------------------------------------------------

    def emit(self, command: C.Command) -> None:
        self.pending.append(command)

    def pump(self) -> bool:
        """Carry out pending commands as far as possible now; True when
        none is left."""
        while self.pending:
            command = self.pending[0]
            name = type(command).__name__
            if name in AT_REST and self._phase == 0 and not self.at_rest():
                return False
            handler = getattr(self, "_do_" + name, None)
            if handler is not None and handler(command) is False:
                return False
            self.pending.popleft()
            self._phase = 0
        return True

    def _do_StraightTraverse(self, c: C.StraightTraverse) -> None:
        self.motion.queue_line(c.end, self._rapid_vel(), rapid=True,
                               line=c.line)
        self.pos = list(c.end)

    def _do_StraightFeed(self, c: C.StraightFeed) -> None:
        self.motion.queue_line(c.end, self._feed(c.feed, c.line),
                               line=c.line)
        self.pos = list(c.end)

    def _do_ArcFeed(self, c: C.ArcFeed) -> None:
        a, b, n = PLANE_AXES[c.plane]
        center = list(self.pos[:3])
        center[a], center[b] = c.center
        normal = [0.0, 0.0, 0.0]
        normal[n] = 1.0 if c.turn > 0 else -1.0
        self.motion.queue_circle(c.end, center, normal,
                                 self._feed(c.feed, c.line),
                                 turn=abs(c.turn) - 1, line=c.line)
        self.pos = list(c.end)

    def _do_SyncedFeed(self, c: C.SyncedFeed) -> None:
        self.motion.queue_thread(c.end, c.pitch, line=c.line)
        self.pos = list(c.end)

    def _do_Probe(self, c: C.Probe) -> bool:
        error = c.kind in ("38.2", "38.4")
        if self._phase == 0:
            self.motion.clear_probe_flag()
            self.motion.queue_probe(c.end, self._feed(c.feed, c.line),
                                    away=c.kind in ("38.4", "38.5"),
                                    error_if_no_contact=error, line=c.line)
            self._phase = 1
            return False
        if not self.at_rest():
            return False
        st = self.motion.status()
        tripped = bool(st.probe_tripped)
        where = list(st.probed_pos) if tripped else list(st.carte_pos_cmd)
        if error and not tripped:
            raise ExecutorError(f"G{c.kind} move finished without "
                                "contact")
        self.pos = list(st.carte_pos_cmd)
        self.probes += 1
        if self.interp is not None:
            self.interp.probe_result(where, tripped)
            self._probe_record()
            # the interpreter continues from where the move stopped
            self.interp.pos = list(self.pos)
        return True

    def _do_Dwell(self, c: C.Dwell) -> bool:
        st = self.motion.status()
        if self._phase == 0:
            self._phase = 1
            self._until = st.heartbeat + round(
                c.seconds / (st.servo_period or 0.001))
        return st.heartbeat >= self._until

    def _do_SetTermCond(self, c: C.SetTermCond) -> None:
        self.motion.queue_term_cond(TERM[c.mode], c.p or 0.0, c.q or 0.0)

    def _do_SpindleSpeed(self, c: C.SpindleSpeed) -> None:
        self.speed = c.rpm
        if self.spindle_dir:
            self.motion.spindle_on(self.spindle_dir * c.rpm *
                                   self.spindle_scale)

    def _do_SpindleOn(self, c: C.SpindleOn) -> None:
        self.speed = c.rpm
        self.spindle_dir = c.direction
        self.motion.spindle_on(c.direction * c.rpm * self.spindle_scale)

    def _do_SpindleOff(self, c: C.SpindleOff) -> None:
        self.spindle_dir = 0
        self.motion.spindle_off()

    def _do_Coolant(self, c: C.Coolant) -> None:
        if c.kind == "off":
            self.io.mist(False)
            self.io.flood(False)
        elif c.kind == "mist":
            self.io.mist(True)
        else:
            self.io.flood(True)

    def _do_SelectTool(self, c: C.SelectTool) -> bool:
        if not self._io_idle():
            return False
        self.io.prepare(c.tool)
        return True

    def _do_ChangeTool(self, c: C.ChangeTool) -> bool:
        # phase 0: the prepare finished; phase 1: the change finished
        if not self._io_idle():
            return False
        if self._phase == 0:
            self.io.change()
            self._phase = 1
            return False
        return True

    def _do_ChangeToolNumber(self, c: C.ChangeToolNumber) -> bool:
        if not self._io_idle():
            return False
        self.io.set_tool_number(c.tool)
        return True

    def _do_SetToolTableEntry(self, c: C.SetToolTableEntry) -> None:
        self.io.set_offsets(c.tool, offset=tuple(c.offset),
                            diameter=c.diameter, frontangle=c.frontangle,
                            backangle=c.backangle,
                            orientation=c.orientation)

    def _do_UseToolLengthOffset(self, c: C.UseToolLengthOffset) -> None:
        self.tool_offset = tuple(c.offset)
        self.motion.set_tool_offset(c.offset)

    def _do_SetG5xOffset(self, c: C.SetG5xOffset) -> None:
        self.g5x_index, self.g5x_offset = c.index, tuple(c.offset)

    def _do_SetG92Offset(self, c: C.SetG92Offset) -> None:
        self.g92_offset = tuple(c.offset)

    def _do_SyncDout(self, c: C.SyncDout) -> None:
        self.motion.queue_dout(c.index, c.on)

    def _do_DoutNow(self, c: C.DoutNow) -> None:
        self.motion.set_dout(c.index, c.on)

    def _do_SyncAout(self, c: C.SyncAout) -> None:
        self.motion.queue_aout(c.index, c.value)

    def _do_AoutNow(self, c: C.AoutNow) -> None:
        self.motion.set_aout(c.index, c.value)

    def _do_WaitInput(self, c: C.WaitInput) -> bool:
        kind = "digital" if c.digital else "analog"
        if not c.digital or c.mode == 0:
            value = self.motion.wait_input(kind, c.index, 0)
            self._input_result(float(value))
            return True
        st = self.motion.status()
        if not 0 <= c.index < st.num_dio:
            raise ExecutorError(f"M66: digital input {c.index} does not "
                                f"exist (num_dio={st.num_dio})")
        bit = bool((st.din >> c.index) & 1)
        if self._phase == 0:
            self._phase = 1
            timeout = c.timeout if math.isfinite(c.timeout) else 1e9
            self._until = st.heartbeat + round(
                max(timeout, 0.0) / (st.servo_period or 0.001))
            self._last_bit = bit
            if c.mode in (3, 4):
                ok = bit == (c.mode == 3)
            else:
                ok = False
        else:
            prev, self._last_bit = self._last_bit, bit
            ok = {1: bit and not prev, 2: prev and not bit,
                  3: bit, 4: not bit}[c.mode]
        if ok:
            self._input_result(1.0 if bit else 0.0)
            return True
        if st.heartbeat >= self._until:
            self._input_result(-1.0)
            return True
        return False

    def _input_result(self, value: float) -> None:
        if self.interp is not None:
            self.interp.input_result(value)

    def _do_ProgramPause(self, c: C.ProgramPause) -> None:
        self.pause()

    def _do_OptionalPause(self, c: C.OptionalPause) -> None:
        if self.optional_stop:
            self.pause()

    def _do_ProgramEnd(self, c: C.ProgramEnd) -> None:
        self.spindle_dir = 0
        self.motion.spindle_off()
        self.io.mist(False)
        self.io.flood(False)
        self.ended = True

    def _do_UserMCode(self, c: C.UserMCode) -> bool:
        # phase 0: start it (motion at rest); then poll until it exits
        try:
            if self._phase == 0:
                self._user_m = UserMRun(c.code, c.path, c.p, c.q,
                                        self.user_m_timeout)
                self._phase = 1
            assert self._user_m is not None
            if not self._user_m.poll():
                return False
        except UserMError as e:
            self._user_m = None
            raise ExecutorError(str(e)) from None
        self._user_m = None
        return True

    def _do_Message(self, c: C.Message) -> None:
        self.message("display", c.text)

    # -- log files (LOGOPEN, LOG, PROBEOPEN ...) ----------------------------

    def _open(self, what: str, name: str, mode: str) -> IO[str]:
        path = os.path.join(self.folder, name)
        try:
            return open(path, mode, encoding="utf-8")
        except OSError as e:
            raise ExecutorError(f"{what}: cannot open '{name}' ({path}): "
                                f"{e.strerror}") from None

    @staticmethod
    def _write(what: str, file: IO[str], text: str) -> None:
        try:
            file.write(text)
            file.flush()
        except OSError as e:
            raise ExecutorError(f"{what}: cannot write to '{file.name}': "
                                f"{e.strerror}") from None

    def _do_LogOpen(self, c: C.LogOpen) -> None:
        what = "LOGAPPEND" if c.append else "LOGOPEN"
        self._close_log()
        self._log = self._open(what, c.path, "a" if c.append else "w")

    def _do_Log(self, c: C.Log) -> None:
        if self._log is not None:
            self._write("LOG", self._log, c.text + "\n")

    def _do_LogClose(self, c: C.LogClose) -> None:
        self._close_log()

    def _close_log(self) -> None:
        log, self._log = self._log, None
        if log is not None:
            log.close()

    def _do_ProbeOpen(self, c: C.ProbeOpen) -> None:
        self._close_probe_log()
        self._probe_log = self._open("PROBEOPEN", c.path, "w")

    def _do_ProbeClose(self, c: C.ProbeClose) -> None:
        self._close_probe_log()

    def _close_probe_log(self) -> None:
        log, self._probe_log = self._probe_log, None
        if log is not None:
            log.close()

    def _probe_record(self) -> None:
        """Where a probe move stopped (#5061..#5069: the program's
        coordinates and units) as a line of the PROBEOPEN file, unless
        it is the point written last (the reference's rule)."""
        if self._probe_log is None or self.interp is None:
            return
        params = self.interp.params
        point = tuple(float(params.get(5061 + i)) for i in range(9))
        if point == self._last_record:
            return
        self._last_record = point
        text = " ".join(f"{v:f}" for v in point)
        self._write("PROBEOPEN", self._probe_log, text + "\n")

    def shutdown(self) -> None:
        """The machine stops: end a running user M-code, close the
        LOGOPEN and PROBEOPEN files."""
        self.clear()
        self.close_files()

    def close_files(self) -> None:
        """Close the LOGOPEN and PROBEOPEN files (the machine stops)."""
        self._close_log()
        self._close_probe_log()
