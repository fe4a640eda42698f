"""Running a program on a machine in simulated time, as fast as possible:
``halsdk run machine.ini --simulate --program part.ngc``.

The machine is started from its INI file with its threads stepped, not
running (nothing waits for the wall clock): the task steps the servo
thread by one task cycle (``[TASK]CYCLE_TIME``, default 10 ms) of servo
periods at a time, as ``halsdk run --stepped`` does, so the result is
the same on any machine and under any load.  The machine is reset, turned
on and homed (unless ``[TRAJ]NO_FORCE_HOMING`` is set), the program runs
to its end, and the result says:

- ``program_time``: seconds of machine time from the start of the program
  to the task cycle that saw it end and the machine at rest;
- ``max_following_error``: per joint, the largest ``|pos-cmd - pos-fb|``
  since the machine was turned on (motion's high mark: homing included);
- ``limit_hits``: hard and soft limits met (each also an error);
- ``errors``: every error message (motion, I/O, interpreter with file and
  line); any error or limit hit makes the exit status 1.

Speed: while the task only waits for motion to come to rest, the task
cycles in which it provably could not see that are run as one step of the
servo thread (:class:`SimMachine`): fewer Python cycles, the same servo
cycles and program time.  The simulation never changes the
machine's files (tool table, parameter file).
"""

from __future__ import annotations

import json
import math
import os
import re
import sys
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Optional, TextIO

from halsdk.atomicfile import write_atomic
from halsdk.errors import HalError
from halsdk.machine.api import Machine
from halsdk.machine.controller import KIND_NAMES
from halsdk.machine.executor import AT_REST
from halsdk.machine.task import InterpState, MachineError, TaskMode, TaskState

__all__ = ["SimMachine", "SimResult", "simulate", "main_simulate"]

@dataclass
class SimResult:
    """What ``halsdk run --simulate`` measured (also its JSON)."""
    ini: str
    program: str
    ok: bool = False
    program_time: float = 0.0           #: s of machine time
    homing_time: float = 0.0            #: s of machine time
    servo_period: float = 0.0           #: s
    task_cycle: float = 0.0             #: s
    servo_cycles: int = 0               #: of the whole simulation
    skipped_task_cycles: int = 0        #: stepped through (SimMachine)
    max_following_error: list[float] = field(default_factory=list)
    ferror_limit: list[float] = field(default_factory=list)  #: FERROR
    limit_hits: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    wall_time: float = 0.0              #: s, start to end (not exact)
    run_wall_time: float = 0.0          #: s, homing and program only
    speed: float = 0.0                  #: machine s per run wall s

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=2) + "\n"


#: what the messages of a limit hit say (motmod: a limit switch, a
#: move or jog beyond the soft limits; the interpreter)
LIMIT_WORDS = ("hard limit", "soft limit", "outside the axis limits",
               "outside the joint limits", "on limit switch")


def _is_limit(text: str) -> bool:
    t = text.lower()
    return any(w in t for w in LIMIT_WORDS)


class SimMachine(Machine):
    """A :class:`Machine` whose every cycle is one task cycle of
    ``steps`` servo periods (``[TASK]CYCLE_TIME``), and that skips the
    task cycles in which it provably only waits for motion to come to
    rest.

    That is the case when the interpreter has queued everything up to a
    command that needs the machine at rest (a tool change, the program
    end, ...) and nothing else is in flight.  The moves left take at least
    the straight distance from the commanded position to the end of the
    last queued move (less the tool offset, which motion may add) over
    the largest speed the axis limits allow, sqrt(sum of vmax^2) over X, Y
    and Z; motion cannot be at rest earlier.  The task sleeps through the
    whole task cycles of that time but the last, as one step of the servo
    thread, so it sees the machine at rest in the same task cycle as when
    it looks every cycle: the same servo cycles, the same program time,
    far fewer Python cycles.  Moves not yet taken by motmod (which may
    refuse them) and messages not yet collected keep it looking; an error
    that motmod meets within a skipped stretch (a following error, a
    limit switch) is seen at its end.
    """

    steps = 10                          #: servo cycles per task cycle
    cycles = 0                          #: servo cycles stepped
    skipped = 0                         #: task cycles skipped
    skipping = True

    def take_io_poll(self) -> None:
        """Poll the I/O controller once per task cycle, as ``halsdk run``
        does, rather than as a Python function in the servo thread
        (which would cost a call into Python every servo cycle)."""
        for function in self.hal.functions("iocontrol.0.poll"):
            for thread in self.hal.threads():
                if function.name in getattr(thread, "functions", ()):
                    self.hal.delf(function.name, thread.name)
        self._io_polled = True

    def cycle(self) -> Optional[str]:
        if getattr(self, "_io_polled", False):
            self.io.poll()
        return super().cycle()

    def _tick(self) -> None:
        k = self._skip() if self.skipping else 0
        n = self.steps * (1 + k)
        self.hal.step(n, thread=self.thread)
        self.cycles += n
        self.skipped += k

    def _skip(self) -> int:
        """Task cycles that can be skipped now (0: none)."""
        if self._m0_paused or self._mdi_queue:
            return 0
        program = getattr(self, "_program_ticket", None)
        if any(t is not program for t in self._inflight):
            return 0                    # a command waits for its end
        state = self.task.interp_state
        executor = self.executor
        if state is InterpState.READING:
            if not executor.pending:
                return 0                # the interpreter can go on
            first = type(executor.pending[0]).__name__
            if first not in AT_REST or executor._phase != 0:
                return 0                # a command in progress
        elif state is not InterpState.WAITING:
            return 0
        if self.motion.queue_pending() or self.motion.messages_waiting():
            return 0                    # a move motmod may still refuse
        d = self.motion.status_dict()
        if not d["enabled"] or d["homing"]:
            return 0
        vmax = math.sqrt(sum(a["vel_limit"] ** 2 for a in d["axes"][:3]))
        if not vmax > 0:
            return 0
        here, there = d["carte_pos_cmd"], executor.pos
        dist = math.sqrt(sum((there[i] - here[i]) ** 2 for i in range(3)))
        dist -= math.sqrt(sum(x * x for x in d["tool_offset"][:3]))
        cycle = self.steps * (d["servo_period"] or 0.001)
        return max(0, int(dist / vmax / cycle) - 1)


