"""The native client of a running machine: :func:`connect`.

A machine started with ``halsdk run machine.ini`` hosts the task
controller; any process of the same user reaches it with::

    from halsdk.machine import connect, TaskMode, TaskState

    with connect() as m:                  # $HALSDK_INSTANCE or the default
        m.estop_reset()
        m.on()
        m.home(wait=True)
        m.mode(TaskMode.MDI)
        m.mdi("G0 X10 Y5")                # waits until the moves are done
        print(m.status().position[:3], m.errors())

Every command method sends the command on the command channel and
waits until the task took it (at most ``timeout`` seconds) or refused it:
a refusal raises :class:`MachineError` with the task's reason.  Methods
with ``wait=True`` then wait until the command is done (an MDI line's
moves ended, the program ended, the joints are homed).  Each returns a
:class:`Command`, so a caller can also wait later: ``cmd.wait(timeout)``,
``await cmd.wait_async(timeout)``, ``cmd.done``, ``cmd.error``.

:meth:`MachineClient.status` reads the status channel (a consistent
snapshot, a few microseconds) into a frozen :class:`RemoteStatus`;
:meth:`MachineClient.errors` takes the messages of the error channel.
The asyncio helpers (:meth:`MachineClient.wait_for_async`,
:meth:`MachineClient.follow`, :meth:`Command.wait_async`) poll and sleep
and never block the event loop.

When the machine goes away (its host stopped or died) every call raises
:class:`ChannelGone` ("the machine is gone: ..."); nothing waits for it.
"""

from __future__ import annotations

import asyncio
import os
import time
from collections.abc import AsyncIterator, Callable
from typing import Any, Optional, Union

from halsdk.channels import cmdproto
from halsdk.channels.cmdclient import CommandClient
from halsdk.channels.cmdproto import RCS_DONE, RCS_ERROR, RCS_EXEC
from halsdk.channels.constants import (
    AUTO_PAUSE,
    AUTO_RESUME,
    AUTO_RUN,
    AUTO_STEP,
    JOG_CONTINUOUS,
    JOG_INCREMENT,
    JOG_STOP,
    KIND_NAMES,
    SPINDLE_CONSTANT,
    SPINDLE_DECREASE,
    SPINDLE_FORWARD,
    SPINDLE_INCREASE,
    SPINDLE_OFF,
    SPINDLE_REVERSE,
)
from halsdk.channels.shmchannel import (
    BLOCK_NAME,
    ChannelError,
    ChannelGone,
    ErrorReader,
    Snapshot,
    StatusReader,
)
from halsdk.errors import HalError, InvalidError, NotFoundError
from halsdk.hal import Hal
from halsdk.machine.remote_status import (
    AXIS_LETTERS,
    RemoteStatus,
    enum_member,
)
from halsdk.machine.task import MachineError, TaskMode, TaskState

__all__ = ["connect", "MachineClient", "Command", "MachineTimeout",
           "ChannelError", "ChannelGone", "kind_name", "START_HINT"]

#: what a "no machine" error tells the user to do
START_HINT = "start one with: halsdk run machine.ini"
#: seconds between status polls while waiting
POLL_INTERVAL = 0.005
# task cycles homing may stay idle (no joint homing, not all homed)
# before the wait says homing stopped; between two home sequences the
# joints are idle for a few servo periods only
_HOMING_IDLE_CYCLES = 20
# task cycles a finished command's effect takes to show in the status
_SETTLE_CYCLES = 2

_SPINDLE_WORDS = {"forward": SPINDLE_FORWARD, "reverse": SPINDLE_REVERSE,
                  "off": SPINDLE_OFF, "increase": SPINDLE_INCREASE,
                  "decrease": SPINDLE_DECREASE, "constant": SPINDLE_CONSTANT}


class MachineTimeout(MachineError, TimeoutError):
    """A wait for the machine ended without the awaited result: the task
    did not take a command in time, or a command was not done in time
    (it goes on in the task)."""


