"""The Python client of the motion controller (motmod).

A :class:`Motion` object talks to motmod through the shared command
channel (``components/motion/channel.h``): it sends one command at a
time, waits for motmod's echo and raises :class:`Rejected` with motmod's
reason when the command was refused.  :meth:`Motion.status` returns a
consistent snapshot; :meth:`Motion.errors` the realtime error messages.

Waiting is deterministic when the client is given the :class:`halsdk.Hal`
object of the instance and its threads are not running in real time: the
client then steps the servo thread itself, one cycle at a time, until the
echo (or the awaited condition) arrives.  Otherwise it polls with short
sleeps until a timeout of wall-clock time.
"""

from __future__ import annotations

import enum
import math
import os
import threading
import time
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, Callable, Optional, Union

from halsdk.errors import HalError, NotFoundError
from halsdk.hal import Hal
from halsdk.motion import _channel, screwcomp
from halsdk.motion.ini import (
    Plan,
    axis_plan,
    homing_fields,
    joint_plan,
    read_motion_ini,
    traj_plan,
)
from halsdk.motion.protocol import (
    Cmd,
    Echo,
    Mode,
    MotionType,
    ProbeFlag,
    Profile,
    TermCond,
)
from halsdk.motion.status import (
    AXES,
    JOINT_ERROR,
    JOINT_FAULT,
    JOINT_FERROR,
    JOINT_HOMED,
    JOINT_NEG_HARD,
    JOINT_POS_HARD,
    Pose,
    Status,
)

__all__ = ["Motion", "Rejected", "EnableFailed", "QueueRejected",
           "MotionError",
           "MotionTimeout", "Cmd", "Echo", "InputWait", "homing_fields"]

CHANNEL_NAME = "motmod.channel"


class MotionError(HalError):
    """The motion channel is missing, gone or of another version, or a
    wait ended without the awaited result."""


class MotionTimeout(MotionError, TimeoutError):
    """A wait did not end within its timeout."""


class Rejected(HalError):
    """motmod refused a command; nothing was done.

    :ivar command: the command's name (e.g. ``"JOG_INCR"``).
    :ivar reason: motmod's reason, one sentence.
    """

    def __init__(self, command: str, reason: str):
        super().__init__(f"{command} rejected: {reason}")
        self.command = command
        self.reason = reason


class QueueRejected(Rejected):
    """motmod refused a queued record (sent with a ``queue_*`` method);
    the queue stopped there and the records written after it were dropped.
    Raised by the next call of the client after motmod saw it.

    :ivar id: the motion id of the record.
    :ivar line: its program line.
    """

    def __init__(self, command: str, reason: str, id: int, line: int):
        Rejected.__init__(self, command, reason)
        self.args = (f"queued {command} (id {id}, line {line}) rejected: "
                     f"{reason}",)
        self.id = id
        self.line = line

    def __str__(self) -> str:
        return self.args[0]


class EnableFailed(Rejected):
    """motmod took ENABLE but a fault disabled motion again at once
    (:meth:`Motion.enable`); motion stays disabled.

    :ivar reason: why, naming the joint (or spindle) and the fault, e.g.
        ``"joint 0 amplifier fault (joint.0.amp-fault-in is true)"``.
    :ivar joint: the joint at fault, or None (spindle, ``motion.enable``,
        a misc error, or not known).
    :ivar fault: ``"amp-fault"``, ``"pos-hard-limit"``,
        ``"neg-hard-limit"``, ``"following-error"``, ``"spindle-amp-fault"``,
        ``"motion-enable"``, ``"misc-error"`` or ``"unknown"``.
    :ivar messages: motmod's messages posted meanwhile.
    """

    def __init__(self, status: dict, messages: Sequence[str] = ()):
        self.messages = list(messages)
        self.joint, self.fault, reason = _enable_fault(status, self.messages)
        Rejected.__init__(self, "ENABLE", reason)


_DISABLED = ": motion disabled"


def _enable_fault(d: dict, messages: Sequence[str]
                  ) -> tuple[Optional[int], str, str]:
    """(joint, fault kind, reason) of a motion that did not stay enabled,
    from the joint flags of the status (the pins) and motmod's message."""
    said = [t[:-len(_DISABLED)] for t in messages if t.endswith(_DISABLED)]
    joints = d["joints"][:max(0, min(d["num_joints"], len(d["joints"])))]
    for i, j in enumerate(joints):
        f = j["flags"]
        if not f & JOINT_ERROR:
            continue
        if f & JOINT_FAULT:
            return (i, "amp-fault", f"joint {i} amplifier fault "
                    f"(joint.{i}.amp-fault-in is true)")
        if f & JOINT_FERROR:
            told = [t for t in said if t.startswith(f"joint {i} following")]
            return (i, "following-error", told[-1] if told else
                    f"joint {i} following error exceeds its limit "
                    f"{j['ferror_limit']:g}")
        if f & JOINT_POS_HARD:
            return (i, "pos-hard-limit", f"joint {i} on its positive hard "
                    f"limit (joint.{i}.pos-lim-sw-in is true)")
        if f & JOINT_NEG_HARD:
            return (i, "neg-hard-limit", f"joint {i} on its negative hard "
                    f"limit (joint.{i}.neg-lim-sw-in is true)")
    for n, sp in enumerate(d["spindles"][:d["num_spindles"]]):
        if sp["amp_fault"]:
            return (None, "spindle-amp-fault", f"spindle {n} amplifier "
                    f"fault (spindle.{n}.amp-fault-in is true)")
    for t in reversed(said):
        if t.startswith("motion.enable"):
            return None, "motion-enable", "motion.enable went false"
        if t.startswith("motion.misc-error"):
            return None, "misc-error", t
    if said:
        return None, "unknown", said[-1]
    return None, "unknown", ("motion did not stay enabled (motmod gave no "
                             "reason)")


class InputWait(enum.IntEnum):
    """Modes of :meth:`Motion.wait_input` (the L word of M66)."""
    IMMEDIATE = 0   #: no wait: the value now
    RISE = 1        #: a digital input going from false to true
    FALL = 2        #: a digital input going from true to false
    HIGH = 3        #: a digital input being true
    LOW = 4         #: a digital input being false


# length units of SET_LINEAR_UNITS: millimetres per unit
LINEAR_UNITS = {"mm": 1.0, "metric": 1.0, "cm": 10.0, "inch": 25.4,
                "in": 25.4, "imperial": 25.4}


# one sender at a time in this process (the channel lock is per process)
_send_lock = threading.RLock()

PoseLike = Union[Sequence[float], Mapping[str, float], Pose]
JointOrAxis = Union[int, str]


def _axis_index(letter: str) -> int:
    i = AXES.find(letter.lower()) if len(letter) == 1 else -1
    if i < 0:
        raise ValueError(f"unknown axis letter {letter!r} (one of "
                         "X Y Z A B C U V W)")
    return i


