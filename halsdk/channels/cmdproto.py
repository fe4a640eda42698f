"""The wire protocol of the task's command channel.

The channel is a Unix stream socket. Each message is a frame: a 4-byte
big-endian length, then that many bytes of UTF-8 JSON holding one object.
A frame carries at most :data:`MAX_FRAME` bytes of JSON.

The first frame each way is the handshake::

    client  {"hello": "halsdk-task", "version": 1, "pid": P, "name": "ctl"}
    task    {"hello": "halsdk-task", "version": 1, "ok": true, "task_pid": N}
    or      {"hello": "halsdk-task", "version": 1, "ok": false,
             "error": "client speaks version 2, this task version 1"}

then the client sends commands and the task answers each one::

    client  {"serial": n, "cmd": "home", "args": {"joint": 0}}
    task    {"serial": n, "state": 2}                  RCS_EXEC: taken
    task    {"serial": n, "state": 1}                  RCS_DONE
    or      {"serial": n, "state": 3, "error": "why"}  RCS_ERROR

A command the task refuses at once (unknown name, bad arguments) gets only
the ``RCS_ERROR`` reply. The serial is the client's own counter, 1, 2, ...
per connection, as the reference's ``linuxcnc.command().serial``.

:data:`COMMANDS` lists the commands (the methods of the reference's
``linuxcnc.command``) with their arguments; :func:`validate` checks the
arguments of one command and fills in the defaults.
"""

from __future__ import annotations

import difflib
import json
import math
import os
from collections.abc import Iterator, Mapping
from typing import Any, NamedTuple, Optional

from halsdk.channels.constants import RCS_DONE, RCS_ERROR, RCS_EXEC
from halsdk.channels.errors import ChannelError
from halsdk.errors import InvalidError

__all__ = [
    "ALIASES", "Arg", "COMMANDS", "CommandError", "FrameError", "FrameReader",
    "HELLO", "MAX_FRAME", "PROTOCOL_VERSION", "RCS_DONE", "RCS_ERROR",
    "RCS_EXEC", "ClientHello", "canonical", "client_hello", "decode", "encode",
    "is_serial", "parse_client_hello", "signature", "task_hello", "task_refusal",
    "validate",
]

#: version of this protocol; both ends must speak the same one
PROTOCOL_VERSION = 1
#: the "hello" word of the handshake frames
HELLO = "halsdk-task"
#: the most bytes of JSON in one frame
MAX_FRAME = 64 * 1024
#: length of the frame header
HEADER = 4


#: largest serial number (a C int64 on the other side)
MAX_SERIAL = (1 << 63) - 1
_INT_MIN = -(1 << 31)
_INT_MAX = (1 << 31) - 1


class FrameError(ChannelError):
    """A frame that breaks the protocol: bad length, not JSON, not an
    object, too large, or a frame that is not the one expected."""


class CommandError(InvalidError):
    """A command that cannot be carried out as given: an unknown name, a
    missing, unknown or badly typed argument. The message says which."""


# ---------------------------------------------------------------- frames


def _refuse_constant(word: str) -> Any:
    raise ValueError(f"{word} is not a JSON number")


def _json_default(value: Any) -> Any:
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"{type(value).__name__} is not a JSON value")


def encode(message: Mapping[str, Any]) -> bytes:
    """The frame of ``message``: header + JSON.

    :raises FrameError: the JSON would exceed :data:`MAX_FRAME` bytes.
    :raises TypeError, ValueError: a value JSON cannot carry (a NaN, an
        object of another type).
    """
    body = json.dumps(message, separators=(",", ":"), ensure_ascii=False,
                      allow_nan=False, default=_json_default).encode("utf-8")
    if len(body) > MAX_FRAME:
        raise FrameError(f"the message is {len(body)} bytes of JSON, a frame "
                         f"carries at most {MAX_FRAME}")
    return len(body).to_bytes(HEADER, "big") + body


def decode(body: bytes) -> dict[str, Any]:
    """The object in the JSON ``body`` of a frame.

    :raises FrameError: not UTF-8, not JSON (NaN and Infinity included) or
        not an object.
    """
    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise FrameError(f"the frame is not UTF-8 text ({exc.reason} at "
                         f"byte {exc.start})") from None
    try:
        obj = json.loads(text, parse_constant=_refuse_constant)
    except (ValueError, RecursionError) as exc:
        raise FrameError(f"the frame is not valid JSON ({exc})") from None
    if not isinstance(obj, dict):
        raise FrameError(f"the frame holds a JSON {_json_kind(obj)}, not an "
                         "object")
    return obj