def kind_name(kind: int) -> str:
    """The word of a message kind of :meth:`MachineClient.errors`:
    ``"error"`` (NML_ERROR 1, OPERATOR_ERROR 11), ``"text"`` (2, 12) or
    ``"display"`` (3, 13)."""
    return KIND_NAMES.get(kind, "error")


# ---------------------------------------------------------------- commands

class _Until:
    """What a command's wait checks in the status after the task said
    done (homing ended, a jog increment arrived).  Called with each new
    status: True when reached; MachineError when it cannot be."""

    def __init__(self, what: str) -> None:
        self.what = what
        self.start: Optional[int] = None

    def __call__(self, st: RemoteStatus) -> bool:
        if self.start is None:
            self.start = st.heartbeat
        if st.task_state is not TaskState.ON or not st.enabled:
            raise MachineError(f"{self.what}: the machine left ON before it "
                               "ended")
        return self.check(st, st.heartbeat - self.start)

    def check(self, st: RemoteStatus, cycles: int) -> bool:
        raise NotImplementedError


class _Homed(_Until):
    def __init__(self, joint: int) -> None:
        super().__init__("home")
        self.joint = joint
        self.idle_since: Optional[int] = None

    def check(self, st: RemoteStatus, cycles: int) -> bool:
        if self.joint < 0:
            joints = st.joints
        elif self.joint < len(st.joints):
            joints = (st.joints[self.joint],)
        else:
            joints = ()
        if any(j.homing for j in joints):
            self.idle_since = None
            return False
        if joints and all(j.homed for j in joints) and \
                cycles >= _SETTLE_CYCLES:
            return True
        if self.idle_since is None:
            self.idle_since = st.heartbeat
        elif st.heartbeat - self.idle_since > _HOMING_IDLE_CYCLES:
            which = "all joints" if self.joint < 0 else f"joint {self.joint}"
            raise MachineError(f"home: homing stopped before {which} "
                               "were homed (see the error messages)")
        return False


class _JogDone(_Until):
    def __init__(self) -> None:
        super().__init__("jog")

    def check(self, st: RemoteStatus, cycles: int) -> bool:
        return cycles >= _SETTLE_CYCLES and st.inpos and \
            all(j.inpos for j in st.joints)