class Motion:
    """A connection to the motion controller of the attached HAL instance.

    Use :meth:`connect`.  Every command method waits for motmod's echo and
    raises :class:`Rejected` (with the reason) when the command is refused;
    commands that start motion return when the motion has started — use
    :meth:`wait_done`, :meth:`wait_inpos`, :meth:`wait_homed` or
    :meth:`wait_for` to wait for its end.
    """

    def __init__(self, channel: _channel.Channel, hal: Any = None,
                 thread: str = "servo-thread", timeout: float = 5.0,
                 own_hal: Any = None):
        self._ch = channel
        self._hal = hal
        self._own_hal = own_hal
        self.thread = thread
        self.timeout = timeout
        self._msg_read = channel.msg_count()
        self._pending: list[str] = []
        self._next_id = 1
        self._last_end: Optional[Pose] = None
        # the queue rejections seen so far (records carry it as epoch)
        self._q_epoch = channel.queue_state()[2]

    # ------------------------------------------------------------ connect

    @classmethod
    def connect(cls, hal: Any = None, name: str = CHANNEL_NAME, *,
                thread: str = "servo-thread", timeout: float = 5.0
                ) -> Motion:
        """Attach to motmod's channel block ``name``.

        :param hal: the :class:`halsdk.Hal` of the instance.  When given
            and its threads are not running in real time, waits step
            ``thread`` deterministically.  Without it, the client attaches
            to the user's instance (``halsdk.Hal()``) and polls.
        :param timeout: default timeout of waits, seconds (simulated time
            when stepping).
        :raises MotionError: no channel (motmod not loaded), or one of
            another version or size.
        """
        own = None
        if hal is None and not _attached():
            own = Hal(create=False)
        try:
            ch = _channel.Channel(name, os.getpid())
        except NotFoundError:
            if own is not None:
                own.close()
            raise MotionError(
                f"no motion channel '{name}' in HAL instance: is motmod "
                "loaded?") from None
        except _channel.ChannelError as e:
            if own is not None:
                own.close()
            raise MotionError(str(e)) from None
        return cls(ch, hal, thread, timeout, own)

    def close(self) -> None:
        """Forget the channel (and detach if connect() attached)."""
        if self._own_hal is not None:
            self._own_hal.close()
            self._own_hal = None

    def __enter__(self) -> Motion:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # ------------------------------------------------------------ waiting

    @property
    def stepping(self) -> bool:
        """True when waits step the servo thread themselves (the client
        has the Hal and its threads do not run in real time)."""
        return (self._hal is not None and
                not self._hal.info()["threads_running"])

    def moves_done(self, status: Optional[Status | dict] = None) -> bool:
        """Every queued move was taken and has run, and nothing moves
        (what wait_done waits for); without waiting.  Raises
        :class:`QueueRejected` when motmod refused a queued record that
        was not reported yet: a refused queue is drained, not done.
        ``status``: a :class:`Status` or a :meth:`status_dict` already
        taken this cycle (default: a new snapshot)."""
        if status is None or isinstance(status, dict):
            d = self.status_dict() if status is None else status
            if d["queue_err_count"] != self._q_epoch:
                self._check_queue()
            return (d["queue_taken"] == self._ch.queue_state()[0]
                    and d["queue_depth"] == 0 and d["in_position"]
                    and not d["homing"])
        st = status
        self._check_queue()
        return (st.queue_taken == self._ch.queue_state()[0]
                and st.queue_depth == 0 and st.in_position
                and not st.homing)

    def _wait(self, cond: Callable[[], Any], timeout: Optional[float],
              what: str) -> Any:
        """Wait until cond() returns something true; return it."""
        if timeout is None:
            timeout = self.timeout
        try:
            r = cond()
            if r:
                return r
            if self.stepping:
                period = self._servo_period()
                for _ in range(max(1, math.ceil(timeout / period))):
                    self._hal.step(1, thread=self.thread)
                    r = cond()
                    if r:
                        return r
                raise MotionTimeout(
                    f"timeout: {what} did not happen within {timeout:g} s "
                    f"of simulated time ({self.thread} stepped)")
            start = time.monotonic()
            end = start + timeout
            beat = self._heartbeat()
            while (now := time.monotonic()) < end:
                # motmod answers within a servo period or two: look often
                # at first, then every millisecond
                time.sleep(0.0001 if now - start < 0.005 else 0.001)
                r = cond()
                if r:
                    return r
            note = ""
            if self._heartbeat() == beat:
                note = (" — the servo thread did not run at all (start the "
                        "threads, or pass hal= to step them)")
            raise MotionTimeout(f"timeout: {what} did not happen within "
                                f"{timeout:g} s{note}")
        except _channel.ChannelError as e:
            raise MotionError(str(e)) from None

    def _servo_period(self) -> float:
        p = self._ch.status()["servo_period"]
        return p if p > 0 else 0.001

    def _heartbeat(self) -> int:
        return self._ch.status()["heartbeat"]

    # ------------------------------------------------------------ commands

    def command(self, cmd: Cmd, timeout: Optional[float] = None,
                **fields: Any) -> Echo:
        """Send one command record (fields of channel.h's mot_command_t)
        and wait for its echo; returns DONE or ACCEPTED, raises
        :class:`Rejected` with motmod's reason."""
        cmd = Cmd(cmd)
        ch = self._ch
        self._check_queue()
        with _send_lock:
            try:
                self._wait(lambda: ch.try_lock() == 0, timeout,
                           f"{cmd.name}: the channel lock (held by another "
                           "process)")
                try:
                    self._wait(ch.idle, timeout,
                               f"{cmd.name}: motmod taking the previous "
                               "command")
                    seq = ch.send(int(cmd), fields)
                    echo = self._wait(
                        lambda: (e := ch.echo())[0] == seq and e, timeout,
                        f"{cmd.name}: motmod's answer (is "
                        "motion-command-handler in a running thread?)")
                finally:
                    if ch.alive():
                        ch.unlock()
            except _channel.ChannelError as e:
                raise MotionError(str(e)) from None
        _, status, code, reason = echo
        if status == Echo.REJECTED:
            raise Rejected(cmd.name, reason or "no reason given")
        if status not in (Echo.DONE, Echo.ACCEPTED):
            raise MotionError(f"{cmd.name}: unexpected echo status "
                              f"{status} from motmod")
        return Echo(status)

    @staticmethod
    def _target(joint: JointOrAxis, teleop: bool) -> dict:
        """joint=... or axis=... fields of a jog."""
        if isinstance(joint, str):
            return {"joint": -1, "axis": _axis_index(joint)}
        if teleop:
            return {"joint": -1, "axis": int(joint)}
        return {"joint": int(joint)}

    # modes and state

    def abort(self) -> None:
        """Stop all motion in any mode (always accepted)."""
        self.command(Cmd.ABORT)

    def free(self) -> None:
        """Free mode: joints move on their own (needs all at rest)."""
        self.command(Cmd.FREE)

    def teleop(self) -> None:
        """Teleop mode: axis velocities through kinematics (needs all at
        rest; non-trivial kinematics need all joints homed)."""
        self.command(Cmd.TELEOP)

    def coord(self) -> None:
        """Coordinated mode: the trajectory planner runs queued moves
        (needs all at rest; non-trivial kinematics need homing)."""
        self.command(Cmd.COORD)

    def enable(self, timeout: Optional[float] = None) -> None:
        """Enable motion (amplifiers on, planners follow commands) and
        wait (at most ``timeout``, default the client's) until
        motion-controller has run a cycle with motion enabled.

        Raises :class:`Rejected` when motmod refuses the command (e.g.
        ``motion.enable`` is false) and :class:`EnableFailed` (a
        :class:`Rejected`) when motmod took it but a fault disabled
        motion again at once: an amplifier fault (``joint.N.amp-fault-in``,
        ``spindle.N.amp-fault-in``), a hard limit switch
        (``joint.N.pos-lim-sw-in`` / ``neg-lim-sw-in``, unless limits are
        overridden), a following error, ``motion.enable`` going false or a
        ``motion.misc-error-NN``; its text names the joint and the fault.
        motmod's message stays in :meth:`errors` as well."""
        self._pull_messages()
        seen = len(self._pending)
        self.command(Cmd.ENABLE, timeout)
        try:
            beat = self._ch.status()["heartbeat"]
        except _channel.ChannelError as e:
            raise MotionError(str(e)) from None
        # the first status written by motion-controller after motmod took
        # the command (in either order of the two functions in the thread)
        d = self._wait(lambda: (x := self._ch.status())["heartbeat"] > beat
                       and x, timeout,
                       "ENABLE: motion-controller running a cycle (is it in "
                       "a running thread?)")
        if d["enabled"]:
            return
        self._pull_messages()
        raise EnableFailed(d, self._pending[max(0, min(seen,
                                                       len(self._pending))):])

    def disable(self) -> None:
        """Disable motion: stop at once, amplifiers off."""
        self.command(Cmd.DISABLE)

    def enable_amplifier(self, joint: int) -> None:
        self.command(Cmd.ENABLE_AMPLIFIER, joint=joint)

    def disable_amplifier(self, joint: int) -> None:
        self.command(Cmd.DISABLE_AMPLIFIER, joint=joint)

    def activate_joint(self, joint: int) -> None:
        self.command(Cmd.ACTIVATE_JOINT, joint=joint)

    def deactivate_joint(self, joint: int) -> None:
        self.command(Cmd.DEACTIVATE_JOINT, joint=joint)

    def pause(self) -> None:
        """Pause the coordinated planner (decelerates along the path)."""
        self.command(Cmd.PAUSE)

    def resume(self) -> None:
        self.command(Cmd.RESUME)

    def step(self) -> None:
        """Resume and pause again at the end of the present move."""
        self.command(Cmd.STEP)

    def set_feed_scale(self, scale: float) -> None:
        """Feed override of coordinated feed moves, >= 0."""
        self.command(Cmd.SCALE, value=scale)

    def set_rapid_scale(self, scale: float) -> None:
        """Override of coordinated traverses, >= 0."""
        self.command(Cmd.RAPID_SCALE, value=scale)

    def override_limits(self, on: bool = True) -> None:
        """Ignore limit switches until the end of the next jog (on), or
        cancel such an override (off)."""
        self.command(Cmd.OVERRIDE_LIMITS, ival=1 if on else 0)

    # homing

    def home(self, joint: int = -1) -> None:
        """Start homing one joint, or -1: all joints with a sequence."""
        self.command(Cmd.HOME, joint=joint)

    def unhome(self, joint: int = -1) -> None:
        """Mark unhomed: one joint, -1 all, -2 those with VOLATILE_HOME."""
        self.command(Cmd.UNHOME, joint=joint)

    # jogs

    def jog_cont(self, joint: JointOrAxis, vel: float, *,
                 teleop: bool = False) -> None:
        """Jog continuously at the signed velocity ``vel`` until
        :meth:`jog_stop`, :meth:`abort` or a limit.  ``joint`` is a joint
        number (free mode) or an axis letter / number with
        ``teleop=True`` (teleop mode)."""
        self.command(Cmd.JOG_CONT, vel=vel, **self._target(joint, teleop))

    def jog_incr(self, joint: JointOrAxis, vel: float, dist: float, *,
                 teleop: bool = False) -> None:
        """Move by ``dist`` (signed) at speed ``vel`` > 0; increments add
        up when sent while the previous one still moves."""
        self.command(Cmd.JOG_INCR, vel=vel, offset=dist,
                     **self._target(joint, teleop))

    def jog_abs(self, joint: JointOrAxis, vel: float, pos: float, *,
                teleop: bool = False) -> None:
        """Move to ``pos`` at speed ``vel`` > 0."""
        self.command(Cmd.JOG_ABS, vel=vel, offset=pos,
                     **self._target(joint, teleop))

    def jog_stop(self, joint: JointOrAxis, *, teleop: bool = False) -> None:
        """Stop the jog of one joint (or axis), decelerating."""
        self.command(Cmd.JOG_STOP, **self._target(joint, teleop))

    # coordinated moves

    def _pose(self, p: PoseLike, what: str) -> tuple:
        if isinstance(p, Mapping):
            base = list(self._queue_end())
            for k, v in p.items():
                base[_axis_index(k)] = float(v)
            return tuple(base)
        vals = tuple(float(v) for v in p)
        if len(vals) != 9:
            raise ValueError(f"{what} needs 9 values (X Y Z A B C U V W) "
                             f"or a mapping of axis letters, got "
                             f"{len(vals)} values")
        return vals

    def _queue_end(self) -> Pose:
        if self._last_end is not None:
            head, tail, _ = self._ch.queue_state()
            if head != tail:
                return self._last_end
        st = self._ch.status()
        if st["queue_depth"] == 0 or self._last_end is None:
            return Pose(*st["carte_pos_cmd"])
        return self._last_end

    def _move_fields(self, vel: float, ini_maxvel: Optional[float],
                     acc: Optional[float], id: Optional[int]) -> dict:
        if id is None:
            id = self._next_id
        self._next_id = id + 1
        # 0: motmod uses its SET_VEL_LIMIT / SET_ACC values
        return {"vel": vel, "ini_maxvel": ini_maxvel or 0.0,
                "acc": acc or 0.0, "id": id}

    def set_line(self, end: PoseLike, vel: float, *,
                 acc: Optional[float] = None,
                 ini_maxvel: Optional[float] = None,
                 rapid: bool = False, id: Optional[int] = None,
                 jerk: float = 0.0, flags: int = 0, line: int = 0) -> int:
        """Queue a straight move to ``end`` (9 values, or a mapping of
        axis letters: the other axes stay where the last queued move
        ends).  ``vel`` is the requested path velocity; ``ini_maxvel`` the
        velocity never exceeded even with overrides (default: the
        machine's velocity limit, SET_VEL_LIMIT); ``acc`` the
        path acceleration (default: SET_ACC).  ``rapid``: a traverse (the
        rapid scale applies).  Returns the motion id."""
        p = self._pose(end, "SET_LINE end")
        f = self._move_fields(vel, ini_maxvel, acc, id)
        self.command(Cmd.SET_LINE, pos=p, jerk=jerk, ival=flags, line=line,
                     motion_type=int(MotionType.TRAVERSE if rapid
                                     else MotionType.FEED), **f)
        self._last_end = Pose(*p)
        return f["id"]

    def set_circle(self, end: PoseLike, center: Sequence[float],
                   normal: Sequence[float], vel: float, *, turn: int = 0,
                   acc: Optional[float] = None,
                   ini_maxvel: Optional[float] = None,
                   id: Optional[int] = None, line: int = 0) -> int:
        """Queue an arc or helix to ``end`` around the axis through
        ``center`` along ``normal`` (counterclockwise seen from the tip of
        normal), with ``turn`` extra full turns.  Returns the motion id."""
        p = self._pose(end, "SET_CIRCLE end")
        f = self._move_fields(vel, ini_maxvel, acc, id)
        self.command(Cmd.SET_CIRCLE, pos=p, center=tuple(center),
                     normal=tuple(normal), turn=turn, line=line,
                     motion_type=int(MotionType.ARC), **f)
        self._last_end = Pose(*p)
        return f["id"]

    def probe(self, end: PoseLike, vel: float, *,
              acc: Optional[float] = None,
              ini_maxvel: Optional[float] = None, away: bool = False,
              error_if_no_contact: bool = True,
              id: Optional[int] = None, line: int = 0) -> int:
        """Queue a probe move toward ``end``: it stops and records the
        position (status().probed_pos) when motion.probe-input trips (goes
        true; false with ``away``).  Without contact the move ends at
        ``end`` and, with ``error_if_no_contact``, motmod reports an
        error.  Returns the motion id."""
        p = self._pose(end, "PROBE end")
        f = self._move_fields(vel, ini_maxvel, acc, id)
        ptype = (ProbeFlag.AWAY if away else 0) | \
            (0 if error_if_no_contact else ProbeFlag.NO_ERROR)
        self.command(Cmd.PROBE, pos=p, ival=int(ptype), line=line,
                     motion_type=int(MotionType.PROBING), **f)
        self._last_end = Pose(*p)
        return f["id"]

    def clear_probe_flag(self) -> None:
        self.command(Cmd.CLEAR_PROBE_FLAG)

    # the move queue

    def _check_queue(self) -> None:
        """Raise QueueRejected when motmod refused a queued record since
        the last check (once per rejection)."""
        try:
            n, code, id, line, reason = self._ch.queue_error()
        except _channel.ChannelError as e:
            raise MotionError(str(e)) from None
        if n != self._q_epoch:
            self._q_epoch = n
            self._last_end = None
            try:
                name = Cmd(code).name
            except ValueError:
                name = f"command {code}"
            raise QueueRejected(name, reason or "no reason given", id, line)

    def queue(self, cmd: Cmd, timeout: Optional[float] = None,
              **fields: Any) -> None:
        """Write one record (fields of mot_command_t) into the move queue
        and return at once; blocks only while the queue is full (stepping
        the servo thread when the client steps).  Raises QueueRejected
        for an earlier queued record that motmod refused."""
        cmd = Cmd(cmd)
        ch = self._ch
        self._check_queue()
        with _send_lock:
            try:
                while True:
                    r = ch.push(int(cmd), fields, self._q_epoch)
                    if r == 0:
                        return
                    if r == 1:
                        def room():
                            self._check_queue()
                            return ch.queue_free() > 0
                        self._wait(room, timeout,
                                   f"{cmd.name}: room in the move queue (is "
                                   "motion-command-handler in a running "
                                   "thread?)")
                    else:
                        def lockable() -> bool:
                            if ch.try_lock() != 0:
                                return False
                            ch.unlock()
                            return True
                        self._wait(lockable, timeout,
                                   f"{cmd.name}: the channel lock (held by "
                                   "another process)")
            except _channel.ChannelError as e:
                raise MotionError(str(e)) from None

    def queue_free(self) -> int:
        """Places free in the move queue (of MOVE_QUEUE_SIZE)."""
        return self._ch.queue_free()

    def queue_pending(self) -> int:
        """Records written to the move queue and not yet taken by
        motmod."""
        head, tail, _ = self._ch.queue_state()
        return (head - tail) & 0xFFFFFFFF

    def queue_line(self, end: PoseLike, vel: float, *,
                   acc: Optional[float] = None,
                   ini_maxvel: Optional[float] = None,
                   rapid: bool = False, id: Optional[int] = None,
                   line: int = 0, jerk: float = 0.0, flags: int = 0) -> int:
        """Like :meth:`set_line`, through the move queue: returns at once
        (blocks only while the queue is full).  ``line`` is the program
        line (motion.program-line while the move runs).  Returns the motion
        id."""
        p = self._pose(end, "SET_LINE end")
        f = self._move_fields(vel, ini_maxvel, acc, id)
        self.queue(Cmd.SET_LINE, pos=p, jerk=jerk, ival=flags, line=line,
                   motion_type=int(MotionType.TRAVERSE if rapid
                                   else MotionType.FEED), **f)
        self._last_end = Pose(*p)
        return f["id"]

    def queue_circle(self, end: PoseLike, center: Sequence[float],
                     normal: Sequence[float], vel: float, *, turn: int = 0,
                     acc: Optional[float] = None,
                     ini_maxvel: Optional[float] = None,
                     id: Optional[int] = None, line: int = 0) -> int:
        """Like :meth:`set_circle`, through the move queue."""
        p = self._pose(end, "SET_CIRCLE end")
        f = self._move_fields(vel, ini_maxvel, acc, id)
        self.queue(Cmd.SET_CIRCLE, pos=p, center=tuple(center),
                   normal=tuple(normal), turn=turn, line=line,
                   motion_type=int(MotionType.ARC), **f)
        self._last_end = Pose(*p)
        return f["id"]

    def queue_probe(self, end: PoseLike, vel: float, *,
                    acc: Optional[float] = None,
                    ini_maxvel: Optional[float] = None, away: bool = False,
                    error_if_no_contact: bool = True,
                    id: Optional[int] = None, line: int = 0) -> int:
        """Like :meth:`probe`, through the move queue."""
        p = self._pose(end, "PROBE end")
        f = self._move_fields(vel, ini_maxvel, acc, id)
        ptype = (ProbeFlag.AWAY if away else 0) | \
            (0 if error_if_no_contact else ProbeFlag.NO_ERROR)
        self.queue(Cmd.PROBE, pos=p, ival=int(ptype), line=line,
                   motion_type=int(MotionType.PROBING), **f)
        self._last_end = Pose(*p)
        return f["id"]

    def _sync_move(self, cmd: Cmd, end: PoseLike, pitch: float,
                   vel: float, spindle: int, acc: Optional[float],
                   ini_maxvel: Optional[float], id: Optional[int],
                   line: int, queued: bool) -> int:
        p = self._pose(end, f"{cmd.name} end")
        f = self._move_fields(vel, ini_maxvel, acc, id)
        args = dict(pos=p, pitch=pitch, index=spindle, line=line,
                    motion_type=int(MotionType.FEED), **f)
        if queued:
            self.queue(cmd, **args)
        else:
            self.command(cmd, **args)
        if cmd == Cmd.SPINDLE_SYNC_LINE:
            self._last_end = Pose(*p)
        return f["id"]

    def queue_thread(self, end: PoseLike, pitch: float, *,
                     vel: Optional[float] = None, spindle: int = 0,
                     acc: Optional[float] = None,
                     ini_maxvel: Optional[float] = None,
                     id: Optional[int] = None, line: int = 0) -> int:
        """A spindle-synchronized line (G33) to ``end``: ``pitch`` units
        of path per spindle revolution, starting at the spindle's index.
        ``vel`` bounds the path velocity (default: the velocity limit).
        Needs the spindle turning (queue_spindle_on / spindle_on)."""
        return self._sync_move(Cmd.SPINDLE_SYNC_LINE, end, pitch,
                               vel or self._vel_limit(), spindle, acc,
                               ini_maxvel, id, line, True)

    def queue_rigid_tap(self, end: PoseLike, pitch: float, *,
                        vel: Optional[float] = None, spindle: int = 0,
                        acc: Optional[float] = None,
                        ini_maxvel: Optional[float] = None,
                        id: Optional[int] = None, line: int = 0) -> int:
        """Rigid tapping (G33.1): in to ``end`` following the spindle with
        ``pitch`` per revolution, the spindle reverses, the tool follows it
        back out to the start."""
        return self._sync_move(Cmd.RIGID_TAP, end, pitch,
                               vel or self._vel_limit(), spindle, acc,
                               ini_maxvel, id, line, True)

    def _vel_limit(self) -> float:
        v = self._ch.status()["vel_limit"]
        if not v > 0:
            raise ValueError("give vel= (no SET_VEL_LIMIT was sent)")
        return v

    def queue_dout(self, index: int, value: bool) -> None:
        """Synchronized digital output (M62/M63): changes when the next
        queued move starts."""
        self.queue(Cmd.SET_DOUT, index=index, ival=1 if value else 0, sync=1)

    def queue_aout(self, index: int, value: float) -> None:
        """Synchronized analog output (M67): changes when the next queued
        move starts."""
        self.queue(Cmd.SET_AOUT, index=index, value=value, sync=1)

    def queue_term_cond(self, cond: Union[TermCond, int],
                        tolerance: float = 0.0,
                        cam_tolerance: float = 0.0) -> None:
        """:meth:`set_term_cond` in order with the queued moves (G61,
        G61.1, G64 P Q)."""
        self.queue(Cmd.SET_TERM_COND, ival=int(cond), tolerance=tolerance,
                   value=cam_tolerance)

    def queue_spindle_on(self, speed: float, spindle: int = 0, **css: Any
                         ) -> None:
        """:meth:`spindle_on` in order with the queued moves (taken when
        the moves before it are in the planner, as the reference's M3/M4
        are); the next feed move waits for spindle.N.at-speed."""
        self.queue(Cmd.SPINDLE_ON, **_spindle_on_fields(speed, spindle,
                                                        **css))

    def queue_spindle_off(self, spindle: int = 0) -> None:
        """:meth:`spindle_off` in order with the queued moves."""
        self.queue(Cmd.SPINDLE_OFF, index=spindle)

    def set_teleop_vector(self, vel: PoseLike) -> None:
        """Teleop mode: move with this velocity of each axis (9 values or
        a mapping of axis letters, others 0)."""
        if isinstance(vel, Mapping):
            v = [0.0] * 9
            for k, x in vel.items():
                v[_axis_index(k)] = float(x)
        else:
            v = [float(x) for x in vel]
            if len(v) != 9:
                raise ValueError("the teleop vector needs 9 values")
        self.command(Cmd.SET_TELEOP_VECTOR, pos=tuple(v))

    # configuration

    def set_num_joints(self, n: int) -> None:
        self.command(Cmd.SET_NUM_JOINTS, ival=n)

    def set_joint_limits(self, joint: int, min_limit: float,
                         max_limit: float) -> None:
        """Soft limits of a joint (MIN_LIMIT, MAX_LIMIT)."""
        self.command(Cmd.SET_JOINT_POSITION_LIMITS, joint=joint,
                     min_limit=min_limit, max_limit=max_limit)

    def set_joint_max_velocity(self, joint: int, vel: float) -> None:
        self.command(Cmd.SET_JOINT_VEL_LIMIT, joint=joint, vel=vel)

    def set_joint_max_acceleration(self, joint: int, acc: float) -> None:
        self.command(Cmd.SET_JOINT_ACC_LIMIT, joint=joint, acc=acc)

    def set_joint_max_jerk(self, joint: int, jerk: float) -> None:
        """Jerk limit (> 0 also selects jerk-limited profiles)."""
        self.command(Cmd.SET_JOINT_JERK_LIMIT, joint=joint, jerk=jerk)

    def set_joint_ferror(self, joint: int, min_ferror: float,
                         max_ferror: float) -> None:
        """Following error limits: min_ferror at rest, max_ferror (FERROR)
        at the joint's maximum velocity, in between by speed."""
        self.command(Cmd.SET_JOINT_MIN_FERROR, joint=joint,
                     value=min_ferror)
        self.command(Cmd.SET_JOINT_MAX_FERROR, joint=joint,
                     value=max_ferror)

    def set_joint_backlash(self, joint: int, backlash: float) -> None:
        self.command(Cmd.SET_JOINT_BACKLASH, joint=joint, value=backlash)

    def set_joint_motor_offset(self, joint: int, offset: float) -> None:
        self.command(Cmd.SET_JOINT_MOTOR_OFFSET, joint=joint, value=offset)

    def set_joint_homing(self, joint: int, **keys: Any) -> None:
        """Homing parameters from [JOINT_n] keys (case-insensitive):
        HOME, HOME_OFFSET, HOME_SEARCH_VEL, HOME_LATCH_VEL,
        HOME_FINAL_VEL, HOME_SEQUENCE, HOME_USE_INDEX, HOME_IGNORE_LIMITS,
        HOME_IS_SHARED, HOME_INDEX_NO_ENCODER_RESET, VOLATILE_HOME,
        HOME_ABSOLUTE_ENCODER (0, 1, 2), HOME_NO_FINAL_MOVE,
        HOME_NO_REHOME, HOME_UNLOCK_FIRST."""
        self.command(Cmd.SET_JOINT_HOMING_PARAMS, joint=joint,
                     **homing_fields(keys, f"joint {joint}"))

    def clear_joint_comp(self, joint: int) -> None:
        self.command(Cmd.CLEAR_JOINT_COMP, joint=joint)

    def set_joint_comp(self, joint: int, entries: Iterable[Sequence[float]]
                       ) -> None:
        """Replace the screw compensation table of a joint by ``entries``
        of (nominal, forward, reverse) with increasing nominal."""
        self.clear_joint_comp(joint)
        for k, e in enumerate(entries):
            nominal, fwd, rev = (float(x) for x in e)
            try:
                self.command(Cmd.SET_JOINT_COMP, joint=joint,
                             comp=(nominal, fwd, rev))
            except Rejected as r:
                raise Rejected(r.command, f"entry {k + 1} ({nominal:g}, "
                               f"{fwd:g}, {rev:g}): {r.reason}") from None

    def load_comp_file(self, joint: int, path: str, type: int = 0) -> int:
        """Read a compensation file (COMP_FILE, COMP_FILE_TYPE of
        [JOINT_n]) and send it; returns the number of entries.  A bad
        file raises before anything is sent, naming the line."""
        entries = screwcomp.read_comp_file(path, type)
        self.set_joint_comp(joint, entries)
        return len(entries)

    def set_axis_limits(self, axis: JointOrAxis, min_limit: float,
                        max_limit: float) -> None:
        self.command(Cmd.SET_AXIS_POSITION_LIMITS, axis=_axis(axis),
                     min_limit=min_limit, max_limit=max_limit)

    def set_axis_max_velocity(self, axis: JointOrAxis, vel: float) -> None:
        self.command(Cmd.SET_AXIS_VEL_LIMIT, axis=_axis(axis), vel=vel)

    def set_axis_max_acceleration(self, axis: JointOrAxis,
                                  acc: float) -> None:
        self.command(Cmd.SET_AXIS_ACC_LIMIT, axis=_axis(axis), acc=acc)

    def set_axis_max_jerk(self, axis: JointOrAxis, jerk: float) -> None:
        self.command(Cmd.SET_AXIS_JERK_LIMIT, axis=_axis(axis), jerk=jerk)

    def set_vel(self, vel: float, ini_maxvel: Optional[float] = None
                ) -> None:
        """Default requested velocity of coordinated moves."""
        self.command(Cmd.SET_VEL, vel=vel,
                     ini_maxvel=vel if ini_maxvel is None else ini_maxvel)

    def set_vel_limit(self, vel: float) -> None:
        """Velocity limit of every coordinated move."""
        self.command(Cmd.SET_VEL_LIMIT, vel=vel)

    def set_acc(self, acc: float) -> None:
        """Default acceleration of coordinated moves."""
        self.command(Cmd.SET_ACC, acc=acc)

    def set_term_cond(self, cond: Union[TermCond, int],
                      tolerance: float = 0.0,
                      cam_tolerance: float = 0.0) -> None:
        """End of coordinated moves: STOP (G61.1), EXACT (G61), BLEND
        with ``tolerance`` (G64 P) and ``cam_tolerance`` (G64 Q).  For
        moves already in the move queue use :meth:`queue_term_cond`."""
        self.command(Cmd.SET_TERM_COND, ival=int(cond), tolerance=tolerance,
                     value=cam_tolerance)

    def set_tool_offset(self, offset: PoseLike) -> None:
        """The tool offset (9 values or a mapping of axis letters, others
        0)."""
        if isinstance(offset, Mapping):
            v = [0.0] * 9
            for k, x in offset.items():
                v[_axis_index(k)] = float(x)
        else:
            v = [float(x) for x in offset]
            if len(v) != 9:
                raise ValueError("the tool offset needs 9 values")
        self.command(Cmd.SET_OFFSET, pos=tuple(v))

    def set_profile(self, profile: Union[Profile, str, int]) -> None:
        """Profile of the free and teleop planners: "trapezoid" or
        "jerk"."""
        if isinstance(profile, str):
            try:
                profile = Profile[profile.upper()]
            except KeyError:
                raise ValueError(f"unknown profile {profile!r} (trapezoid "
                                 "or jerk)") from None
        self.command(Cmd.SET_PROFILE, ival=int(profile))

    def set_dout(self, index: int, value: bool, sync: bool = False
                 ) -> None:
        """Set motion.digital-out-NN now (M64/M65), or with ``sync`` when
        the next queued move starts (M62/M63; see also
        :meth:`queue_dout`)."""
        self.command(Cmd.SET_DOUT, index=index, ival=1 if value else 0,
                     sync=1 if sync else 0)

    def set_aout(self, index: int, value: float, sync: bool = False
                 ) -> None:
        """Set motion.analog-out-NN now (M68), or with ``sync`` when the
        next queued move starts (M67; see also :meth:`queue_aout`)."""
        self.command(Cmd.SET_AOUT, index=index, value=value,
                     sync=1 if sync else 0)

    # feed control

    def set_feed_hold_enable(self, on: bool = True) -> None:
        """M53: motion.feed-hold stops coordinated motion only while
        enabled (the default)."""
        self.command(Cmd.SET_FEED_HOLD_ENABLE, ival=1 if on else 0)

    def set_adaptive_feed_enable(self, on: bool = True) -> None:
        """M52: motion.adaptive-feed scales the feed only while enabled
        (off by default)."""
        self.command(Cmd.SET_ADAPTIVE_FEED_ENABLE, ival=1 if on else 0)

    def set_linear_units(self, units: Union[str, float]) -> None:
        """The machine's length unit ([TRAJ]LINEAR_UNITS): "mm", "inch"
        (also "in", "cm", "metric", "imperial") or millimetres per unit;
        the mm and inch feed pins need it."""
        if isinstance(units, str):
            try:
                mm = LINEAR_UNITS[units.strip().lower()]
            except KeyError:
                raise ValueError(f"unknown linear units {units!r} (mm, "
                                 "inch, cm or a number of mm)") from None
        else:
            mm = float(units)
        self.command(Cmd.SET_LINEAR_UNITS, value=mm)

    # spindles

    def spindle_on(self, speed: float, spindle: int = 0, *,
                   css: float = 0.0, css_axis: JointOrAxis = "x",
                   css_max: float = 0.0) -> None:
        """Turn a spindle on at ``speed`` rpm (negative: reverse, M4).
        With ``css`` (surface speed, units per minute) the speed follows
        the radius on ``css_axis`` up to ``css_max`` rpm (G96).  The next
        feed move waits for spindle.N.at-speed."""
        self.command(Cmd.SPINDLE_ON, **_spindle_on_fields(
            speed, spindle, css=css, css_axis=css_axis, css_max=css_max))

    def spindle_off(self, spindle: int = 0) -> None:
        """Stop a spindle (M5): speed 0, brake on."""
        self.command(Cmd.SPINDLE_OFF, index=spindle)

    def spindle_increase(self, spindle: int = 0, step: float = 0.0) -> None:
        """Faster by ``step`` rpm (0: by 10 %)."""
        self.command(Cmd.SPINDLE_INCREASE, index=spindle, value=step)

    def spindle_decrease(self, spindle: int = 0, step: float = 0.0) -> None:
        """Slower by ``step`` rpm (0: by 10 %); refused if it would stop."""
        self.command(Cmd.SPINDLE_DECREASE, index=spindle, value=step)

    def spindle_orient(self, angle: float, mode: int = 0, spindle: int = 0,
                       *, wait: bool = False,
                       timeout: Optional[float] = None) -> None:
        """M19: stop the spindle and ask the drive to orient it to
        ``angle`` (spindle.N.orient, -angle, -mode).  With ``wait``, wait
        until spindle.N.is-oriented (locked, brake on); an orient fault
        raises MotionError."""
        self.command(Cmd.SPINDLE_ORIENT, index=spindle, value=angle,
                     ival=mode)
        if wait:
            self.wait_oriented(spindle, timeout)

    def wait_oriented(self, spindle: int = 0,
                      timeout: Optional[float] = None) -> Status:
        """Wait for the end of an orient; raises MotionError on an orient
        fault."""
        def done(d: dict) -> bool:
            sp = d["spindles"][spindle]
            if sp["orient_state"] == 3:
                self._pull_messages()
                raise MotionError(f"spindle {spindle} orient failed "
                                  f"(orient-fault {sp['orient_fault']})")
            return sp["orient_state"] == 2
        return self._wait_raw(done, timeout, f"spindle {spindle} oriented")

    def spindle_brake(self, engage: bool = True, spindle: int = 0) -> None:
        """Engage (refused while it turns) or release the brake."""
        self.command(Cmd.SPINDLE_BRAKE_ENGAGE if engage
                     else Cmd.SPINDLE_BRAKE_RELEASE, index=spindle)

    def spindle_sync_line(self, end: PoseLike, pitch: float, *,
               vel: Optional[float] = None, spindle: int = 0,
               id: Optional[int] = None, line: int = 0) -> int:
        """G33 (:meth:`queue_thread`) through the command mailbox (waits
        for motmod's answer)."""
        return self._sync_move(Cmd.SPINDLE_SYNC_LINE, end, pitch,
                               vel or self._vel_limit(), spindle, None,
                               None, id, line, False)

    def rigid_tap(self, end: PoseLike, pitch: float, *,
                  vel: Optional[float] = None, spindle: int = 0,
                  id: Optional[int] = None, line: int = 0) -> int:
        """:meth:`queue_rigid_tap` through the command mailbox."""
        return self._sync_move(Cmd.RIGID_TAP, end, pitch,
                               vel or self._vel_limit(), spindle, None,
                               None, id, line, False)

    def configure(self, joints: Sequence[Mapping[str, Any]] = (),
                  axes: Optional[Mapping[str, Mapping[str, Any]]] = None,
                  traj: Optional[Mapping[str, Any]] = None) -> None:
        """Send the configuration of a whole machine from INI-like keys.

        ``joints``: one mapping per joint with keys of [JOINT_n]
        (MIN_LIMIT, MAX_LIMIT, MAX_VELOCITY, MAX_ACCELERATION, MAX_JERK,
        FERROR, MIN_FERROR, BACKLASH, COMP_FILE, COMP_FILE_TYPE and the
        homing keys of :meth:`set_joint_homing`; TYPE is accepted and not
        used); also sets the number of joints.  ``axes``: axis letter ->
        keys of [AXIS_L] (MIN_LIMIT, MAX_LIMIT, MAX_VELOCITY,
        MAX_ACCELERATION, MAX_JERK).  ``traj``:
        keys of [TRAJ] (MAX_LINEAR_VELOCITY or MAX_VELOCITY,
        DEFAULT_LINEAR_VELOCITY, MAX_LINEAR_ACCELERATION or
        MAX_ACCELERATION).  Unknown keys raise ValueError before anything
        is sent."""
        plans: list[tuple[tuple[int, ...], Plan]] = [
            ((j,), joint_plan(j, keys)) for j, keys in enumerate(joints)]
        plans += [((_axis(k),), axis_plan(k, v))
                  for k, v in (axes or {}).items()]
        plans.append(((), traj_plan(traj or {})))
        if joints:
            self.set_num_joints(len(joints))
        for first, plan in plans:
            for fn, args, kwargs in plan:
                getattr(self, fn)(*first, *args, **kwargs)

    def configure_ini(self, path: str) -> None:
        """Send the motion configuration of an INI file: [KINS]JOINTS,
        [JOINT_n], [AXIS_L] and [TRAJ] (see :mod:`halsdk.motion.ini`).
        The whole file is checked first: a bad value raises
        MotionIniError naming the file and line, and nothing is sent."""
        config = read_motion_ini(path)
        self.configure(config.joints, config.axes, config.traj)

    # ------------------------------------------------------------ status

    def _pull_messages(self) -> None:
        try:
            msgs, self._msg_read, lost = self._ch.messages(self._msg_read)
        except _channel.ChannelError as e:
            raise MotionError(str(e)) from None
        if lost:
            self._pending.append(f"({lost} motion message(s) lost: the "
                                 "ring overflowed)")
        self._pending.extend(msgs)

    def status(self) -> Status:
        """A consistent snapshot of the motion controller."""
        try:
            d = self._ch.status()
        except _channel.ChannelError as e:
            raise MotionError(str(e)) from None
        self._pull_messages()
        return Status.from_dict(d, tuple(self._pending))

    def status_dict(self) -> dict:
        """The same snapshot as :meth:`status` as the plain dict motmod's
        channel gives (the keys of ``channel.h``; joints, axes and spindles
        as lists of dicts, joint flags as raw bits): ten times cheaper,
        for a caller that reads it every cycle (the task's status)."""
        try:
            d = self._ch.status()
        except _channel.ChannelError as e:
            raise MotionError(str(e)) from None
        self._pull_messages()
        return d

    def messages_waiting(self) -> bool:
        """True when motmod posted a message that :meth:`errors` has not
        returned yet (cheap: no status snapshot)."""
        if self._pending:
            return True
        try:
            return self._ch.msg_count() != self._msg_read
        except _channel.ChannelError as e:
            raise MotionError(str(e)) from None

    def errors(self) -> list[str]:
        """The realtime error messages posted since the last call."""
        self._pull_messages()
        out, self._pending = self._pending, []
        return out

    def wait_for(self, predicate: Callable[[Status], bool],
                 timeout: Optional[float] = None,
                 what: str = "the condition") -> Status:
        """Wait until ``predicate(status)`` is true; returns that
        status."""
        def cond():
            st = self.status()
            return st if predicate(st) else None
        return self._wait(cond, timeout, what)

    def _wait_raw(self, predicate: Callable[[dict], bool],
                  timeout: Optional[float], what: str) -> Status:
        """wait_for() with a predicate on the raw status dict (cheaper
        per cycle); returns the Status of the cycle it became true."""
        def cond():
            try:
                d = self._ch.status()
            except _channel.ChannelError as e:
                raise MotionError(str(e)) from None
            if predicate(d):
                self._pull_messages()
                return Status.from_dict(d, tuple(self._pending))
            return None
        return self._wait(cond, timeout, what)

    def wait_inpos(self, timeout: Optional[float] = None) -> Status:
        """Wait until nothing moves (jogs, homing, coordinated moves)."""
        return self._wait_raw(
            lambda d: d["in_position"] and d["queue_depth"] == 0
            and not d["homing"], timeout, "motion coming to rest")

    def wait_done(self, timeout: Optional[float] = None) -> Status:
        """Wait until the coordinated queue is empty and everything is at
        rest; raises MotionError if motion got disabled meanwhile."""
        self._check_queue()
        head = self._ch.queue_state()[0]

        def done(d: dict) -> bool:
            if d["queue_err_count"] != self._q_epoch:
                self._check_queue()
            if not d["enabled"]:
                self._pull_messages()
                raise MotionError(
                    "motion was disabled while waiting for the moves to "
                    "finish" + _because(self._pending))
            return (d["queue_taken"] == head and d["in_position"]
                    and d["queue_depth"] == 0 and not d["homing"])
        return self._wait_raw(done, timeout, "the end of the moves")

    def wait_input(self, kind: str, index: int,
                   mode: Union[InputWait, int, str] = InputWait.IMMEDIATE,
                   timeout: Optional[float] = None
                   ) -> Union[bool, float, None]:
        """M66: wait for motion.digital-in-NN (``kind`` "digital") or read
        motion.analog-in-NN ("analog").  ``mode``: IMMEDIATE (the value
        now), RISE, FALL (an edge after the call), HIGH, LOW (the level;
        true at once if it already holds) — digital inputs only.  Returns
        the input's value in the cycle the condition held, or None when
        ``timeout`` (seconds, simulated when stepping) passed first (the
        reference's -1).  The inputs are read from the status, every servo
        cycle when the client steps."""
        if isinstance(mode, str):
            try:
                mode = InputWait[mode.upper()]
            except KeyError:
                raise ValueError(f"unknown wait mode {mode!r} (immediate, "
                                 "rise, fall, high, low)") from None
        mode = InputWait(mode)
        kind = kind.lower()
        if kind not in ("digital", "analog"):
            raise ValueError(f"input kind must be 'digital' or 'analog', "
                             f"got {kind!r}")
        d = self._ch.status()
        n = d["num_dio"] if kind == "digital" else d["num_aio"]
        if not 0 <= index < n:
            raise ValueError(f"{kind} input {index} does not exist "
                             f"(num_{'dio' if kind == 'digital' else 'aio'}"
                             f"={n})")
        if kind == "analog":
            if mode != InputWait.IMMEDIATE:
                raise ValueError("analog inputs can only be read "
                                 "(mode IMMEDIATE)")
            return d["ain"][index]

        def bit(d: dict) -> bool:
            return bool((d["din"] >> index) & 1)

        last = [bit(d)]
        if mode == InputWait.IMMEDIATE:
            return last[0]
        if timeout is None:
            timeout = self.timeout
        if timeout < 0 or not math.isfinite(timeout):
            raise ValueError(f"timeout must be >= 0 seconds, got {timeout}")

        def cond():
            v = bit(self._ch.status())
            prev, last[0] = last[0], v
            if mode == InputWait.HIGH:
                return v or None
            if mode == InputWait.LOW:
                return (not v) or None
            if mode == InputWait.RISE:
                return (v and not prev) or None
            return (prev and not v) or None

        if mode in (InputWait.HIGH, InputWait.LOW) and \
                last[0] == (mode == InputWait.HIGH):
            return last[0]
        if timeout == 0:
            return None
        try:
            self._wait(cond, timeout, f"digital input {index}")
        except MotionTimeout:
            return None
        return last[0]

    def wait_homed(self, joints: Optional[Iterable[int]] = None,
                   timeout: Optional[float] = None) -> Status:
        """Wait until the joints (default: all in use) are homed; raises
        MotionError when homing stops without that."""
        want = None if joints is None else list(joints)
        seen_homing = [False]

        def homed(d: dict) -> bool:
            js = d["joints"][:d["num_joints"]]
            if want is not None:
                try:
                    js = [js[j] for j in want]
                except IndexError:
                    raise ValueError(f"wait_homed: joints {want} are not "
                                     f"all in use (num_joints="
                                     f"{d['num_joints']})") from None
            if all(j["flags"] & JOINT_HOMED for j in js):
                return True
            if d["homing"]:
                seen_homing[0] = True
            elif seen_homing[0] or not d["enabled"]:
                self._pull_messages()
                raise MotionError("homing stopped before all joints were "
                                  "homed" + _because(self._pending))
            return False
        return self._wait_raw(homed, timeout, "homing")

    @property
    def mode(self) -> Mode:
        return self.status().mode


def _spindle_on_fields(speed: float, spindle: int = 0, *,
                       css: float = 0.0, css_axis: JointOrAxis = "x",
                       css_max: float = 0.0) -> dict:
    return dict(index=spindle, vel=speed, value=css, ival=_axis(css_axis),
                offset=css_max)


def _because(errors: Sequence[str]) -> str:
    return (": " + "; ".join(errors)) if errors else ""


def _axis(axis: JointOrAxis) -> int:
    return _axis_index(axis) if isinstance(axis, str) else int(axis)


def _attached() -> bool:
    """This process is attached to a HAL instance already."""
    return Hal.current() is not None
