"""LinuxCNC's Python ``linuxcnc`` module, on the channels of ``halsdk run``.

A script written against the reference's documented Python interface
runs unchanged against a machine started with ``halsdk run MACHINE.ini``
in another shell, once ``import linuxcnc`` finds this module (put
:func:`halsdk.compat.pythonpath` on ``PYTHONPATH``; ``HALSDK_INSTANCE``
names the machine's instance when it is not the default one)::

    import linuxcnc
    s = linuxcnc.stat()
    c = linuxcnc.command()
    c.state(linuxcnc.STATE_ESTOP_RESET)
    c.wait_complete()
    s.poll()
    print(s.task_state, s.position[:3])

* :class:`stat`: ``poll()`` copies one consistent snapshot of the status
  channel; the attributes (the reference's names, types and tuple
  lengths) read that copy.  Before the first poll they read zeros, as the
  reference's do.
* :class:`command`: each method checks its arguments as the reference's
  C extension does (TypeError, ValueError with its words) and sends the
  command with the next serial number; it does not wait for the task.
  :meth:`command.wait_complete` waits for the last command sent.
* :class:`error_channel`: ``poll()`` gives the next ``(kind, text)``
  message or None.
* :class:`ini`: ``find`` and ``findall`` over an INI file.

Where this differs from the reference is listed in ``docs/compat.md``.
It reads the task's channels (:mod:`halsdk.channels`);
``halsdk/compat/pypath/linuxcnc.py`` makes ``import linuxcnc`` this
module.
"""

from __future__ import annotations

import operator
import os
import sys
import threading
from collections import namedtuple
from typing import Any, NoReturn, Optional

