"""The status snapshot in bytes: how the fields of
:mod:`halsdk.channels.statusfields` are packed into the status channel,
and the :class:`Snapshot` a reader gets back.

A snapshot is one :data:`STATUS` struct (native byte order, no padding):
the FIELDS in table order (``i`` as int64, ``b`` as one byte, ``d`` as
double, ``s`` as ``count`` bytes of UTF-8 padded with NULs), then the
MAX_JOINTS joint, MAX_AXES axis and MAX_SPINDLES spindle groups, each
the values of its keys in table order.  A tool table entry is one
:data:`TOOL_ENTRY` struct.  :mod:`halsdk.channels.shmchannel` moves the
bytes; this module only packs and unpacks them.
"""

from __future__ import annotations

import struct
import zlib
from collections import namedtuple
from collections.abc import Mapping
from operator import itemgetter
from typing import TYPE_CHECKING, Any, Callable

from halsdk.channels.statusfields import (
    AXIS_FIELDS,
    FIELDS,
    JOINT_FIELDS,
    MAX_AXES,
    MAX_JOINTS,
    MAX_SPINDLES,
    MAX_TOOLS,
    SPINDLE_FIELDS,
    TOOL_COMMENT_SIZE,
    TOOL_FIELDS,
)
from halsdk.errors import InvalidError

__all__ = ["STATUS", "STATUS_SIZE", "TOOL_ENTRY", "TOOL_ENTRY_SIZE",
           "LAYOUT_CRC", "FIELD_NAMES", "GROUPS", "Snapshot", "ToolResult",
           "StatusPacker", "pack_tool", "unpack_tool", "cut"]

_CODE = {"i": "q", "b": "?", "d": "d"}
_DEFAULT: dict[str, Any] = {"i": 0, "b": False, "d": 0.0, "s": ""}

Keys = tuple[tuple[str, str], ...]

#: the groups of dicts after the fields: (name, keys, how many)
GROUPS: tuple[tuple[str, Keys, int], ...] = (
    ("joint", JOINT_FIELDS, MAX_JOINTS),
    ("axis", AXIS_FIELDS, MAX_AXES),
    ("spindle", SPINDLE_FIELDS, MAX_SPINDLES),
)
FIELD_NAMES: tuple[str, ...] = tuple(name for name, _, _ in FIELDS)


def _code(kind: str, count: int) -> str:
    return f"{count}s" if kind == "s" else f"{count}{_CODE[kind]}"


def _group_code(keys: Keys, n: int) -> str:
    return "".join(_CODE[kind] for _, kind in keys) * n


STATUS = struct.Struct("=" + "".join(_code(k, c) for _, k, c in FIELDS)
                       + "".join(_group_code(keys, n) for _, keys, n in GROUPS))
STATUS_SIZE = STATUS.size
TOOL_ENTRY = struct.Struct("=" + "".join(
    f"{TOOL_COMMENT_SIZE}s" if kind == "s" else _CODE[kind]
    for _, kind in TOOL_FIELDS))
TOOL_ENTRY_SIZE = TOOL_ENTRY.size
#: a checksum of the tables the layout is made of: a client built from
#: another table is refused even where LAYOUT_VERSION was not bumped
LAYOUT_CRC = zlib.crc32(repr((FIELDS, GROUPS, TOOL_FIELDS,
                              TOOL_COMMENT_SIZE, MAX_TOOLS)).encode())


def cut(text: Any, size: int) -> bytes:
    """``text`` as UTF-8, cut to at most ``size`` bytes at a character
    boundary (None: empty; bytes are taken as they are)."""
    if text is None:
        return b""
    if isinstance(text, bytes):
        raw = text
    else:
        try:
            raw = str(text).encode("utf-8", "surrogateescape")
        except UnicodeEncodeError:
            raw = str(text).encode("utf-8", "replace")
    if len(raw) <= size:
        return raw
    end = size
    # back off over continuation bytes (10xxxxxx) to a character start
    while end > 0 and (raw[end] & 0xC0) == 0x80:
        end -= 1
    return raw[:end]