class Command:
    """A command sent to the machine, as :class:`MachineClient`'s
    methods return it.

    ``serial`` is its number on this client's connection; ``state`` the
    last known RCS_* state (0: no answer yet, ``RCS_EXEC`` 2: taken,
    ``RCS_DONE`` 1, ``RCS_ERROR`` 3); ``done`` whether it finished (for
    ``home`` and jog increments: the joints homed, the move ended);
    ``error`` the reason when it failed.
    """

    def __init__(self, client: MachineClient, name: str, serial: int,
                 until: Optional[_Until] = None) -> None:
        self.client = client
        self.name = name
        self.serial = serial
        self._until = until
        self._finished = False
        self._error: Optional[str] = None

    def __repr__(self) -> str:
        try:
            state = f"state={self.state} done={self.done}"
        except HalError:                # the machine is gone
            state = "machine gone"
        return f"<Command {self.name} serial={self.serial} {state}>"

    @property
    def state(self) -> int:
        if self._finished:
            return RCS_ERROR if self._error is not None else RCS_DONE
        return self.client._cmd.state_of(self.serial)

    @property
    def done(self) -> bool:
        """Whether it finished (done or failed); never waits."""
        self._poll()
        return self._finished

    @property
    def error(self) -> Optional[str]:
        """The reason it failed, None while it runs or when it is done."""
        self._poll()
        return self._error

    def _poll(self) -> bool:
        """Look once (no waiting); True when finished."""
        if self._finished:
            return True
        self.client._check_open()
        state, error = self.client._cmd.wait(self.serial, 0.0)
        if state == -1:
            return False
        if state == RCS_ERROR:
            return self._end(error or f"{self.name} failed")
        if self._until is not None:
            try:
                if not self._until(self.client.status()):
                    return False
            except MachineError as e:
                return self._end(str(e))
        return self._end(None)

    def _end(self, error: Optional[str]) -> bool:
        self._finished = True
        self._error = error
        return True

    def _result(self) -> Command:
        if self._error is not None:
            raise MachineError(self._error)
        return self

    def _timed_out(self, timeout: Optional[float]) -> MachineTimeout:
        return MachineTimeout(f"{self.name}: not done within "
                              f"{timeout:.3g} s (it goes on in the machine)")

    def wait(self, timeout: Optional[float] = None) -> Command:
        """Wait until it is done (``timeout`` seconds; None: no limit; the
        machine going away ends every wait).  Returns the command; raises
        MachineError with the reason when it failed, MachineTimeout when
        the time ran out, ChannelGone when the machine is gone."""
        if self._finished:
            return self._result()
        self.client._check_open()
        deadline = None if timeout is None else time.monotonic() + timeout
        state, error = self.client._cmd.wait(self.serial, timeout)
        if state == -1:
            raise self._timed_out(timeout)
        if state == RCS_ERROR:
            self._end(error or f"{self.name} failed")
            return self._result()
        until = self._until
        if until is not None:
            try:
                self.client._wait_status(until, deadline, self.name, timeout)
            except MachineTimeout:
                raise
            except MachineError as e:
                self._end(str(e))
                return self._result()
        self._end(None)
        return self

    async def wait_async(self, timeout: Optional[float] = None,
                         interval: float = POLL_INTERVAL) -> Command:
        """:meth:`wait` for asyncio: looks every ``interval`` seconds and
        sleeps in between, never blocking the event loop."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while not self._poll():
            if deadline is not None and time.monotonic() >= deadline:
                raise self._timed_out(timeout)
            await asyncio.sleep(interval)
        return self._result()


# ---------------------------------------------------------------- client

JointOrAxis = Union[int, str]


def connect(instance: Optional[str] = None, timeout: float = 5.0, *,
            name: str = "client") -> MachineClient:
    """Connect to the machine running on HAL instance ``instance``
    (default: ``$HALSDK_INSTANCE``, else the user's default instance).

    :param timeout: seconds for connecting and, later, for each command
        to be taken by the task.
    :param name: how the task's reports name this client.
    :raises ChannelError: no machine runs there ("no machine is running
        on instance X (start one with: halsdk run machine.ini)"), or it
        runs another halsdk version.
    :raises MachineTimeout: the machine is there but its task did not
        answer within ``timeout`` (stuck or stopped).
    """
    return MachineClient(instance, timeout, name=name)


class MachineClient:
    """A connection to a running machine (see :func:`connect`).

    The command methods mirror :class:`halsdk.machine.Machine` and the
    reference's ``linuxcnc.command``; each waits until the task took the
    command (at most :attr:`timeout` seconds) and raises
    :class:`MachineError` with the task's reason when it refused it.
    One client may be used from several threads.  Close it (or use it as
    a context manager) when done: it attaches this process to the HAL
    instance, and a process uses one instance at a time.
    """

    def __init__(self, instance: Optional[str] = None, timeout: float = 5.0,
                 *, name: str = "client") -> None:
        if not timeout > 0:
            raise InvalidError(f"timeout {timeout!r}: must be > 0 seconds")
        self.timeout = float(timeout)
        self.instance = _label(instance)
        self._closed = False
        self._hal = self._attach(instance)
        try:
            self.instance = self._hal.instance
            self._open_channels(name)
        except BaseException:
            self._hal.close()
            raise

    # -- connecting ------------------------------------------------------

    def _no_machine(self, why: str = "") -> str:
        return (f"no machine is running on instance {self.instance}"
                f"{why} ({START_HINT})")

    def _attach(self, instance: Optional[str]) -> Hal:
        current = Hal.current()
        if current is not None and (instance is None or
                                    current.instance == self.instance):
            self.instance = current.instance
        elif current is not None:
            raise ChannelError(
                f"this process uses HAL instance '{current.instance}'; a "
                f"client of instance '{self.instance}' needs a process of "
                "its own (one instance per process)")
        try:
            return Hal(instance, create=False)
        except InvalidError:
            raise
        except HalError as e:
            text = str(e)
            if "no HAL instance" in text:
                raise ChannelError(self._no_machine()) from None
            raise ChannelError(self._no_machine(f": {text}")) from None

    def _open_channels(self, name: str) -> None:
        hal = self._hal
        deadline = time.monotonic() + self.timeout
        # a task starting right now: its block is made, its header not
        # yet written, or its socket not yet bound (a few milliseconds)
        settle = time.monotonic() + min(self.timeout, 0.5)
        while True:
            try:
                address, size = hal.shared_block(BLOCK_NAME)
                self._reader = StatusReader(address, size)
                self._errors = ErrorReader(address, size)
                snap = self._reader.poll()
                break
            except NotFoundError:
                raise ChannelError(self._no_machine(
                    " (HAL runs there, but no task)")) from None
            except ChannelGone as e:
                raise ChannelGone(self._no_machine(f": {e}")) from None
            except ChannelError:
                if time.monotonic() >= settle:
                    raise
                time.sleep(0.01)
        self.task_pid = int(snap.task_pid)
        path = hal.private_socket_path("task")
        while not os.path.exists(path) and time.monotonic() < settle:
            time.sleep(0.01)
        try:
            self._cmd = CommandClient(path, name,
                                      max(0.01, deadline - time.monotonic()))
        except ChannelGone as e:
            raise ChannelGone(self._no_machine(f": {e}")) from None
        except ChannelError as e:
            if not os.path.exists(path):
                raise ChannelError(self._no_machine(
                    " (its task has no command socket)")) from None
            if time.monotonic() >= deadline:
                # alive (its status is there) but not answering
                raise MachineTimeout(
                    f"the machine on instance {self.instance} (task pid "
                    f"{self.task_pid}) did not answer within "
                    f"{self.timeout:.3g} s: {e}") from None
            raise
        self._cmd.timeout = self.timeout

    # -- lifetime ----------------------------------------------------------

    def close(self) -> None:
        """Close the connection (commands sent go on in the machine) and
        stop using the HAL instance.  Closing twice is fine."""
        if self._closed:
            return
        self._closed = True
        try:
            self._cmd.close()
        finally:
            self._hal.close()

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> MachineClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self._closed else f"task pid {self.task_pid}"
        return f"<MachineClient instance {self.instance!r} {state}>"

    def _check_open(self) -> None:
        if self._closed:
            raise ChannelError("this machine client is closed; connect() "
                               "again")

    # -- status and errors -------------------------------------------------

    def snapshot(self) -> Snapshot:
        """The raw status channel snapshot (every field of
        :mod:`halsdk.channels.statusfields`, as the reference names them)."""
        self._check_open()
        return self._reader.poll()

    def status(self) -> RemoteStatus:
        """The machine's status now (a consistent snapshot)."""
        snap = self.snapshot()
        return RemoteStatus.from_snapshot(snap, self._errors.pending)

    def errors(self, limit: Optional[int] = None) -> list[tuple[int, str]]:
        """The messages of the error channel this client has not taken
        yet (at most ``limit``), oldest first, as ``(kind, text)`` with
        the reference's kind numbers (:func:`kind_name` gives the word).
        Every client sees every message; the first client also gets those
        posted before any client connected.  Once the machine is gone,
        the messages it left are still returned, then ChannelGone."""
        self._check_open()
        out: list[tuple[int, str]] = []
        while limit is None or len(out) < limit:
            try:
                message = self._errors.poll()
            except ChannelGone:
                if out:
                    return out
                raise
            if message is None:
                return out
            out.append(message)
        return out

    kind_name = staticmethod(kind_name)

    @property
    def errors_lost(self) -> int:
        """Messages overwritten before this client took them."""
        return self._errors.lost

    def wait_for(self, predicate: Callable[[RemoteStatus], bool],
                 timeout: Optional[float] = None,
                 interval: float = POLL_INTERVAL) -> RemoteStatus:
        """Poll the status until ``predicate(status)`` is true; returns
        that status.  MachineTimeout after ``timeout`` seconds (None: no
        limit; the machine going away ends it with ChannelGone)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        return self._wait_status(predicate, deadline, "the condition",
                                 timeout, interval)

    def _wait_status(self, predicate: Callable[[RemoteStatus], bool],
                     deadline: Optional[float], what: str,
                     timeout: Optional[float],
                     interval: float = POLL_INTERVAL) -> RemoteStatus:
        while True:
            st = self.status()
            if predicate(st):
                return st
            if deadline is not None and time.monotonic() >= deadline:
                raise MachineTimeout(f"{what}: not reached within "
                                     f"{timeout:.3g} s")
            time.sleep(interval)

    async def wait_for_async(self, predicate: Callable[[RemoteStatus], bool],
                             timeout: Optional[float] = None,
                             interval: float = POLL_INTERVAL
                             ) -> RemoteStatus:
        """:meth:`wait_for` for asyncio (sleeps between polls, never
        blocks the event loop)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            st = self.status()
            if predicate(st):
                return st
            if deadline is not None and time.monotonic() >= deadline:
                raise MachineTimeout(f"the condition: not reached within "
                                     f"{timeout:.3g} s")
            await asyncio.sleep(interval)

    async def follow(self, interval: float = 0.1, *,
                     changes_only: bool = True
                     ) -> AsyncIterator[RemoteStatus]:
        """``async for st in client.follow(0.1)``: the status now, then
        every ``interval`` seconds the status when it changed (all of
        them with ``changes_only=False``).  Ends with ChannelGone when
        the machine goes away."""
        last: Optional[RemoteStatus] = None
        while True:
            st = self.status()
            if not changes_only or st != last:
                last = st
                yield st
            await asyncio.sleep(interval)

    # -- sending -----------------------------------------------------------

    def command(self, name: str, **args: Any) -> Command:
        """Send command ``name`` of :data:`halsdk.channels.cmdproto.COMMANDS`
        (the reference's ``linuxcnc.command`` methods) with ``args`` and
        wait until the task took it.  CommandError (an InvalidError) for
        an unknown command or bad arguments, MachineError when the task
        refused it."""
        return self._send(name, None, **args)

    def _send(self, name: str, until: Optional[_Until],
              **args: Any) -> Command:
        self._check_open()
        cmdproto.validate(name, args)
        serial = self._cmd.send(name, **args)
        cmd = Command(self, name, serial, until)
        self._taken(cmd)
        return cmd

    def _taken(self, cmd: Command) -> None:
        """Wait until the task took ``cmd`` or refused it (it answers
        "received" first; an immediate refusal or completion follows in
        the same task cycle, so once the status shows a later cycle the
        answer is here, or the command is in progress)."""
        client, serial = self._cmd, cmd.serial
        deadline = time.monotonic() + self.timeout
        state, error = client.wait_received(serial, self.timeout)
        if state == RCS_EXEC:
            beat = self._reader.poll().heartbeat
            while True:
                remaining = deadline - time.monotonic()
                state, error = client.wait(
                    serial, max(0.0, min(remaining, 0.002)))
                if state != -1:
                    break
                if self._reader.poll().heartbeat > beat:
                    state, error = client.wait(serial, 0.0)
                    if state == -1:
                        state = RCS_EXEC        # taken, in progress
                    break
                if remaining <= 0:
                    state = -1
                    break
        if state == -1:
            raise MachineTimeout(f"{cmd.name}: the machine did not take the "
                                 f"command within {self.timeout:g} s (is it "
                                 "stuck?)")
        if state == RCS_ERROR:
            cmd._end(error or f"{cmd.name} refused")
            cmd._result()

    def _do(self, name: str, wait: bool, timeout: Optional[float],
            until: Optional[_Until] = None, **args: Any) -> Command:
        cmd = self._send(name, until, **args)
        if wait:
            cmd.wait(timeout)
        return cmd

    # -- state and mode ----------------------------------------------------

    def state(self, state: TaskState | int | str, wait: bool = True,
              timeout: Optional[float] = None) -> Command:
        """``command.state``: ESTOP, ESTOP_RESET, OFF or ON (a member,
        its number or its name); with ``wait`` until the task finished
        it (an E-stop reset: the I/O controller answered; ``timeout``
        default: the client's)."""
        target = enum_member(TaskState, state, "state")
        return self._do("state", wait,
                        self.timeout if timeout is None else timeout,
                        state=int(target))

    def estop(self) -> Command:
        """E-stop (``state(ESTOP)``)."""
        return self.state(TaskState.ESTOP)

    def estop_reset(self) -> Command:
        """Reset the E-stop (``state(ESTOP_RESET)``)."""
        return self.state(TaskState.ESTOP_RESET)

    def on(self) -> Command:
        """Turn the machine on (``state(ON)``)."""
        return self.state(TaskState.ON)

    def off(self) -> Command:
        """Turn the machine off (``state(OFF)``)."""
        return self.state(TaskState.OFF)

    def mode(self, mode: TaskMode | int | str) -> Command:
        """``command.mode``: MANUAL, AUTO or MDI (only while idle)."""
        target = enum_member(TaskMode, mode, "mode")
        return self._do("mode", True, None, mode=int(target))

    # -- manual ------------------------------------------------------------

    def home(self, joint: int = -1, wait: bool = False,
             timeout: Optional[float] = None) -> Command:
        """``command.home``: home ``joint`` (-1: all, in their sequence;
        MANUAL mode); with ``wait`` until homed (MachineError when homing
        stops before)."""
        return self._do("home", wait, timeout, _Homed(joint), joint=joint)

    def unhome(self, joint: int = -1) -> Command:
        """``command.unhome`` (-1: all joints)."""
        return self._do("unhome", False, None, joint=joint)

    def _jog_target(self, joint_or_axis: JointOrAxis, teleop: bool
                    ) -> tuple[bool, int]:
        if isinstance(joint_or_axis, str):
            letter = joint_or_axis.strip().upper()
            if len(letter) != 1 or letter not in AXIS_LETTERS:
                raise InvalidError(f"jog: {joint_or_axis!r} is not an axis "
                                   f"letter ({' '.join(AXIS_LETTERS)}) nor "
                                   "a joint number")
            return False, AXIS_LETTERS.index(letter)
        return not teleop, int(joint_or_axis)

    def jog(self, joint_or_axis: JointOrAxis, velocity: float,
            distance: Optional[float] = None, teleop: bool = False,
            wait: bool = False, timeout: Optional[float] = None) -> Command:
        """``command.jog``: a joint (a number) or, in teleop mode, an axis
        (a letter, or a number with ``teleop=True``) at ``velocity``
        (units/s; its sign is the direction): continuously until
        :meth:`jog_stop` when ``distance`` is None, else by ``distance``
        (with ``wait``: until the move ended).  MANUAL mode."""
        joint_mode, index = self._jog_target(joint_or_axis, teleop)
        if distance is None:
            return self._do("jog", False, None, action=JOG_CONTINUOUS,
                            joint_mode=joint_mode, index=index,
                            velocity=float(velocity))
        return self._do("jog", wait, timeout, _JogDone(),
                        action=JOG_INCREMENT, joint_mode=joint_mode,
                        index=index, velocity=float(velocity),
                        distance=float(distance))

    def jog_stop(self, joint_or_axis: JointOrAxis, teleop: bool = False
                 ) -> Command:
        """``command.jog(JOG_STOP, ...)``."""
        joint_mode, index = self._jog_target(joint_or_axis, teleop)
        return self._do("jog", False, None, action=JOG_STOP,
                        joint_mode=joint_mode, index=index)

    def override_limits(self) -> Command:
        """``command.override_limits``: jog off a limit switch."""
        return self.command("override_limits")

    def teleop_enable(self, on: bool = True) -> Command:
        return self.command("teleop_enable", on=bool(on))

    def traj_mode(self, mode: int) -> Command:
        """``command.traj_mode``: 1 free, 2 coordinated, 3 teleop."""
        return self.command("traj_mode", mode=int(mode))

    # -- MDI and programs -------------------------------------------------

    def mdi(self, line: str, wait: bool = True,
            timeout: Optional[float] = None) -> Command:
        """``command.mdi``: run one line (MDI mode); with ``wait`` until
        its moves are done (the reference's ``wait_complete``)."""
        return self._do("mdi", wait, timeout, line=line)

    def program_open(self, path: str | os.PathLike[str]) -> Command:
        """``command.program_open``: ``path`` relative to this process's
        current folder."""
        return self.command("program_open", path=os.path.abspath(path))

    def run(self, start_line: int = 0, wait: bool = False,
            timeout: Optional[float] = None) -> Command:
        """``command.auto(AUTO_RUN, start_line)``: run the open program
        (AUTO mode); with ``wait`` until it ended."""
        return self._do("auto", wait, timeout, action=AUTO_RUN,
                        line=int(start_line))

    def pause(self) -> Command:
        """``command.auto(AUTO_PAUSE)``."""
        return self.command("auto", action=AUTO_PAUSE)

    def resume(self) -> Command:
        """``command.auto(AUTO_RESUME)``: after pause or M0/M1."""
        return self.command("auto", action=AUTO_RESUME)

    def step(self) -> Command:
        """``command.auto(AUTO_STEP)``: one block while paused."""
        return self.command("auto", action=AUTO_STEP)

    def abort(self) -> Command:
        """``command.abort``: stop moves, spindle, coolant; idle."""
        return self.command("abort")

    def reset_interpreter(self) -> Command:
        return self.command("reset_interpreter")

    def task_plan_sync(self) -> Command:
        """``command.task_plan_synch``: save the parameters."""
        return self.command("task_plan_sync")

    def set_optional_stop(self, on: bool) -> Command:
        return self.command("set_optional_stop", on=bool(on))

    def set_block_delete(self, on: bool) -> Command:
        return self.command("set_block_delete", on=bool(on))

    # -- overrides and limits -------------------------------------------

    def feed_override(self, scale: float) -> Command:
        """``command.feedrate``: 1.0 is 100 %."""
        return self.command("feedrate", scale=float(scale))

    def rapid_override(self, scale: float) -> Command:
        """``command.rapidrate``: 0 to 1."""
        return self.command("rapidrate", scale=float(scale))

    def spindle_override(self, scale: float, spindle: int = 0) -> Command:
        """``command.spindleoverride``."""
        return self.command("spindleoverride", scale=float(scale),
                            spindle=spindle)

    def max_velocity(self, velocity: float) -> Command:
        """``command.maxvel``."""
        return self.command("maxvel", velocity=float(velocity))

    def set_feed_override(self, on: bool) -> Command:
        return self.command("set_feed_override", on=bool(on))

    def set_spindle_override(self, on: bool, spindle: int = 0) -> Command:
        return self.command("set_spindle_override", on=bool(on),
                            spindle=spindle)

    def set_feed_hold(self, on: bool) -> Command:
        return self.command("set_feed_hold", on=bool(on))

    def set_adaptive_feed(self, on: bool) -> Command:
        return self.command("set_adaptive_feed", on=bool(on))

    def _axis_index(self, axis: JointOrAxis) -> int:
        if isinstance(axis, str):
            letter = axis.strip().upper()
            if len(letter) != 1 or letter not in AXIS_LETTERS:
                raise InvalidError(f"{axis!r} is not an axis letter "
                                   f"({' '.join(AXIS_LETTERS)})")
            return AXIS_LETTERS.index(letter)
        return int(axis)

    def set_min_limit(self, axis: JointOrAxis, limit: float) -> Command:
        return self.command("set_min_limit", axis=self._axis_index(axis),
                            limit=float(limit))

    def set_max_limit(self, axis: JointOrAxis, limit: float) -> Command:
        return self.command("set_max_limit", axis=self._axis_index(axis),
                            limit=float(limit))

    # -- spindle, coolant, I/O -------------------------------------------

    def spindle(self, direction: int | str, speed: float = 0.0,
                spindle: int = 0, wait_for_speed: bool = False) -> Command:
        """``command.spindle``: ``direction`` SPINDLE_FORWARD (1),
        SPINDLE_REVERSE (-1), SPINDLE_OFF (0), SPINDLE_INCREASE (10),
        SPINDLE_DECREASE (11), SPINDLE_CONSTANT (12), or the words
        "forward", "reverse", "off", "increase", "decrease", "constant";
        ``speed`` in rpm."""
        if isinstance(direction, str):
            word = direction.strip().lower()
            if word not in _SPINDLE_WORDS:
                raise InvalidError(f"spindle direction {direction!r}: one of "
                                   f"{', '.join(_SPINDLE_WORDS)}")
            direction = _SPINDLE_WORDS[word]
        return self.command("spindle", direction=int(direction),
                            speed=float(speed), spindle=spindle,
                            wait_for_speed=bool(wait_for_speed))

    def spindle_off(self, spindle: int = 0) -> Command:
        return self.spindle(SPINDLE_OFF, spindle=spindle)

    def brake(self, engage: bool, spindle: int = 0) -> Command:
        return self.command("brake", engage=bool(engage), spindle=spindle)

    def flood(self, on: bool = True) -> Command:
        """``command.flood``."""
        return self.command("flood", on=bool(on))

    def mist(self, on: bool = True) -> Command:
        """``command.mist``."""
        return self.command("mist", on=bool(on))

    def set_digital_output(self, index: int, value: bool) -> Command:
        """``command.set_digital_output`` (motion.digital-out-NN)."""
        return self.command("set_digital_output", index=index,
                            value=bool(value))

    def set_analog_output(self, index: int, value: float) -> Command:
        """``command.set_analog_output`` (motion.analog-out-NN)."""
        return self.command("set_analog_output", index=index,
                            value=float(value))

    # -- tool table --------------------------------------------------------

    def tool_offset(self, tool: int, z: float = 0.0, x: float = 0.0,
                    diameter: float = 0.0, frontangle: float = 0.0,
                    backangle: float = 0.0, orientation: int = 0
                    ) -> Command:
        """``command.tool_offset``: set a tool's data (the table file is
        saved)."""
        return self.command("tool_offset", tool=tool, z=float(z),
                            x=float(x), diameter=float(diameter),
                            frontangle=float(frontangle),
                            backangle=float(backangle),
                            orientation=orientation)

    def load_tool_table(self) -> Command:
        """``command.load_tool_table``: read the table file again."""
        return self.command("load_tool_table")

    # -- messages and debug ------------------------------------------------

    def text_msg(self, text: str) -> Command:
        """Post an operator text message on the error channel."""
        return self.command("text_msg", text=text)

    def error_msg(self, text: str) -> Command:
        """Post an operator error message on the error channel."""
        return self.command("error_msg", text=text)

    def display_msg(self, text: str) -> Command:
        """Post an operator display message on the error channel."""
        return self.command("display_msg", text=text)

    def debug(self, level: int) -> Command:
        return self.command("debug", level=level)

    @property
    def last_serial(self) -> int:
        """The serial of the last command this client sent (0: none)."""
        return self._cmd.serial


def _label(instance: Optional[str]) -> str:
    """The instance's name in messages."""
    name = instance if instance is not None else \
        os.environ.get("HALSDK_INSTANCE", "")
    return name or "default"