import halsdk
from halsdk.channels.cmdclient import CommandClient
from halsdk.channels.constants import (
    AUTO_FORWARD,
    AUTO_PAUSE,
    AUTO_RESUME,
    AUTO_REVERSE,
    AUTO_RUN,
    AUTO_STEP,
    EXEC_DONE,
    EXEC_ERROR,
    EXEC_WAITING_FOR_DELAY,
    EXEC_WAITING_FOR_IO,
    EXEC_WAITING_FOR_MOTION,
    EXEC_WAITING_FOR_MOTION_AND_IO,
    EXEC_WAITING_FOR_MOTION_QUEUE,
    EXEC_WAITING_FOR_SPINDLE_ORIENTED,
    EXEC_WAITING_FOR_SYSTEM_CMD,
    JOG_CONTINUOUS,
    JOG_INCREMENT,
    JOG_STOP,
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
from halsdk.channels.errors import ChannelError, ChannelGone
from halsdk.channels.shmchannel import BLOCK_NAME as _BLOCK_NAME
from halsdk.channels.shmchannel import ErrorReader, StatusReader
from halsdk.channels.statuslayout import STATUS_SIZE as _STATUS_SIZE
from halsdk.channels.statuslayout import Snapshot
from halsdk.errors import HalError, NotFoundError
from halsdk.ini import IniFile

__all__ = [
    "ANGULAR", "AUTO_FORWARD", "AUTO_PAUSE", "AUTO_RESUME", "AUTO_REVERSE",
    "AUTO_RUN", "AUTO_STEP", "BRAKE_ENGAGE", "BRAKE_RELEASE",
    "DEBUG_CONFIG", "DEBUG_INTERP", "DEBUG_INTERP_LIST", "DEBUG_MOTION_TIME",
    "DEBUG_NML", "DEBUG_OWORD", "DEBUG_PYTHON", "DEBUG_RCS", "DEBUG_REMAP",
    "DEBUG_STATE_TAGS", "DEBUG_TASK_ISSUE", "DEBUG_VERSIONS", "EXEC_DONE",
    "EXEC_ERROR", "EXEC_WAITING_FOR_DELAY", "EXEC_WAITING_FOR_IO",
    "EXEC_WAITING_FOR_MOTION", "EXEC_WAITING_FOR_MOTION_AND_IO",
    "EXEC_WAITING_FOR_MOTION_QUEUE", "EXEC_WAITING_FOR_SPINDLE_ORIENTED",
    "EXEC_WAITING_FOR_SYSTEM_CMD", "FLOOD_OFF", "FLOOD_ON", "INTERP_IDLE",
    "INTERP_PAUSED", "INTERP_READING", "INTERP_WAITING", "JOG_CONTINUOUS",
    "JOG_INCREMENT", "JOG_STOP", "KINEMATICS_BOTH", "KINEMATICS_FORWARD_ONLY",
    "KINEMATICS_IDENTITY", "KINEMATICS_INVERSE_ONLY", "LINEAR", "MAX_AXIS",
    "MAX_JOINTS", "MIST_OFF", "MIST_ON", "MODE_AUTO", "MODE_MANUAL",
    "MODE_MDI", "MOTION_TYPE_ARC", "MOTION_TYPE_FEED",
    "MOTION_TYPE_INDEXROTARY", "MOTION_TYPE_PROBING",
    "MOTION_TYPE_TOOLCHANGE", "MOTION_TYPE_TRAVERSE", "NML_DISPLAY",
    "NML_ERROR", "NML_TEXT", "OPERATOR_DISPLAY", "OPERATOR_ERROR",
    "OPERATOR_TEXT", "PREFIX", "RCS_DONE", "RCS_ERROR", "RCS_EXEC", "SHARE",
    "SPINDLE_CONSTANT", "SPINDLE_DECREASE", "SPINDLE_FORWARD",
    "SPINDLE_INCREASE", "SPINDLE_OFF", "SPINDLE_REVERSE", "STATE_ESTOP",
    "STATE_ESTOP_RESET", "STATE_OFF", "STATE_ON", "TRAJ_MODE_COORD",
    "TRAJ_MODE_FREE", "TRAJ_MODE_TELEOP",
    "command", "error", "error_channel", "ini", "nmlfile", "stat", "tool",
    "version",
]

# ------------------------------------------------------------ constants
# the reference's values (tests/data/linuxcnc/module.json)

ANGULAR, LINEAR = 2, 1
BRAKE_RELEASE, BRAKE_ENGAGE = 0, 1
DEBUG_CONFIG = 2
DEBUG_VERSIONS = 8
DEBUG_TASK_ISSUE = 16
DEBUG_NML = 64
DEBUG_MOTION_TIME = 128
DEBUG_INTERP = 256
DEBUG_RCS = 512
DEBUG_INTERP_LIST = 2048
DEBUG_OWORD = 8192
DEBUG_REMAP = 16384
DEBUG_PYTHON = 32768
DEBUG_STATE_TAGS = 524288
FLOOD_OFF, FLOOD_ON = 0, 1
INTERP_IDLE, INTERP_READING, INTERP_PAUSED, INTERP_WAITING = 1, 2, 3, 4
KINEMATICS_IDENTITY = 1
KINEMATICS_FORWARD_ONLY = 2
KINEMATICS_INVERSE_ONLY = 3
KINEMATICS_BOTH = 4
MAX_AXIS = 9
MAX_JOINTS = 16
MIST_OFF, MIST_ON = 0, 1
MODE_MANUAL, MODE_AUTO, MODE_MDI = 1, 2, 3
MOTION_TYPE_TRAVERSE = 1
MOTION_TYPE_FEED = 2
MOTION_TYPE_ARC = 3
MOTION_TYPE_TOOLCHANGE = 4
MOTION_TYPE_PROBING = 5
MOTION_TYPE_INDEXROTARY = 6
STATE_ESTOP, STATE_ESTOP_RESET, STATE_OFF, STATE_ON = 1, 2, 3, 4

#: where this installation lives (the reference: its install prefix)
PREFIX = sys.prefix
SHARE = os.path.join(sys.prefix, "share")
#: the interface version this module implements, and halsdk's own
version = f"2.9.0~halsdk{halsdk.__version__}"
#: the reference's NML configuration file; halsdk has no NML and reads
#: nothing from it (scripts may set it, as they may on the reference)
nmlfile = os.path.join(SHARE, "linuxcnc", "linuxcnc.nml")

#: what the reference's methods allow in a string (LINELEN - 1 bytes)
_LINE_MAX = 254
_INT_MIN, _INT_MAX = -(1 << 31), (1 << 31) - 1
_DEFAULT_TIMEOUT = 5.0
#: a wait_complete() timeout longer than this waits without a limit
_FOREVER = 1e6


class error(RuntimeError, HalError):  # noqa: N801 - the reference's name
    """The reference's ``linuxcnc.error`` (a RuntimeError); here also a
    :class:`halsdk.HalError`.  Raised when no machine runs, when it is
    gone, and where the reference raises it."""

    def __init__(self, *args: object) -> None:
        HalError.__init__(self, *args)


error.__module__ = "linuxcnc"

#: an entry of ``stat.tool_table`` (the reference's ``tool_result``,
#: also reachable as ``linuxcnc.tool``)
tool = namedtuple("tool_result", [  # type: ignore[name-match]
    "id", "xoffset", "yoffset", "zoffset", "aoffset", "boffset", "coffset",
    "uoffset", "voffset", "woffset", "diameter", "frontangle", "backangle",
    "orientation"])
tool.__module__ = "linuxcnc"
_TOOL_FIELDS = len(tool._fields)

# ------------------------------------------------------------ arguments
# the checks and words of the reference's C extension (PyArg_ParseTuple)


def _count(name: str, args: tuple[Any, ...], kwargs: dict[str, Any],
           least: int, most: int) -> None:
    """TypeError unless ``least`` to ``most`` positional arguments and no
    keyword arguments were given."""
    if kwargs:
        raise TypeError(f"{name}() takes no keyword arguments")
    n = len(args)
    if least <= n <= most:
        return
    if most == 0:
        raise TypeError(f"{name}() takes no arguments ({n} given)")
    if least == most:
        word, limit = "exactly", least
    elif n < least:
        word, limit = "at least", least
    else:
        word, limit = "at most", most
    plural = "argument" if limit == 1 else "arguments"
    raise TypeError(f"function takes {word} {limit} {plural} ({n} given)")


def _int(value: Any) -> int:
    """A C ``int`` argument: anything with ``__index__`` (bool too)."""
    n = operator.index(value)
    if n > _INT_MAX:
        raise OverflowError("signed integer is greater than maximum")
    if n < _INT_MIN:
        raise OverflowError("signed integer is less than minimum")
    return n


def _float(value: Any) -> float:
    """A C ``double`` argument: a float, an int or anything with
    ``__float__`` or ``__index__``."""
    if isinstance(value, float):
        return value
    kind = type(value)
    if hasattr(kind, "__float__"):
        return float(value)
    if hasattr(kind, "__index__"):
        return float(operator.index(value))
    raise TypeError(f"must be real number, not {kind.__name__}")


def _text(value: Any, position: int = 1, function: str = "") -> str:
    """A C string argument (``str`` only)."""
    if not isinstance(value, str):
        where = f"{function}() " if function else ""
        raise TypeError(f"{where}argument {position} must be str, not "
                        f"{type(value).__name__}")
    return value


def _buffer(value: Any) -> bytes:
    """A string argument that may also be bytes, as UTF-8 bytes."""
    if isinstance(value, str):
        return value.encode("utf-8", "surrogateescape")
    if isinstance(value, (bytes, bytearray, memoryview)):
        return bytes(value)
    raise TypeError(f"a bytes-like object is required, not "
                    f"'{type(value).__name__}'")


def _decode(raw: bytes) -> str:
    return raw.decode("utf-8", "replace")


def _cut(text: str, size: int = _LINE_MAX) -> str:
    """``text`` cut to ``size`` bytes of UTF-8 at a character boundary
    (what the reference's fixed-size message buffers keep)."""
    raw = text.encode("utf-8", "surrogateescape")
    if len(raw) <= size:
        return text
    return raw[:size].decode("utf-8", "ignore")


# ------------------------------------------------------------ the link

_lock = threading.Lock()
_hal: Optional[halsdk.Hal] = None


def _instance_name() -> str:
    return os.environ.get("HALSDK_INSTANCE") or "default"


def _attach() -> halsdk.Hal:
    """This process's attachment to the machine's HAL instance (one for
    every object of this module; kept until the process ends)."""
    global _hal
    with _lock:
        if _hal is None:
            try:
                _hal = halsdk.Hal(create=False)
            except HalError as e:
                why = "" if str(e).startswith("no HAL instance") else \
                    f" ({e})"
                raise error(f"no machine is running on HAL instance "
                            f"'{_instance_name()}'{why}: start one with "
                            "`halsdk run MACHINE.ini` (HALSDK_INSTANCE "
                            "names the instance)") from None
        return _hal


def _block() -> tuple[int, int]:
    """The task channel's shared block (address, size)."""
    hal = _attach()
    try:
        return hal.shared_block(_BLOCK_NAME)
    except NotFoundError:
        raise error(f"no machine is running on HAL instance "
                    f"'{hal.instance}' (the instance has no task channel; "
                    "start one with `halsdk run MACHINE.ini`)") from None


def _failed(e: HalError) -> NoReturn:
    raise error(str(e)) from None


# ------------------------------------------------------------ stat

#: what the attributes read before the first poll: zeros, as the reference
_EMPTY = Snapshot(bytes(_STATUS_SIZE))

#: the reference's ``linuxcnc.stat`` attributes (every one but ``poll``
#: and ``tool_table``): the status channel's fields of the same names
_STAT_FIELDS = (
    "acceleration", "active_queue", "actual_position",
    "adaptive_feed_enabled", "ain", "angular_units", "aout", "axis",
    "axis_mask", "block_delete", "call_level", "command", "current_line",
    "current_vel", "cycle_time", "debug", "delay_left", "din",
    "distance_to_go", "dout", "dtg", "echo_serial_number", "enabled",
    "estop", "exec_state", "feed_hold_enabled", "feed_override_enabled",
    "feedrate", "file", "flood", "g5x_index", "g5x_offset", "g92_offset",
    "gcodes", "homed", "ini_filename", "inpos", "input_timeout",
    "interp_state", "interpreter_errcode", "joint", "joint_actual_position",
    "joint_position", "joints", "kinematics_type", "limit", "linear_units",
    "lube", "lube_level", "max_acceleration", "max_velocity", "mcodes",
    "misc_error", "mist", "motion_id", "motion_line", "motion_mode",
    "motion_type", "num_extrajoints", "optional_stop", "paused",
    "pocket_prepped", "position", "probe_tripped", "probe_val",
    "probed_position", "probing", "program_units", "queue", "queue_full",
    "queued_mdi_commands", "rapidrate", "read_line", "rotation_xy",
    "settings", "spindle", "spindles", "state", "task_mode", "task_paused",
    "task_state", "tool_from_pocket", "tool_in_spindle", "tool_offset",
    "velocity",
)


class _Status:
    """A read-only attribute of :class:`stat`: the field of the same name
    in the last snapshot polled (decoded once per snapshot)."""

    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        self.name = name

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self
        return getattr(obj._snap, self.name)

    def __set__(self, obj: Any, value: Any) -> None:
        raise AttributeError("readonly attribute")

    def __delete__(self, obj: Any) -> None:
        raise AttributeError("readonly attribute")


class _ToolTable(_Status):
    """``stat.tool_table``: the snapshot's tool table as ``tool_result``
    entries, converted once each time the table changed."""

    __slots__ = ()

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self
        source = obj._snap.tool_table
        if source is not obj._tools_from:
            obj._tools = tuple(tool._make(t[:_TOOL_FIELDS]) for t in source)
            obj._tools_from = source
        return obj._tools


class stat:  # noqa: N801 - the reference's name
    """The status channel of the running machine (the reference's
    ``linuxcnc.stat``).

    :meth:`poll` copies the task's latest snapshot; every attribute then
    reads that copy, so that the values read between two polls belong
    together.  Creating one never fails (the reference's does not
    either); :meth:`poll` raises :class:`error` when no machine runs or
    it is gone.  Arguments to the constructor (the reference's NML file)
    are accepted and ignored.
    """

    __slots__ = ("_snap", "_reader", "_tools", "_tools_from")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._snap = _EMPTY
        self._reader: Optional[StatusReader] = None
        self._tools: tuple[Any, ...] = ()
        self._tools_from: tuple[Any, ...] = ()

    def poll(self) -> None:
        """Copy the current status (one consistent snapshot).

        :raises error: no machine runs on the instance, or it is gone.
        """
        reader = self._reader
        if reader is None:
            reader = self._open()
        try:
            self._snap = reader.poll()
        except ChannelGone as e:
            self._reader = None         # the next poll looks again
            _failed(e)
        except ChannelError as e:
            _failed(e)

    def _open(self) -> StatusReader:
        address, size = _block()
        try:
            self._reader = StatusReader(address, size)
        except ChannelError as e:
            _failed(e)
        return self._reader

    tool_table = _ToolTable("tool_table")


for _name in _STAT_FIELDS:
    setattr(stat, _name, _Status(_name))
del _name


# ------------------------------------------------------------ command

_STATES = (STATE_ESTOP, STATE_ESTOP_RESET, STATE_OFF, STATE_ON)
_MODES = (MODE_MDI, MODE_MANUAL, MODE_AUTO)
_SPINDLE_OTHERS = (SPINDLE_OFF, SPINDLE_INCREASE, SPINDLE_DECREASE,
                   SPINDLE_CONSTANT)
_JOG_ARGS = {JOG_STOP: (3, "JOG_STOP"), JOG_CONTINUOUS: (4, "JOG_CONTINUOUS"),
             JOG_INCREMENT: (5, "JOG_INCREMENT")}


class _Serial:
    """``command.serial``: read-only, as the reference's."""

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self
        client = obj._client
        return obj._serial if client is None else client.serial

    def __set__(self, obj: Any, value: Any) -> None:
        raise AttributeError("readonly attribute")


class command:  # noqa: N801 - the reference's name
    """The command channel of the running machine (the reference's
    ``linuxcnc.command``).

    Every method checks its arguments as the reference does and sends
    the command, numbered by :attr:`serial`, without waiting for the
    task; :meth:`wait_complete` waits for the last one.  The task
    answers every command: a command it refuses in the current state or
    mode (the reference ignores many of them silently) ends with
    ``RCS_ERROR`` and a message on the error channel that says why.

    The connection is made by the first command: :class:`error` when no
    machine runs (or it is gone).  Arguments to the constructor are
    accepted and ignored, as the reference's.
    """

    __slots__ = ("_client", "_serial", "_lock")

    serial = _Serial()

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._client: Optional[CommandClient] = None
        # the last serial of a connection that was lost (a new connection,
        # to a task started again, counts from 1 again)
        self._serial = 0
        self._lock = threading.Lock()

    # -------------------------------------------------------- plumbing

    def _connect(self) -> CommandClient:
        with self._lock:
            if self._client is None:
                path = _attach().private_socket_path("task")
                try:
                    self._client = CommandClient(path, name="linuxcnc")
                except ChannelError as e:
                    _failed(e)
            return self._client

    def _lost(self, client: CommandClient, e: ChannelError) -> NoReturn:
        """Forget a connection that failed (the next command connects
        again) and raise the error."""
        with self._lock:
            if self._client is client:
                self._serial = client.serial
                self._client = None
                client.close()
        _failed(e)

    def _send(self, name: str, **args: Any) -> None:
        client = self._client or self._connect()
        try:
            client.send(name, **args)
        except ChannelError as e:
            self._lost(client, e)

    # ---------------------------------------------------- state, mode

    def state(self, *args: Any, **kwargs: Any) -> None:
        """state(STATE_ESTOP | STATE_ESTOP_RESET | STATE_OFF | STATE_ON)"""
        _count("command.state", args, kwargs, 1, 1)
        value = _int(args[0])
        if value not in _STATES:
            raise ValueError("Machine state should be STATE_ESTOP, "
                             "STATE_ESTOP_RESET, STATE_ON, or STATE_OFF")
        self._send("state", state=value)

    def mode(self, *args: Any, **kwargs: Any) -> None:
        """mode(MODE_MDI | MODE_MANUAL | MODE_AUTO)"""
        _count("command.mode", args, kwargs, 1, 1)
        value = _int(args[0])
        if value not in _MODES:
            raise ValueError("Mode should be MODE_MDI, MODE_MANUAL, or "
                             "MODE_AUTO")
        self._send("mode", mode=value)

    def abort(self, *args: Any, **kwargs: Any) -> None:
        """abort(): stop what runs."""
        _count("command.abort", args, kwargs, 0, 0)
        self._send("abort")

    def debug(self, *args: Any, **kwargs: Any) -> None:
        """debug(level)"""
        _count("command.debug", args, kwargs, 1, 1)
        self._send("debug", level=_int(args[0]))

    # ---------------------------------------------------------- manual

    def home(self, *args: Any, **kwargs: Any) -> None:
        """home(joint): home a joint (-1: all)."""
        _count("command.home", args, kwargs, 1, 1)
        self._send("home", joint=_int(args[0]))

    def unhome(self, *args: Any, **kwargs: Any) -> None:
        """unhome(joint) (-1: all)."""
        _count("command.unhome", args, kwargs, 1, 1)
        self._send("unhome", joint=_int(args[0]))

    def jog(self, *args: Any, **kwargs: Any) -> None:
        """jog(JOG_STOP, jjogmode, joint_or_axis)
        jog(JOG_CONTINUOUS, jjogmode, joint_or_axis, velocity)
        jog(JOG_INCREMENT, jjogmode, joint_or_axis, velocity, distance)

        ``jjogmode`` true: joint ``joint_or_axis``; false: the axis of
        that index in XYZABCUVW."""
        _count("command.jog", args, kwargs, 3, 5)
        action, joint_mode, index = (_int(a) for a in args[:3])
        numbers = [_float(a) for a in args[3:]]
        if action not in _JOG_ARGS:
            raise TypeError("jog() first argument must be JOG_xxx")
        wanted, word = _JOG_ARGS[action]
        if len(args) != wanted:
            raise TypeError(f"jog({word}, ...) takes {wanted} arguments "
                            f"({len(args)} given)")
        numbers += [0.0] * (2 - len(numbers))
        self._send("jog", action=action, joint_mode=bool(joint_mode),
                   index=index, velocity=numbers[0], distance=numbers[1])

    def override_limits(self, *args: Any, **kwargs: Any) -> None:
        """override_limits(): let the joints move off their limits."""
        _count("command.override_limits", args, kwargs, 0, 0)
        self._send("override_limits")

    def teleop_enable(self, *args: Any, **kwargs: Any) -> None:
        """teleop_enable(on): 1 axis (teleop) jogging, 0 joint jogging."""
        _count("command.teleop_enable", args, kwargs, 1, 1)
        self._send("teleop_enable", on=bool(_int(args[0])))

    def traj_mode(self, *args: Any, **kwargs: Any) -> None:
        """traj_mode(TRAJ_MODE_FREE | TRAJ_MODE_COORD | TRAJ_MODE_TELEOP)"""
        _count("command.traj_mode", args, kwargs, 1, 1)
        self._send("traj_mode", mode=_int(args[0]))

    def set_min_limit(self, *args: Any, **kwargs: Any) -> None:
        """set_min_limit(axis, limit)"""
        _count("command.set_min_limit", args, kwargs, 2, 2)
        self._send("set_min_limit", axis=_int(args[0]),
                   limit=_float(args[1]))

    def set_max_limit(self, *args: Any, **kwargs: Any) -> None:
        """set_max_limit(axis, limit)"""
        _count("command.set_max_limit", args, kwargs, 2, 2)
        self._send("set_max_limit", axis=_int(args[0]),
                   limit=_float(args[1]))

    # ------------------------------------------------ MDI and programs

    def mdi(self, *args: Any, **kwargs: Any) -> None:
        """mdi(line): run one line of G-code (at most 254 characters)."""
        _count("command.mdi", args, kwargs, 1, 1)
        raw = _buffer(args[0])
        if len(raw) > _LINE_MAX:
            raise ValueError(f"MDI commands limited to {_LINE_MAX} "
                             "characters")
        self._send("mdi", line=_decode(raw))

    def program_open(self, *args: Any, **kwargs: Any) -> None:
        """program_open(path): open a G-code file (a relative path is
        taken from this process's current folder)."""
        _count("command.program_open", args, kwargs, 1, 1)
        raw = _buffer(args[0])
        if len(raw) > _LINE_MAX:
            raise ValueError(f"File name limited to {_LINE_MAX} characters")
        path = os.path.abspath(os.fsdecode(raw)) if raw else ""
        self._send("program_open", path=path)

    def auto(self, *args: Any, **kwargs: Any) -> None:
        """auto(AUTO_RUN, start_line), auto(AUTO_PAUSE), auto(AUTO_RESUME),
        auto(AUTO_STEP)"""
        # the reference reads (action, line) for AUTO_RUN, else (action,)
        if kwargs:
            raise TypeError("command.auto() takes no keyword arguments")
        if len(args) == 2:
            try:
                action, line = _int(args[0]), _int(args[1])
            except (TypeError, OverflowError):
                action, line = -1, 0
            if action != AUTO_RUN:
                raise TypeError("function takes exactly 1 argument (2 "
                                "given)")
            self._send("auto", action=action, line=line)
            return
        _count("command.auto", args, kwargs, 1, 1)
        action = _int(args[0])
        if action not in (AUTO_RUN, AUTO_PAUSE, AUTO_RESUME, AUTO_STEP,
                          AUTO_REVERSE, AUTO_FORWARD):
            raise error(f"Unexpected argument '{action}' to command.auto")
        self._send("auto", action=action, line=0)

    def reset_interpreter(self, *args: Any, **kwargs: Any) -> None:
        """reset_interpreter()"""
        _count("command.reset_interpreter", args, kwargs, 0, 0)
        self._send("reset_interpreter")

    def task_plan_synch(self, *args: Any, **kwargs: Any) -> None:
        """task_plan_synch(): write the interpreter's parameters to the
        parameter file."""
        _count("command.task_plan_synch", args, kwargs, 0, 0)
        self._send("task_plan_sync")

    #: the manual's spelling
    task_plan_sync = task_plan_synch

    # ------------------------------------------------------- overrides

    def feedrate(self, *args: Any, **kwargs: Any) -> None:
        """feedrate(scale): feed override, 1.0 = 100 %."""
        _count("command.feedrate", args, kwargs, 1, 1)
        self._send("feedrate", scale=_float(args[0]))

    def rapidrate(self, *args: Any, **kwargs: Any) -> None:
        """rapidrate(scale): rapid override, 0 to 1."""
        _count("command.rapidrate", args, kwargs, 1, 1)
        self._send("rapidrate", scale=_float(args[0]))

    def maxvel(self, *args: Any, **kwargs: Any) -> None:
        """maxvel(velocity): the trajectory's maximum velocity."""
        _count("command.maxvel", args, kwargs, 1, 1)
        self._send("maxvel", velocity=_float(args[0]))

    def spindleoverride(self, *args: Any, **kwargs: Any) -> None:
        """spindleoverride(scale[, spindle])"""
        _count("command.spindleoverride", args, kwargs, 1, 2)
        scale = _float(args[0])
        spindle = _int(args[1]) if len(args) > 1 else 0
        self._send("spindleoverride", scale=scale, spindle=spindle)

    def set_feed_override(self, *args: Any, **kwargs: Any) -> None:
        """set_feed_override(on)"""
        self._flag("set_feed_override", args, kwargs)

    def set_feed_hold(self, *args: Any, **kwargs: Any) -> None:
        """set_feed_hold(on)"""
        self._flag("set_feed_hold", args, kwargs)

    def set_adaptive_feed(self, *args: Any, **kwargs: Any) -> None:
        """set_adaptive_feed(on)"""
        self._flag("set_adaptive_feed", args, kwargs)

    def set_optional_stop(self, *args: Any, **kwargs: Any) -> None:
        """set_optional_stop(on)"""
        self._flag("set_optional_stop", args, kwargs)

    def set_block_delete(self, *args: Any, **kwargs: Any) -> None:
        """set_block_delete(on)"""
        self._flag("set_block_delete", args, kwargs)

    def set_spindle_override(self, *args: Any, **kwargs: Any) -> None:
        """set_spindle_override(on[, spindle])"""
        _count("command.set_spindle_override", args, kwargs, 1, 2)
        on = bool(_int(args[0]))
        spindle = _int(args[1]) if len(args) > 1 else 0
        self._send("set_spindle_override", on=on, spindle=spindle)

    def _flag(self, name: str, args: tuple[Any, ...],
              kwargs: dict[str, Any]) -> None:
        _count("command." + name, args, kwargs, 1, 1)
        self._send(name, on=bool(_int(args[0])))

    # --------------------------------------------- spindle and coolant

    def spindle(self, *args: Any, **kwargs: Any) -> None:
        """spindle(direction[, speed[, spindle[, wait_for_speed]]])

        SPINDLE_FORWARD, SPINDLE_REVERSE: ``speed`` in rpm; SPINDLE_OFF,
        SPINDLE_INCREASE, SPINDLE_DECREASE, SPINDLE_CONSTANT: the second
        argument is the spindle, as in the reference."""
        _count("command.spindle", args, kwargs, 1, 4)
        direction = _int(args[0])
        first = _float(args[1]) if len(args) > 1 else 0.0
        second = _float(args[2]) if len(args) > 2 else 0.0
        wait = _int(args[3]) if len(args) > 3 else 0
        if direction in (SPINDLE_FORWARD, SPINDLE_REVERSE):
            if first < 0:           # the reference sends direction * speed
                direction, first = -direction, -first
            self._send("spindle", direction=direction, speed=first,
                       spindle=int(second), wait_for_speed=bool(wait))
        elif direction in _SPINDLE_OTHERS:
            self._send("spindle", direction=direction, speed=0.0,
                       spindle=int(first), wait_for_speed=False)
        else:
            raise ValueError("Spindle direction should be SPINDLE_FORWARD, "
                             "SPINDLE_REVERSE, SPINDLE_OFF, "
                             "SPINDLE_INCREASE, SPINDLE_DECREASE, or "
                             "SPINDLE_CONSTANT")

    def brake(self, *args: Any, **kwargs: Any) -> None:
        """brake(BRAKE_ENGAGE | BRAKE_RELEASE[, spindle])"""
        _count("command.brake", args, kwargs, 1, 2)
        value = _int(args[0])
        spindle = _int(args[1]) if len(args) > 1 else 0
        if value not in (BRAKE_ENGAGE, BRAKE_RELEASE):
            raise ValueError("BRAKE should be BRAKE_ENGAGE or BRAKE_RELEASE")
        self._send("brake", engage=value == BRAKE_ENGAGE, spindle=spindle)

    def flood(self, *args: Any, **kwargs: Any) -> None:
        """flood(FLOOD_ON | FLOOD_OFF)"""
        _count("command.flood", args, kwargs, 1, 1)
        value = _int(args[0])
        if value not in (FLOOD_ON, FLOOD_OFF):
            raise ValueError("FLOOD should be FLOOD_ON or FLOOD_OFF")
        self._send("flood", on=value == FLOOD_ON)

    def mist(self, *args: Any, **kwargs: Any) -> None:
        """mist(MIST_ON | MIST_OFF)"""
        _count("command.mist", args, kwargs, 1, 1)
        value = _int(args[0])
        if value not in (MIST_ON, MIST_OFF):
            raise ValueError("Mist should be MIST_ON or MIST_OFF")
        self._send("mist", on=value == MIST_ON)

    # ------------------------------------------------------------ I/O

    def set_digital_output(self, *args: Any, **kwargs: Any) -> None:
        """set_digital_output(index, value)"""
        _count("command.set_digital_output", args, kwargs, 2, 2)
        self._send("set_digital_output", index=_int(args[0]),
                   value=bool(_int(args[1])))

    def set_analog_output(self, *args: Any, **kwargs: Any) -> None:
        """set_analog_output(index, value)"""
        _count("command.set_analog_output", args, kwargs, 2, 2)
        self._send("set_analog_output", index=_int(args[0]),
                   value=_float(args[1]))

    # ------------------------------------------------------ tool table

    def tool_offset(self, *args: Any, **kwargs: Any) -> None:
        """tool_offset(tool, z, x, diameter, frontangle, backangle,
        orientation)"""
        _count("command.tool_offset", args, kwargs, 7, 7)
        number = _int(args[0])
        z, x, diameter, front, back = (_float(a) for a in args[1:6])
        orientation = _int(args[6])
        self._send("tool_offset", tool=number, z=z, x=x, diameter=diameter,
                   frontangle=front, backangle=back,
                   orientation=orientation)

    def load_tool_table(self, *args: Any, **kwargs: Any) -> None:
        """load_tool_table(): read the tool table file again."""
        _count("command.load_tool_table", args, kwargs, 0, 0)
        self._send("load_tool_table")

    # -------------------------------------------------------- messages

    def text_msg(self, *args: Any, **kwargs: Any) -> None:
        """text_msg(text): an OPERATOR_TEXT message (254 characters)."""
        self._message("text_msg", args, kwargs)

    def display_msg(self, *args: Any, **kwargs: Any) -> None:
        """display_msg(text): an OPERATOR_DISPLAY message."""
        self._message("display_msg", args, kwargs)

    def error_msg(self, *args: Any, **kwargs: Any) -> None:
        """error_msg(text): an OPERATOR_ERROR message."""
        self._message("error_msg", args, kwargs)

    def _message(self, name: str, args: tuple[Any, ...],
                 kwargs: dict[str, Any]) -> None:
        _count("command." + name, args, kwargs, 1, 1)
        self._send(name, text=_cut(_text(args[0])))

    # ------------------------------------------------------ completion

    def wait_complete(self, *args: Any, **kwargs: Any) -> int:
        """wait_complete([timeout]): wait up to ``timeout`` seconds
        (default 5) for the last command sent to finish: RCS_DONE,
        RCS_ERROR, or -1 when the time ran out."""
        if len(args) > 1:
            raise TypeError("emc.command.wait_complete() takes at most 1 "
                            f"argument ({len(args)} given)")
        _count("command.wait_complete", args, kwargs, 0, 1)
        timeout = _float(args[0]) if args else _DEFAULT_TIMEOUT
        client = self._client or self._connect()
        if client.serial == 0:
            return RCS_DONE             # nothing sent on this connection
        limit: Optional[float] = max(timeout, 0.0)
        if timeout != timeout:          # NaN: one look, as the reference
            limit = 0.0
        elif timeout > _FOREVER:
            limit = None                # until it ends (or the task does)
        try:
            state, _reason = client.wait(client.serial, limit)
        except ChannelError as e:
            self._lost(client, e)
        return state


# ------------------------------------------------------------ errors

class error_channel:  # noqa: N801 - the reference's name
    """The error channel of the running machine (the reference's
    ``linuxcnc.error_channel``): the task's messages as ``(kind, text)``.

    Every reader sees every message posted after it connected, and a new
    reader also gets the messages nobody has read yet (the reference
    hands each message to one reader only).

    :raises error: no machine runs (as the reference's).
    """

    __slots__ = ("_reader",)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._reader: Optional[ErrorReader] = None
        self._open()

    def _open(self) -> ErrorReader:
        address, size = _block()
        try:
            self._reader = ErrorReader(address, size)
        except ChannelError as e:
            _failed(e)
        return self._reader

    def poll(self) -> Optional[tuple[int, str]]:
        """The next message as ``(kind, text)``, or None (never waits);
        kind is one of NML_ERROR, NML_TEXT, NML_DISPLAY, OPERATOR_ERROR,
        OPERATOR_TEXT, OPERATOR_DISPLAY.

        :raises error: the machine is gone (after its last messages)."""
        reader = self._reader or self._open()
        try:
            return reader.poll()
        except ChannelGone as e:
            self._reader = None
            _failed(e)
        except ChannelError as e:
            _failed(e)


# ------------------------------------------------------------ INI files

class ini:  # noqa: N801 - the reference's name
    """An INI file (the reference's ``linuxcnc.ini``).

    Looked up as the reference does: a section given twice is read at its
    first place only, an empty value counts as absent, a value is the
    text after ``=`` without the blanks around it (``#`` or ``;`` after
    it are part of it), names are case sensitive.
    """

    __slots__ = ("_file", "_first")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        _count("ini", args, kwargs, 1, 1)
        path = _text(args[0])
        try:
            self._file = IniFile(path)
        except OSError as e:
            raise error(f"inifile.open() failed: {path}: "
                        f"{e.strerror or e}") from None
        # the line span of each section's first place
        self._first: dict[str, tuple[int, float]] = {}
        headers = self._file.headers
        for i, (name, line) in enumerate(headers):
            if name not in self._first:
                end = headers[i + 1][1] if i + 1 < len(headers) \
                    else float("inf")
                self._first[name] = (line, end)

    def _values(self, section: str, key: str) -> list[str]:
        span = self._first.get(section)
        if span is None:
            return []
        start, end = span
        return [value for value, line in self._file.every.get(
            (section, key), ()) if start < line < end and value]

    def find(self, *args: Any, **kwargs: Any) -> Optional[str]:
        """find(section, key[, num]): the value of ``[section]key`` (the
        ``num``-th of a repeated key, from 1), None when absent."""
        if kwargs:
            raise TypeError("ini.find() takes no keyword arguments")
        if len(args) < 2:
            raise TypeError(f"find() takes at least 2 arguments "
                            f"({len(args)} given)")
        if len(args) > 3:
            raise TypeError(f"find() takes at most 3 arguments "
                            f"({len(args)} given)")
        section, key = _text(args[0], 1, "find"), _text(args[1], 2, "find")
        num = _int(args[2]) if len(args) > 2 else 1
        values = self._values(section, key)
        index = max(num, 1) - 1
        return values[index] if index < len(values) else None

    def findall(self, *args: Any, **kwargs: Any) -> list[str]:
        """findall(section, key): every value of ``[section]key``."""
        if kwargs:
            raise TypeError("ini.findall() takes no keyword arguments")
        if len(args) != 2:
            raise TypeError(f"findall() takes exactly 2 arguments "
                            f"({len(args)} given)")
        return self._values(_text(args[0], 1, "findall"),
                            _text(args[1], 2, "findall"))


for _cls in (stat, command, error_channel, ini):
    _cls.__module__ = "linuxcnc"
del _cls