def text(raw: bytes) -> str:
    """A string field's bytes as str."""
    return raw.rstrip(b"\0").decode("utf-8", "surrogateescape")


# ------------------------------------------------------------ packing

_SCALAR, _ARRAY, _STRING = 0, 1, 2


class _Span:
    """Where a field's values sit in the flat list STATUS packs."""

    __slots__ = ("name", "code", "start", "end")

    def __init__(self, name: str, code: str, start: int, end: int) -> None:
        self.name, self.code, self.start, self.end = name, code, start, end


def _spans() -> list[_Span]:
    spans = []
    at = 0
    for name, kind, count in FIELDS:
        n = 1 if kind == "s" or count == 1 else count
        spans.append(_Span(name, _code(kind, count), at, at + n))
        at += n
    for name, keys, most in GROUPS:
        for i in range(most):
            for key, kind in keys:
                spans.append(_Span(f"{name}[{i}].{key}", _CODE[kind], at,
                                   at + 1))
                at += 1
    return spans


_SPANS = _spans()
_AT = {s.name: s for s in _SPANS}
# per field: name, form, count, default, count defaults
_PLAN = [(name, _STRING if kind == "s" else _SCALAR if count == 1
          else _ARRAY, count, _DEFAULT[kind], (_DEFAULT[kind],) * count)
         for name, kind, count in FIELDS]
# per group: name, how many, getter of all keys, (key, default)s, defaults
_GROUP_PLAN = [(name, most, itemgetter(*(k for k, _ in keys)),
                tuple((k, _DEFAULT[kind]) for k, kind in keys),
                tuple(_DEFAULT[kind] for _, kind in keys))
               for name, keys, most in GROUPS]


def _offset(name: str) -> int:
    """Byte offset of a field in STATUS."""
    i = FIELD_NAMES.index(name)
    return struct.calcsize("=" + "".join(_code(k, c) for _, k, c in
                                         FIELDS[:i]))


class StatusPacker:
    """Packs snapshot mappings into a STATUS buffer of its own
    (:attr:`buffer`), for the writer to copy into the channel."""

    #: byte offset of the ``closed`` field
    CLOSED_OFFSET = _offset("closed")

    def __init__(self, pid: int) -> None:
        self.pid = pid
        self.buffer = bytearray(STATUS_SIZE)
        self._spare = bytearray(STATUS_SIZE)

    def pack(self, snapshot: Mapping[str, Any]) -> None:
        """Pack ``snapshot`` (see StatusWriter.publish) into
        :attr:`buffer`: ``task_pid`` defaults to this packer's pid,
        ``closed`` is always False.  InvalidError names a field of the
        wrong type or a tuple that is too long; the buffer then still
        holds the last snapshot packed."""
        values = _flatten(snapshot)
        if snapshot.get("task_pid") is None:
            values[_AT["task_pid"].start] = self.pid
        values[_AT["closed"].start] = False
        try:
            # into the spare buffer: a failed pack_into leaves it half
            # written
            STATUS.pack_into(self._spare, 0, *values)
        except struct.error as exc:
            raise _bad_value(values, exc) from None
        self.buffer, self._spare = self._spare, self.buffer

    def set_closed(self) -> None:
        self.buffer[self.CLOSED_OFFSET] = 1


