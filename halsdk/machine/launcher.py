"""Starting a whole machine from its INI file: ``halsdk run machine.ini``.

What the launcher does, in order:

1. reads the INI file; a missing ``[HAL]HALFILE`` is an error naming the
   file; checks it for typing mistakes (:mod:`halsdk.machine.inicheck`:
   unknown keys of LinuxCNC's sections, repeated sections and keys,
   ``[KINS]JOINTS`` against the ``[JOINT_n]`` sections), each a warning
   on ``err``, or with ``strict`` an error before anything is started;
2. creates the HAL instance (this process is its host); when the INI file
   has an ``[EMCIO]`` section, makes the I/O controller ``iocontrol.0``
   (:class:`halsdk.machine.IoControl`, its tool table from
   ``[EMCIO]TOOL_TABLE`` and ``RANDOM_TOOLCHANGER``) first, so that the
   HAL files can wire its pins, as LinuxCNC starts ``io`` before them;
   then runs every
   ``[HAL]HALFILE`` (relative to the INI file's folder; two passes when
   ``[HAL]TWOPASS`` is set) and ``[HAL]HALCMD`` with ``[SECTION]KEY``
   substitution from the INI file; the first error (``file:line: ...``)
   stops the start;
3. when the HAL files loaded the motion module, checks that it has
   ``[KINS]JOINTS`` joints and that the HAL files wire no joint beyond
   them (a warning, or with ``strict`` an error that shuts down what was
   started), then configures it from the
   INI file (:meth:`halsdk.motion.Motion.configure_ini`: [KINS], [TRAJ],
   [JOINT_n], [AXIS_L]); the I/O controller runs in ``servo-thread``;
4. starts the realtime threads and runs ``[HAL]POSTGUI_HALFILE``;
5. when motion is loaded, hosts the task controller on a thread of its
   own (:class:`halsdk.machine.runner.TaskRunner`): other processes
   operate the machine through its command, status and error channels
   (``import linuxcnc``, :func:`halsdk.machine.connect`, ``halsdk ctl``);
   then runs until SIGINT (Ctrl-C) or SIGTERM, or for ``seconds``;
6. shuts down: the task stopped (clients are told), motion disabled,
   ``[HAL]SHUTDOWN`` run, threads stopped, ``loadusr`` programs still
   running ended (SIGTERM, then SIGKILL after 5 s), every module unloaded
   and the instance removed.

The HAL files run in the INI file's folder, as LinuxCNC runs them: a
relative path given to ``source`` or to a ``loadusr`` program (its
configuration file, say) is taken from there, and the programs start
there, whatever the current folder of ``halsdk run``.

Whatever fails on the way, the machine is left safe: motion is disabled
before anything else is torn down, and the instance is removed.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from typing import Any, Optional, TextIO

from halsdk.errors import HalError
from halsdk.ini import IniFile

#: seconds between two looks of Launcher.wait() at the stop flag
STOP_POLL = 0.05


class LaunchError(HalError):
    """The machine could not be started (the message says where)."""


def _path(ini: IniFile, name: str) -> str:
    if os.path.isabs(name):
        return name
    return os.path.join(os.path.dirname(os.path.abspath(ini.path)), name)


class Launcher:
    """One machine started from an INI file (see the module docstring)."""

    def __init__(self, ini_path: str, out: TextIO = sys.stdout,
                 err: TextIO = sys.stderr, strict: bool = False):
        try:
            self.ini = IniFile(ini_path)
        except OSError as e:
            raise LaunchError(f"{ini_path}: cannot read: {e.strerror}"
                              ) from None
        self.out, self.err = out, err
        #: problems of the INI file are errors (``halsdk run --strict``)
        self.strict = strict
        #: the problems found so far (warnings unless strict)
        self.problems: list[Any] = []
        self.hal: Any = None
        self.motion: Any = None
        self.io: Any = None             # the I/O controller, with [EMCIO]
        # a plain flag, not a threading.Event: stop() runs in a signal
        # handler on the thread that waits (see wait())
        self._stopping = False
        # HAL files run in the INI file's folder, as LinuxCNC does: relative
        # paths of sourced files and loadusr programs and their arguments
        self.workdir = os.path.dirname(os.path.abspath(self.ini.path))
        self._executors: list[Any] = []     # their loadusr programs

    # ------------------------------------------------------------ start

    def start(self, realtime: bool = True) -> None:
        """Steps 1 to 4; raises LaunchError (after shutting down what was
        started)."""
        import halsdk
        halfiles = self.ini.all("HAL", "HALFILE")
        if not halfiles:
            raise LaunchError(f"{self.ini.path}: [HAL]HALFILE is missing "
                              "(the HAL files of the machine)")
        for name in halfiles:
            path = _path(self.ini, name.split()[0])
            if not os.access(path, os.R_OK):
                raise LaunchError(f"{self.ini.where('HAL', 'HALFILE')}: "
                                  f"cannot read HAL file '{name}'")
        from halsdk.machine.inicheck import check_ini
        self._report(check_ini(self.ini))
        self.hal = halsdk.Hal(create=True)
        try:
            self._start_io()
            ex = self._executor()
            self._load(ex, halfiles)
            self._check_joints()
            self._configure_motion()
            if self.io is not None and self.motion is not None:
                self.io.attach(self.hal, "servo-thread")
            if realtime:
                note = self.hal.start()
                if note:
                    print(note, file=self.err)
            for name in self.ini.all("HAL", "POSTGUI_HALFILE"):
                self._source(ex, _path(self.ini, name))
        except BaseException:
            self.shutdown()
            raise

    def _executor(self, hal: Any = None) -> Any:
        from halsdk.halcmd.commands import CommandRunner
        ex = CommandRunner(hal or self.hal, ini=self.ini.path, register=False,
                      workdir=self.workdir)
        self._executors.append(ex)
        return ex

    def _start_io(self) -> None:
        if not self.ini.has_section("EMCIO"):
            return
        from halsdk.machine import IoControl, ToolTable
        random = str(self.ini.get("EMCIO", "RANDOM_TOOLCHANGER") or "0"
                     ).strip() not in ("0", "")
        name = self.ini.get("EMCIO", "TOOL_TABLE")
        if name:
            table = ToolTable.load(_path(self.ini, name), random=random)
        else:
            table = ToolTable(random=random)
        self.io = IoControl(table)

    def _load(self, ex: Any, halfiles: list[str]) -> None:
        if any(self.ini.all("HAL", "TWOPASS")):
            from halsdk.halcmd import twopass
            if twopass.run(ex, self.ini.path):
                raise LaunchError(f"{self.ini.path}: loading the HAL files "
                                  "(twopass) failed")
        else:
            for name in halfiles:
                self._source(ex, _path(self.ini, name.split()[0]))
        for command in self.ini.all("HAL", "HALCMD"):
            if ex.run_lines([command], self.ini.path):
                raise LaunchError(f"{self.ini.where('HAL', 'HALCMD')}: "
                                  f"[HAL]HALCMD '{command}' failed")

    def _source(self, ex: Any, path: str) -> None:
        before = ex.errors
        ex.run_file(path)
        if ex.errors != before:
            raise LaunchError(f"{path}: the HAL file failed (see the "
                              "message above)")

    def _report(self, problems: list[Any]) -> None:
        """Warnings on ``err``; with ``strict`` a LaunchError that lists
        them."""
        if not problems:
            return
        self.problems.extend(problems)
        if self.strict:
            n = len(problems)
            raise LaunchError(
                f"{self.ini.path}: {n} problem{'s' if n > 1 else ''} in the "
                "INI file (--strict: the machine is not started):\n" +
                "\n".join(f"  {p}" for p in problems))
        for p in problems:
            print(f"warning: {p}", file=self.err, flush=True)

    def _check_joints(self) -> None:
        try:
            self.hal.shared_block("motmod.channel")
        except HalError:
            return                      # no motion module: no joints
        from halsdk.machine.inicheck import check_hal_joints
        self._report(check_hal_joints(self.ini, self.hal))

    def _configure_motion(self) -> None:
        try:
            self.hal.shared_block("motmod.channel")
        except HalError:
            return                      # no motion module: a plain HAL
        from halsdk.motion import Motion
        self.motion = Motion.connect(self.hal, timeout=5.0)
        self.motion.configure_ini(self.ini.path)

    def controller_parts(self, io: Any = None, thread: str = "servo-thread"
                         ) -> tuple[Any, Any, Any, str]:
        """``(hal, motion, io, units)`` for the task controller of this
        machine: the I/O controller made from [EMCIO] (or a new one with
        an empty tool table, its poll in ``thread``) and the length unit
        of [TRAJ]LINEAR_UNITS."""
        from halsdk.machine import IoControl, MachineError, ToolTable
        ini = self.ini
        if self.motion is None:
            raise MachineError(f"{ini.path}: the HAL files load no motion "
                               "module (motmod)")
        if io is None and self.io is not None:
            io = self.io                # made before the HAL files ran
        if io is None:
            name = ini.get("EMCIO", "TOOL_TABLE")
            random = str(ini.get("EMCIO", "RANDOM_TOOLCHANGER") or "0"
                         ).strip() not in ("0", "")
            table = ToolTable(random=random)
            if name:
                table = ToolTable.load(_path(ini, name), random=random)
            io = IoControl(table)
            io.attach(self.hal, thread)
            self.io = io
        units = str(ini.get("TRAJ", "LINEAR_UNITS") or "mm").strip().lower()
        units = "inch" if units in ("inch", "in", "imperial") else "mm"
        return self.hal, self.motion, io, units

    # ------------------------------------------------------------ run

    def wait(self, seconds: Optional[float] = None) -> None:
        """Step 5: until stop() (SIGINT, SIGTERM) or ``seconds``.

        It looks at a flag every :data:`STOP_POLL` seconds: stop() is the
        signal handler, run on this very thread between two bytecodes,
        so it must take no lock.  (With a ``threading.Event``, ``set()``
        in the handler could find the Event's lock held by the
        interrupted ``wait()`` and wait for it forever: a machine that
        SIGTERM never stopped.)"""
        deadline = None if seconds is None else time.monotonic() + seconds
        while not self._stopping:
            left = STOP_POLL if deadline is None else \
                min(STOP_POLL, deadline - time.monotonic())
            if left <= 0:
                return
            time.sleep(left)

    def stop(self, *_: Any) -> None:
        """Ask wait() to return (any thread, or a signal handler)."""
        self._stopping = True

    def shutdown(self) -> None:
        """Step 6 (safe to call more than once)."""
        hal, self.hal = self.hal, None
        if hal is None:
            return
        try:
            if self.motion is not None:
                try:
                    self.motion.disable()
                except HalError as e:
                    print(f"halsdk run: disabling motion: {e}",
                          file=self.err)
            for name in self.ini.all("HAL", "SHUTDOWN"):
                self._executor(hal).run_file(_path(self.ini, name))
            hal.stop()
            # programs that the HAL files started and nothing ended
            executors, self._executors = self._executors, []
            for ex in executors:
                ex.end_children()
        finally:
            io, self.io = self.io, None
            if io is not None:
                try:
                    io.close()
                except HalError:
                    pass                # closed by its user already
            hal.close()


def run(ini_path: str, seconds: Optional[float] = None,
        realtime: bool = True, strict: bool = False) -> int:
    """``halsdk run``: start, host the task (when the HAL files load
    motion), run until a signal (or ``seconds``), shut down.  Returns the
    exit status.  ``strict``: problems of the INI file are errors (exit
    status 1, nothing started)."""
    from halsdk.machine.runner import TaskRunner
    try:
        machine = Launcher(ini_path, strict=strict)
        machine.start(realtime=realtime)
    except HalError as e:
        print(f"halsdk run: {e}", file=sys.stderr)
        return 1
    runner = None
    try:
        if machine.motion is not None:
            runner = TaskRunner(machine, realtime=realtime)
            runner.start()
    except HalError as e:
        print(f"halsdk run: {e}", file=sys.stderr)
        machine.shutdown()
        return 1
    old = {s: signal.signal(s, machine.stop)
           for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        what = "machine running" if runner else "HAL running (no motion: " \
            "no task)"
        print(f"halsdk run: {ini_path}: {what}; Ctrl-C stops it",
              file=machine.out, flush=True)
        machine.wait(seconds)
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
        try:
            if runner is not None:
                runner.stop()
        finally:
            machine.shutdown()
    print("halsdk run: stopped", file=machine.out, flush=True)
    return 0