def _ini_float(ini: Any, section: str, key: str, default: float) -> float:
    text = ini.get(section, key)
    try:
        return float(str(text).split()[0]) if text else default
    except ValueError:
        return default


def _home_required(ini: Any) -> bool:
    text = str(ini.get("TRAJ", "NO_FORCE_HOMING") or "0").strip()
    return text in ("", "0")


def simulate(ini_path: str, program: str, *, timeout: float = 86400.0,
             strict: bool = False, skipping: bool = True,
             out: TextIO = sys.stdout, err: TextIO = sys.stderr
             ) -> SimResult:
    """Start the machine of ``ini_path`` stepped, home it (when the INI
    file requires homing), run ``program`` to its end; returns the
    :class:`SimResult`.  ``timeout``: seconds of machine time for the
    program (and again for homing).  ``strict``: problems of the INI
    file are errors.  ``skipping``: False looks every task cycle (the
    same result, slower: see :class:`SimMachine`).  Raises HalError when
    the machine cannot be started."""
    from halsdk.machine.launcher import Launcher
    from halsdk.machine.runner import _cycle_time

    result = SimResult(ini=os.path.abspath(ini_path),
                       program=os.path.abspath(program))
    if not os.access(program, os.R_OK):
        raise MachineError(f"{program}: cannot read the program")
    wall0 = time.perf_counter()
    launcher = Launcher(ini_path, out=out, err=err, strict=strict)
    launcher.start(realtime=False)
    try:
        if launcher.motion is None:
            raise MachineError(f"{ini_path}: the HAL files load no motion "
                               "module (motmod): nothing to simulate")
        ini = launcher.ini
        if launcher.io is not None:
            launcher.io.table.path = None   # never write the tool table
        hal, motion, io, units = launcher.controller_parts()
        machine = SimMachine(hal, motion, io, units=units)
        machine.configure_from_ini(ini)
        machine.parameter_file = None       # nor the parameter file
        machine.skipping = skipping
        machine.take_io_poll()
        period = machine.motion.status().servo_period or 0.001
        cycle = _cycle_time(ini)
        machine.steps = max(1, round(cycle / period))
        result.servo_period = period
        result.task_cycle = machine.steps * period
        joints = machine.motion.status_dict()["num_joints"]
        result.ferror_limit = [
            _ini_float(ini, f"JOINT_{n}", "FERROR", 1.0)
            for n in range(joints)]
        wall1 = time.perf_counter()
        _session(machine, result, ini, program, timeout)
        result.run_wall_time = time.perf_counter() - wall1
        d = machine.motion.status_dict()
        result.max_following_error = [
            j["ferror_high_mark"] for j in d["joints"][:joints]]
        for kind, text in machine.take_messages():
            _error(result, KIND_NAMES.get(kind, "error"), text)
        result.servo_cycles = machine.cycles
        result.skipped_task_cycles = machine.skipped
    finally:
        launcher.shutdown()
    result.wall_time = time.perf_counter() - wall0
    machine_time = result.homing_time + result.program_time
    if result.run_wall_time > 0:
        result.speed = machine_time / result.run_wall_time
    result.ok = not result.errors and not result.limit_hits
    return result


def _core(text: str) -> str:
    """A message without the ``file:line:`` the task puts before motion's
    own and without its ``; ...`` tail: one event, told twice."""
    return re.sub(r"^\S+:\d+(:\d+)?: ", "", text).split(";")[0]


def _error(result: SimResult, kind: str, text: str) -> None:
    if kind != "error" or text in result.errors:
        return
    result.errors.append(text)
    if not _is_limit(text):
        return
    for i, hit in enumerate(result.limit_hits):
        if _core(hit) == _core(text):       # the same hit, told twice:
            if _core(text) != text:         # keep the one with file:line
                result.limit_hits[i] = text
            return
    result.limit_hits.append(text)