def _flatten(snapshot: Mapping[str, Any]) -> list[Any]:
    """The values STATUS packs, from a snapshot mapping."""
    out: list[Any] = []
    add, extend = out.append, out.extend
    get = snapshot.get
    for name, form, count, default, zeros in _PLAN:
        v = get(name)
        if form == _SCALAR:
            add(default if v is None else v)
        elif form == _STRING:
            add(cut(v, count))
        elif v is None:
            extend(zeros)
        else:
            n = len(v)
            if n == count:
                extend(v)
            elif n < count:
                extend(v)
                extend(zeros[n:])
            else:
                raise InvalidError(f"status field '{name}' has {n} values, "
                                   f"the channel holds {count}")
    for name, most, getter, defaults, zeros in _GROUP_PLAN:
        rows = get(name) or ()
        if len(rows) > most:
            raise InvalidError(f"status field '{name}' has {len(rows)} "
                               f"entries, the channel holds {most}")
        for row in rows:
            try:
                extend(getter(row))
            except KeyError:
                extend(row.get(k, d) for k, d in defaults)
        extend(zeros * (most - len(rows)))
    return out


def _bad_value(values: list[Any], error: Exception) -> InvalidError:
    """The error naming the field whose value STATUS could not pack."""
    for s in _SPANS:
        try:
            struct.pack("=" + s.code, *values[s.start:s.end])
        except struct.error as exc:
            got = values[s.start] if s.end - s.start == 1 \
                else values[s.start:s.end]
            return InvalidError(f"status field '{s.name}': {exc} (got "
                                f"{got!r:.80})")
    return InvalidError(f"status snapshot: {error}")


# ------------------------------------------------------------ tools

ToolResult = namedtuple(  # type: ignore[misc]
    "ToolResult", [name for name, _ in TOOL_FIELDS])
ToolResult.__doc__ = ("An entry of the tool table: the reference's "
                      "``tool_result`` fields, then pocket and comment.")

_TOOL_GET = itemgetter(*(k for k, _ in TOOL_FIELDS))
_TOOL_DEFAULTS = tuple((k, _DEFAULT[kind]) for k, kind in TOOL_FIELDS)
_COMMENT = [k for k, _ in TOOL_FIELDS].index("comment")


def pack_tool(buffer: bytearray, offset: int, tool: Mapping[str, Any],
              index: int) -> None:
    """Pack one tool table entry (TOOL_FIELDS keys, missing ones 0 or "")
    at ``offset``; InvalidError names entry ``index`` when a value does
    not fit."""
    try:
        row = list(_TOOL_GET(tool))
    except KeyError:
        row = [tool.get(k, d) for k, d in _TOOL_DEFAULTS]
    row[_COMMENT] = cut(row[_COMMENT], TOOL_COMMENT_SIZE)
    try:
        TOOL_ENTRY.pack_into(buffer, offset, *row)
    except struct.error as exc:
        raise InvalidError(f"tool table entry {index}: {exc} "
                           f"({tool!r:.120})") from None


def unpack_tool(raw: bytes, offset: int) -> Any:
    """The ToolResult packed at ``offset``."""
    row = list(TOOL_ENTRY.unpack_from(raw, offset))
    row[_COMMENT] = text(row[_COMMENT])
    return ToolResult._make(row)


# ------------------------------------------------------------ snapshot

class _Field:
    """A Snapshot attribute: decoded from the raw copy on first use, then
    kept in the instance (a non-data descriptor: from then on the
    instance's dict answers)."""

    __slots__ = ("name", "read")

    def __init__(self, name: str, read: Callable[[bytes], Any]) -> None:
        self.name = name
        self.read = read

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self
        value = self.read(obj._raw)
        obj.__dict__[self.name] = value
        return value


def _field_reader(kind: str, count: int,
                  offset: int) -> Callable[[bytes], Any]:
    if kind == "s":
        end = offset + count
        return lambda raw: text(raw[offset:end])
    unpack = struct.Struct("=" + _code(kind, count)).unpack_from
    if count == 1:
        return lambda raw: unpack(raw, offset)[0]
    return lambda raw: unpack(raw, offset)


def _dicts(keys: list[str], flat: Any, start: int,
           n: int) -> tuple[dict[str, Any], ...]:
    width = len(keys)
    return tuple(dict(zip(keys, flat[start + i * width:
                                     start + (i + 1) * width]))
                 for i in range(n))