class FrameReader:
    """Cuts a byte stream into frames.

    :meth:`feed` the bytes as they arrive, then iterate :meth:`frames`: it
    yields each whole frame and keeps an incomplete one for later. A bad
    length is refused as soon as the header is in, before its body.
    """

    def __init__(self) -> None:
        self._buf = bytearray()
        self.received = 0           # bytes fed in all

    def feed(self, data: bytes) -> None:
        self._buf += data
        self.received += len(data)

    @property
    def pending(self) -> int:
        """Bytes held of a frame not complete yet (0: between frames)."""
        return len(self._buf)

    @property
    def expected(self) -> Optional[int]:
        """Full size of the incomplete frame, when its header is in."""
        if len(self._buf) < HEADER:
            return None
        return HEADER + int.from_bytes(self._buf[:HEADER], "big")

    def frames(self) -> Iterator[dict[str, Any]]:
        """Yield the whole frames fed so far, in order.

        :raises FrameError: at the first bad frame; the stream cannot be
            read past it.
        """
        buf = self._buf
        while len(buf) >= HEADER:
            size = int.from_bytes(buf[:HEADER], "big")
            if size == 0:
                raise FrameError("a frame of length 0 (a frame holds a JSON "
                                 "object)")
            if size > MAX_FRAME:
                raise FrameError(f"a frame of {size} bytes, at most "
                                 f"{MAX_FRAME} are allowed")
            if len(buf) < HEADER + size:
                return
            body = bytes(buf[HEADER:HEADER + size])
            del buf[:HEADER + size]
            yield decode(body)


def _json_kind(value: object) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "array"
    return "object"


# ------------------------------------------------------------- handshake


class ClientHello(NamedTuple):
    version: int
    pid: int
    name: str


def client_hello(pid: int, name: str,
                 version: int = PROTOCOL_VERSION) -> dict[str, Any]:
    """The client's first frame."""
    return {"hello": HELLO, "version": version, "pid": pid, "name": name}


def task_hello(task_pid: int) -> dict[str, Any]:
    """The task's answer to a client it accepts."""
    return {"hello": HELLO, "version": PROTOCOL_VERSION, "ok": True,
            "task_pid": task_pid}


def task_refusal(error: str) -> dict[str, Any]:
    """The task's answer to a client it refuses (then it closes)."""
    return {"hello": HELLO, "version": PROTOCOL_VERSION, "ok": False,
            "error": error}


def parse_client_hello(message: Mapping[str, Any]) -> ClientHello:
    """The client's hello frame, read.

    :raises FrameError: the frame is not a hello of this protocol.
    """
    if message.get("hello") != HELLO:
        raise FrameError("the first frame is not the hello of the task's "
                         f"command channel (expected \"hello\": \"{HELLO}\")")
    version = message.get("version")
    if not _is_int(version):
        raise FrameError("the hello frame carries no protocol version")
    pid = message.get("pid", 0)
    name = message.get("name", "")
    if not _is_int(pid) or not isinstance(name, str):
        raise FrameError("the hello frame's pid must be an integer and its "
                         "name a string")
    assert isinstance(version, int) and isinstance(pid, int)
    return ClientHello(version, pid, name[:100])


# -------------------------------------------------------------- commands


class Arg(NamedTuple):
    """One argument of a command: its name, its type (``int``, ``float``,
    ``bool`` or ``str``), whether it is required, and its default."""
    name: str
    type: type
    required: bool = True
    default: Any = None


def _opt(name: str, kind: type, default: Any) -> Arg:
    return Arg(name, kind, False, default)


_INT, _FLOAT, _BOOL, _STR = int, float, bool, str

#: command name -> its arguments, the methods of the reference's
#: ``linuxcnc.command`` (``serial`` and ``wait_complete`` are the
#: client's own); ``task_plan_synch`` is the reference's spelling of
#: ``task_plan_sync``
COMMANDS: Mapping[str, tuple[Arg, ...]] = {
    "state": (Arg("state", _INT),),
    "mode": (Arg("mode", _INT),),
    "home": (Arg("joint", _INT),),
    "unhome": (Arg("joint", _INT),),
    "jog": (Arg("action", _INT), Arg("joint_mode", _BOOL),
            Arg("index", _INT), _opt("velocity", _FLOAT, 0.0),
            _opt("distance", _FLOAT, 0.0)),
    "mdi": (Arg("line", _STR),),
    "program_open": (Arg("path", _STR),),
    "auto": (Arg("action", _INT), _opt("line", _INT, 0)),
    "abort": (),
    "feedrate": (Arg("scale", _FLOAT),),
    "rapidrate": (Arg("scale", _FLOAT),),
    "maxvel": (Arg("velocity", _FLOAT),),
    "spindle": (Arg("direction", _INT), _opt("speed", _FLOAT, 0.0),
                _opt("spindle", _INT, 0),
                _opt("wait_for_speed", _BOOL, False)),
    "spindleoverride": (Arg("scale", _FLOAT), _opt("spindle", _INT, 0)),
    "flood": (Arg("on", _BOOL),),
    "mist": (Arg("on", _BOOL),),
    "brake": (Arg("engage", _BOOL), _opt("spindle", _INT, 0)),
    "set_digital_output": (Arg("index", _INT), Arg("value", _BOOL)),
    "set_analog_output": (Arg("index", _INT), Arg("value", _FLOAT)),
    "override_limits": (),
    "teleop_enable": (Arg("on", _BOOL),),
    "traj_mode": (Arg("mode", _INT),),
    "tool_offset": (Arg("tool", _INT), Arg("z", _FLOAT), Arg("x", _FLOAT),
                    Arg("diameter", _FLOAT), Arg("frontangle", _FLOAT),
                    Arg("backangle", _FLOAT), Arg("orientation", _INT)),
    "load_tool_table": (),
    "reset_interpreter": (),
    "task_plan_sync": (),
    "task_plan_synch": (),
    "text_msg": (Arg("text", _STR),),
    "error_msg": (Arg("text", _STR),),
    "display_msg": (Arg("text", _STR),),
    "set_optional_stop": (Arg("on", _BOOL),),
    "set_block_delete": (Arg("on", _BOOL),),
    "set_feed_override": (Arg("on", _BOOL),),
    "set_feed_hold": (Arg("on", _BOOL),),
    "set_spindle_override": (Arg("on", _BOOL), _opt("spindle", _INT, 0)),
    "set_adaptive_feed": (Arg("on", _BOOL),),
    "set_max_limit": (Arg("axis", _INT), Arg("limit", _FLOAT)),
    "set_min_limit": (Arg("axis", _INT), Arg("limit", _FLOAT)),
    "debug": (Arg("level", _INT),),
}