def _session(machine: SimMachine, result: SimResult, ini: Any,
             program: str, timeout: float) -> None:
    """Reset, on, home, run; errors go into ``result``."""
    def drain() -> None:
        for kind, text in machine.errors():
            _error(result, kind, text)

    period = result.servo_period
    try:
        machine.state(TaskState.ESTOP_RESET)
        machine.state(TaskState.ON)
        if _home_required(ini):
            start = machine.cycles
            _home(machine, timeout)
            result.homing_time = (machine.cycles - start) * period
        drain()
        machine.mode(TaskMode.AUTO)
        machine.program_open(os.path.abspath(program))
        start = machine.cycles
        try:
            machine.program_run()
            limit = start + round(timeout / period)
            while machine.task.interp_state is not InterpState.IDLE:
                if machine._m0_paused:
                    machine.resume()    # M0/M1: nobody to press resume
                if machine.cycles >= limit:
                    raise MachineError(f"{program}: the program did not "
                                       f"end within {timeout:g} s of "
                                       "machine time")
                machine.update()
            ticket = getattr(machine, "_program_ticket", None)
            if ticket is not None:
                machine._raise(ticket)
        finally:                        # up to the end, or the error
            result.program_time = (machine.cycles - start) * period
    except HalError as e:
        drain()
        _error(result, "error", str(e))
    drain()


#: task cycles of homing between two full looks (errors, a homing that
#: stopped); in between only motion.is-all-homed is read
HOME_LOOK_EVERY = 50


def _home(machine: SimMachine, timeout: float) -> None:
    """Home every joint in sequence.  Each task cycle reads the pin
    ``motion.is-all-homed`` (a few microseconds), so homing ends to the
    task cycle as when the task looks every cycle; the full look (task
    cycle, errors, a homing that stopped) every
    :data:`HOME_LOOK_EVERY` task cycles and whenever motion posted a
    message."""
    from halsdk.motion.status import JOINT_HOMED
    ticket = machine.issue("home", {"joint": -1})
    machine._raise(ticket)
    motion, hal = machine.motion, machine.hal
    n = round(timeout / (machine.steps * (motion.status().servo_period
                                          or 0.001)))
    seen = False
    for i in range(max(1, n)):
        if i % HOME_LOOK_EVERY and not motion.messages_waiting():
            hal.step(machine.steps, thread=machine.thread)
            machine.cycles += machine.steps
            if hal.getp("motion.is-all-homed"):
                return
            continue
        machine.update()
        d = motion.status_dict()
        js = d["joints"][:d["num_joints"]]
        if all(j["flags"] & JOINT_HOMED for j in js):
            return
        if d["homing"]:
            seen = True
        elif seen or not d["enabled"]:
            raise MachineError("homing stopped before every joint was "
                               "homed")
    raise MachineError(f"homing did not end within {timeout:g} s of "
                       "machine time")


def print_result(r: SimResult, out: TextIO = sys.stdout) -> None:
    """The summary ``halsdk run --simulate`` prints."""
    print(f"simulated {r.program} on {r.ini}", file=out)
    print(f"  program time:   {r.program_time:.3f} s "
          f"(homing {r.homing_time:.3f} s; task cycle "
          f"{r.task_cycle * 1000:g} ms, servo period "
          f"{r.servo_period * 1e6:g} us)", file=out)
    for n, e in enumerate(r.max_following_error):
        limit = r.ferror_limit[n] if n < len(r.ferror_limit) else 0.0
        print(f"  max following error joint {n}: {e:.6f} "
              f"(FERROR {limit:g})", file=out)
    print(f"  limit hits:     {len(r.limit_hits) or 'none'}", file=out)
    for text in r.limit_hits:
        print(f"    {text}", file=out)
    print(f"  errors:         {len(r.errors) or 'none'}", file=out)
    for text in r.errors:
        print(f"    {text}", file=out)
    print(f"  wall time:      {r.wall_time:.2f} s (homing and program "
          f"{r.run_wall_time:.2f} s: {r.speed:.0f}x real time)", file=out)


def main_simulate(ini_path: str, program: str, json_path: Optional[str],
                  timeout: float, strict: bool = False) -> int:
    """``halsdk run INI --simulate --program FILE [--json OUT]``."""
    own = "HALSDK_INSTANCE" not in os.environ
    if own:                             # parallel CI jobs do not collide
        os.environ["HALSDK_INSTANCE"] = f"halsdk-sim-{os.getpid()}"
    try:
        path = program
        if not os.path.exists(path):
            beside = os.path.join(os.path.dirname(os.path.abspath(ini_path)),
                                  program)
            if os.path.exists(beside):
                path = beside
        try:
            result = simulate(ini_path, path, timeout=timeout,
                              strict=strict)
        except HalError as e:
            print(f"halsdk run: {e}", file=sys.stderr)
            return 1
        print_result(result)
        if json_path:
            try:
                write_atomic(json_path, result.to_json())
            except OSError as e:
                print(f"halsdk run: {json_path}: cannot write: {e.strerror}",
                      file=sys.stderr)
                return 1
        return 0 if result.ok else 1
    finally:
        if own:
            os.environ.pop("HALSDK_INSTANCE", None)