def _group_reader(keys: Keys, n: int, offset: int) -> Callable[[bytes], Any]:
    unpack = struct.Struct("=" + _group_code(keys, n)).unpack_from
    names = [k for k, _ in keys]
    return lambda raw: _dicts(names, unpack(raw, offset), 0, n)


def _decode_all(raw: bytes) -> dict[str, Any]:
    """Every field of a raw snapshot, from one unpack."""
    flat = STATUS.unpack_from(raw)
    out: dict[str, Any] = {}
    for name, form, _count, _default, _zeros in _PLAN:
        s = _AT[name]
        out[name] = (flat[s.start] if form == _SCALAR
                     else text(flat[s.start]) if form == _STRING
                     else flat[s.start:s.end])
    at = _SPANS[len(FIELDS)].start
    for name, keys, n in GROUPS:
        out[name] = _dicts([k for k, _ in keys], flat, at, n)
        at += n * len(keys)
    return out


class Snapshot:
    """One consistent status snapshot (immutable).

    An attribute per FIELDS name, of the reader's type: int, bool,
    float or str, a tuple of them for a count above 1.  ``joint``,
    ``axis`` and ``spindle``: tuples of MAX_JOINTS, MAX_AXES and
    MAX_SPINDLES dicts; ``tool_table``: tuple of :class:`ToolResult` in
    table order.  A field is decoded when it is first read, so that a
    poll costs a copy of the bytes and no more.
    """

    joint: tuple[dict[str, Any], ...]
    axis: tuple[dict[str, Any], ...]
    spindle: tuple[dict[str, Any], ...]
    tool_table: tuple[Any, ...]
    _raw: bytes

    if TYPE_CHECKING:
        def __getattr__(self, name: str) -> Any: ...

    def __init__(self, raw: bytes, tool_table: tuple[Any, ...] = ()) -> None:
        if len(raw) != STATUS_SIZE:
            raise InvalidError(f"a status snapshot has {STATUS_SIZE} bytes, "
                               f"not {len(raw)}")
        d = self.__dict__
        d["_raw"] = bytes(raw)
        d["tool_table"] = tuple(tool_table)

    @classmethod
    def _make(cls, raw: bytes, tool_table: tuple[Any, ...]) -> Snapshot:
        """The reader's constructor (no checks)."""
        snap = object.__new__(cls)
        d = snap.__dict__
        d["_raw"] = raw
        d["tool_table"] = tool_table
        return snap

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"a Snapshot is read-only ({name})")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"a Snapshot is read-only ({name})")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Snapshot):
            return NotImplemented
        return self._raw == other._raw and self.tool_table == other.tool_table

    def __hash__(self) -> int:
        return hash(self._raw)

    def __repr__(self) -> str:
        return (f"<Snapshot heartbeat={self.heartbeat} task_state="
                f"{self.task_state} task_mode={self.task_mode} "
                f"interp_state={self.interp_state} "
                f"echo_serial_number={self.echo_serial_number}>")

    def as_dict(self) -> dict[str, Any]:
        """Every field by name, with ``joint``, ``axis``, ``spindle`` and
        ``tool_table`` (decoded with one unpack of the whole copy)."""
        d = self.__dict__
        if "_decoded" not in d:
            for name, value in _decode_all(self._raw).items():
                d.setdefault(name, value)
            d["_decoded"] = True
        out = {name: d[name] for name in _ALL_NAMES}
        out["tool_table"] = self.tool_table
        return out


_ALL_NAMES = FIELD_NAMES + tuple(name for name, _, _ in GROUPS)


def _install_fields() -> None:
    offset = 0
    for name, kind, count in FIELDS:
        setattr(Snapshot, name,
                _Field(name, _field_reader(kind, count, offset)))
        offset += struct.calcsize("=" + _code(kind, count))
    for name, keys, n in GROUPS:
        setattr(Snapshot, name, _Field(name, _group_reader(keys, n, offset)))
        offset += struct.calcsize("=" + _group_code(keys, n))
    assert offset == STATUS_SIZE


_install_fields()