#: other spellings -> the name the task is given
ALIASES: Mapping[str, str] = {"task_plan_synch": "task_plan_sync"}

_TYPE_WORDS = {int: "int", float: "float", bool: "bool", str: "str"}


def canonical(name: str) -> str:
    """The name the task knows a command by (``task_plan_synch`` ->
    ``task_plan_sync``); other names unchanged."""
    return ALIASES.get(name, name)


def signature(name: str) -> str:
    """The arguments of a command in words, e.g. ``joint:int``."""
    parts = []
    for arg in COMMANDS[name]:
        word = f"{arg.name}:{_TYPE_WORDS[arg.type]}"
        if not arg.required:
            word += f"={json.dumps(arg.default)}"
        parts.append(word)
    return ", ".join(parts) or "no arguments"


def validate(name: Any, args: Any) -> dict[str, Any]:
    """The arguments of command ``name`` checked and completed with the
    defaults of the missing optional ones.

    Integers are JSON integers (a float with an integral value passes, a
    boolean does not) within a C int; floats are finite JSON numbers
    (integers pass); booleans are ``true``/``false`` (or 0/1, as the
    reference's ``FLOOD_ON`` and friends); strings hold no NUL.

    :raises CommandError: unknown command, missing, unknown or badly
        typed argument; the message says which.
    """
    if not isinstance(name, str):
        raise CommandError("the command has no name (\"cmd\" must be a "
                           f"string, got a JSON {_json_kind(name)})")
    specs = COMMANDS.get(name)
    if specs is None:
        near = difflib.get_close_matches(name, list(COMMANDS), n=1)
        hint = f" (did you mean '{near[0]}'?)" if near else ""
        raise CommandError(f"unknown command '{name[:80]}'{hint}")
    if args is None:
        args = {}
    if not isinstance(args, Mapping):
        raise CommandError(f"command '{name}': the arguments must be a JSON "
                           f"object, got a JSON {_json_kind(args)}")
    known = {arg.name for arg in specs}
    unknown = sorted(str(key) for key in args if key not in known)
    if unknown:
        raise CommandError(f"command '{name}': unknown argument "
                           f"'{unknown[0][:80]}' ({name} takes "
                           f"{signature(name)})")
    result: dict[str, Any] = {}
    for arg in specs:
        if arg.name not in args:
            if arg.required:
                raise CommandError(f"command '{name}': missing argument "
                                   f"'{arg.name}' ({name} takes "
                                   f"{signature(name)})")
            result[arg.name] = arg.default
            continue
        result[arg.name] = _check(name, arg, args[arg.name])
    return result


def _check(command: str, arg: Arg, value: Any) -> Any:
    def bad(expect: str) -> CommandError:
        shown = json.dumps(value, allow_nan=True, default=repr)
        if len(shown) > 40:
            shown = shown[:37] + "..."
        return CommandError(f"command '{command}': argument '{arg.name}' "
                            f"must be {expect}, got {shown} (a JSON "
                            f"{_json_kind(value)})")

    if arg.type is bool:
        if isinstance(value, bool):
            return value
        if _is_int(value) and value in (0, 1):
            return bool(value)
        raise bad("a boolean (true or false)")
    if arg.type is int:
        if isinstance(value, float) and math.isfinite(value) \
                and value.is_integer():
            value_int = int(value)
        elif _is_int(value):
            value_int = value
        else:
            raise bad("an integer")
        if not _INT_MIN <= value_int <= _INT_MAX:
            raise bad(f"an integer from {_INT_MIN} to {_INT_MAX}")
        return value_int
    if arg.type is float:
        if _is_int(value):
            return float(value)
        if isinstance(value, float) and math.isfinite(value):
            return value
        raise bad("a finite number")
    if not isinstance(value, str):
        raise bad("a string")
    if "\0" in value:
        raise bad("a string without NUL characters")
    return value


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def is_serial(value: Any) -> bool:
    """Whether ``value`` can be a command's serial number."""
    return _is_int(value) and 0 <= value <= MAX_SERIAL
