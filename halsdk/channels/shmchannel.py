"""The task controller's status and error channels, in HAL shared memory.

The task creates one shared block, :data:`BLOCK_NAME` in the instance
segment, of :func:`block_size` bytes, and writes it with a
:class:`StatusWriter`: every cycle a status snapshot (the fields of
:mod:`halsdk.channels.statusfields`), now and then the tool table, and
the operator messages.  Clients attach the block
(``Hal.shared_block(BLOCK_NAME)``) and read it with a
:class:`StatusReader` and an :class:`ErrorReader`.

Layout of the block (every region starts on a 64-byte line; integers
native, as both sides run on the same machine)::

    header      magic, LAYOUT_VERSION, block size, task pid, closed flag,
                checksum of the field tables, ring geometry
    status      u64 sequence word, then the snapshot packed by one
                struct.Struct (:mod:`halsdk.channels.statuslayout`)
    tools       u64 sequence word, then (version, generation, count) and
                MAX_TOOLS entries of TOOL_ENTRY_SIZE bytes
    messages    u64 count of posted messages, u64 "consumed" mark, then
                RING_SIZE slots of (mark, kind, length, text)

The status and the tools are seqlocks: the writer makes the sequence
word odd, copies, makes it even again; a reader copies and keeps the
copy only when the word was even and unchanged around it.  The writer
never waits for a reader; a reader never holds up the writer (it
retries, and gives up after about a second of torn copies).  A reader
raises ChannelGone once the task has closed the channel or its process
has ended (a pidfd, so a reused pid does not fool it).

Messages go to a ring: message n goes to slot n % RING_SIZE, marked as
being written, then as complete, then the count is raised.  A reader
that falls more than RING_SIZE messages behind loses the oldest ones
and counts them (:attr:`ErrorReader.lost`).  Unlike the reference (its
error channel is a queue: the first reader takes a message, the others
never see it), every reader sees every message posted after it
connected; a shared "consumed" mark, the highest message any reader has
taken, lets a reader that connects later start with the first message
nobody has read, so that a message posted before any client connected
is not lost.
"""

from __future__ import annotations

import struct
import threading
import zlib
from collections.abc import Mapping, Sequence
from typing import Any, NoReturn, Optional

from halsdk.channels import _shm
from halsdk.channels.errors import ChannelError, ChannelGone
from halsdk.channels.statusfields import LAYOUT_VERSION, MAX_TOOLS
from halsdk.channels.statuslayout import (
    LAYOUT_CRC,
    STATUS_SIZE,
    TOOL_ENTRY_SIZE,
    Snapshot,
    StatusPacker,
    ToolResult,
    cut,
    pack_tool,
    unpack_tool,
)
from halsdk.errors import InvalidError

__all__ = ["BLOCK_NAME", "block_size", "ChannelError", "ChannelGone",
           "StatusWriter", "StatusReader", "Snapshot", "ToolResult",
           "ErrorReader", "MESSAGE_KINDS", "RING_SIZE", "TEXT_SIZE"]

BLOCK_NAME = "task.channel"
MAGIC = int.from_bytes(b"HTSK", "little")
#: messages the ring holds before the oldest is overwritten
RING_SIZE = 128
#: bytes of a message's text (UTF-8; longer texts are cut)
TEXT_SIZE = 1024
#: the kinds of messages, numbered as the reference's: NML_ERROR,
#: NML_TEXT, NML_DISPLAY, OPERATOR_ERROR, OPERATOR_TEXT, OPERATOR_DISPLAY
MESSAGE_KINDS = frozenset({1, 2, 3, 11, 12, 13})
#: how long a reader retries torn copies before it gives up (s)
READ_TIMEOUT = 1.0

# ------------------------------------------------------------ the block

_LINE = 64


def _up(n: int) -> int:
    return (n + _LINE - 1) // _LINE * _LINE


# header: magic, layout version, block size, task pid, closed, layout
# checksum, ring slots, text bytes
_HEADER = struct.Struct("=IIQqIIII")
_OFF_MAGIC, _OFF_PID, _OFF_CLOSED, _OFF_CRC = 0, 16, 24, 28
# the tool region's head: version (the writer's count of tool table
# writes, what readers compare), generation (the task's), entries
_TOOL_HEAD = struct.Struct("=QqQ")
_SLOT_SIZE = _shm.SLOT_HEADER + TEXT_SIZE

_STATUS_SEQ = _LINE
_STATUS_DATA = 2 * _LINE
_TOOLS_SEQ = _STATUS_DATA + _up(STATUS_SIZE)
_TOOLS_DATA = _TOOLS_SEQ + _LINE
_TOOLS_COUNT = _TOOLS_DATA + 16
_MSG_COUNT = _TOOLS_DATA + _up(_TOOL_HEAD.size + MAX_TOOLS * TOOL_ENTRY_SIZE)
_MSG_CONSUMED = _MSG_COUNT + _LINE      # written by readers: a line of its own
_MSG_SLOTS = _MSG_CONSUMED + _LINE
_BLOCK_SIZE = _MSG_SLOTS + RING_SIZE * _SLOT_SIZE
#: the checksum in the header: the field tables and the ring's geometry
TABLE_CRC = zlib.crc32(repr((RING_SIZE, TEXT_SIZE)).encode(), LAYOUT_CRC)


def block_size() -> int:
    """The bytes the shared block of the channel needs."""
    return _BLOCK_SIZE


# ------------------------------------------------------------ writer

class StatusWriter:
    """The task's side of the channel: the only writer of the block.

    ``address`` and ``size``: the block (``Hal.new_shared_block(
    BLOCK_NAME, block_size(), component)``); ``pid``: the process that
    hosts the task (readers raise :class:`ChannelGone` once it ends).
    The constructor writes the header, an all-zero snapshot and an empty
    tool table.  Call publish, publish_tools and close from one thread
    (the task's); post from any.  Nothing here waits for a reader.
    """

    def __init__(self, address: int, size: int, pid: int) -> None:
        if size < _BLOCK_SIZE:
            raise ChannelError(f"the task channel block has {size} bytes, "
                               f"the channel needs {_BLOCK_SIZE}")
        if pid <= 0:
            raise InvalidError(f"task pid {pid}: not a process id")
        self.address = address
        self.pid = pid
        self._packer = StatusPacker(pid)
        self._closed = False
        self._tool_version = 0
        self._tool_generation: Optional[int] = None
        self._posted = 0
        self._lock = threading.Lock()       # post() from other threads
        _shm.zero(address, _BLOCK_SIZE)
        _shm.fill(address, _HEADER.pack(0, LAYOUT_VERSION, _BLOCK_SIZE, pid,
                                        0, TABLE_CRC, RING_SIZE, TEXT_SIZE))
        self.publish({})
        self.publish_tools(0, ())
        # last, with release: a reader that sees the magic sees the rest
        _shm.store32(address + _OFF_MAGIC, MAGIC)

    @property
    def closed(self) -> bool:
        return self._closed

    def _check_open(self) -> None:
        if self._closed:
            raise ChannelError("the status channel is closed")

    def publish(self, snapshot: Mapping[str, Any]) -> None:
        """Publish a status snapshot: the FIELDS names (a missing or None
        value reads as 0, "" or False; ``task_pid`` defaults to the
        writer's pid; ``closed`` is the writer's), and ``joint``,
        ``axis``, ``spindle``: sequences of dicts (JOINT_FIELDS,
        AXIS_FIELDS, SPINDLE_FIELDS keys, missing ones 0), at most
        MAX_JOINTS, MAX_AXES, MAX_SPINDLES of them.  Shorter tuples are
        padded with zeros; strings are cut at a UTF-8 character boundary.
        InvalidError names a field of the wrong type or a tuple that is
        too long (nothing is published then)."""
        self._check_open()
        self._packer.pack(snapshot)
        _shm.seq_write(self.address + _STATUS_SEQ,
                       self.address + _STATUS_DATA, self._packer.buffer)

    def publish_tools(self, generation: int,
                      tools: Sequence[Mapping[str, Any]]) -> None:
        """Publish the tool table: entries with TOOL_FIELDS keys (a
        missing one reads as 0 or ""), in table order.  ``generation``
        names this content: a call with the generation already published
        does nothing, and readers copy the table only when it changed."""
        self._check_open()
        if generation == self._tool_generation:
            return
        if len(tools) > MAX_TOOLS:
            raise InvalidError(f"tool table of {len(tools)} entries: the "
                               f"channel holds at most {MAX_TOOLS}")
        head = _TOOL_HEAD.size
        buf = bytearray(head + len(tools) * TOOL_ENTRY_SIZE)
        for i, tool in enumerate(tools):
            pack_tool(buf, head + i * TOOL_ENTRY_SIZE, tool, i)
        _TOOL_HEAD.pack_into(buf, 0, self._tool_version + 1, generation,
                             len(tools))
        _shm.seq_write(self.address + _TOOLS_SEQ,
                       self.address + _TOOLS_DATA, buf)
        self._tool_version += 1
        self._tool_generation = generation

    def post(self, kind: int, text: str) -> None:
        """Post a message (``kind``: one of MESSAGE_KINDS) to the error
        ring; the text is cut to TEXT_SIZE bytes of UTF-8."""
        if kind not in MESSAGE_KINDS:
            raise InvalidError(f"message kind {kind}: expected one of "
                               f"{sorted(MESSAGE_KINDS)}")
        raw = cut(text, TEXT_SIZE)
        with self._lock:
            self._check_open()
            n = self._posted
            _shm.slot_write(self.address + _MSG_SLOTS
                            + (n % RING_SIZE) * _SLOT_SIZE, n, kind, raw)
            self._posted = n + 1
            _shm.store64(self.address + _MSG_COUNT, n + 1)

    def close(self) -> None:
        """Mark the channel closed (the task stopped): readers then raise
        ChannelGone (an ErrorReader once it has read what was posted).
        Do it before the block is deleted.  Closing twice is fine."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._packer.set_closed()
            _shm.seq_write(self.address + _STATUS_SEQ,
                           self.address + _STATUS_DATA, self._packer.buffer)
            _shm.store32(self.address + _OFF_CLOSED, 1)


# ------------------------------------------------------------ readers

def _check_header(address: int, size: int) -> int:
    """Check the block's header; returns the task's pid."""
    if size < _LINE:
        raise ChannelError(f"the task channel block has {size} bytes: too "
                           "small to be one")
    live = _shm.load32(address + _OFF_MAGIC)        # acquire, then the rest
    _magic, version, declared, pid, _closed, crc, ring, text_size = \
        _HEADER.unpack(_shm.peek(address, _HEADER.size))
    if live != MAGIC:
        if live == 0:
            raise ChannelError("the task channel block is not initialised "
                               "(the task has not started its channel)")
        raise ChannelError(f"the block is not a task channel (magic "
                           f"{live:#x}, expected {MAGIC:#x})")
    if version != LAYOUT_VERSION:
        raise ChannelError(
            f"the task's channel has layout version {version}, this client "
            f"reads version {LAYOUT_VERSION}: the task and this client run "
            "different halsdk versions")
    if crc != TABLE_CRC or ring != RING_SIZE or text_size != TEXT_SIZE:
        raise ChannelError(
            "the task's channel has another field table than this client "
            f"(both say layout version {version}): the task and this "
            "client run different halsdk versions")
    if declared != _BLOCK_SIZE or size < _BLOCK_SIZE:
        raise ChannelError(
            f"the task channel block has {size} bytes and declares "
            f"{declared}, this client needs {_BLOCK_SIZE}")
    if pid <= 0:
        raise ChannelError(f"the task channel names task pid {pid}")
    return int(pid)


class _Attached:
    """What both readers share: the header check and the liveness test."""

    def __init__(self, address: int, size: int) -> None:
        self.address = address
        self.size = size
        self.pid = _check_header(address, size)
        self._watch = _shm.PidWatch(self.pid)

    def _check_block(self) -> None:
        """ChannelGone when the block no longer holds this task's channel
        (the task removed it, and another may have taken the memory)."""
        a = self.address
        if _shm.load32(a + _OFF_MAGIC) != MAGIC or \
                _shm.load64(a + _OFF_PID) != self.pid:
            raise ChannelGone("the machine is gone: the task channel block "
                              f"of pid {self.pid} was removed or reused")

    def _check_task(self) -> None:
        """ChannelGone when the task closed the channel or died."""
        if _shm.load32(self.address + _OFF_CLOSED):
            raise ChannelGone(f"the machine is gone: the task (pid "
                              f"{self.pid}) closed its status channel")
        if self._watch.dead():
            raise ChannelGone(f"the machine is gone: the task (pid "
                              f"{self.pid}) is dead")

    def _check(self) -> None:
        self._check_task()
        self._check_block()


class StatusReader(_Attached):
    """A client's side of the status channel.

    ``address`` and ``size``: the block in this process
    (``Hal.shared_block(BLOCK_NAME)``).  ChannelError when it is not a
    channel this client can read (bad magic, another layout version or
    field table, too small), saying which.
    """

    def __init__(self, address: int, size: int, *,
                 timeout: float = READ_TIMEOUT) -> None:
        super().__init__(address, size)
        self.timeout = timeout
        # (version, table) of the last copy, replaced as one (polls from
        # several threads)
        self._tools: tuple[int, tuple[Any, ...]] = (-1, ())

    def poll(self) -> Snapshot:
        """A consistent copy of the last snapshot the task published.

        Never blocks the task: retries while the task is in the middle
        of an update; ChannelError after ``timeout`` s (1 s) of torn
        copies; ChannelGone when the task closed the channel or died."""
        self._check()
        a = self.address
        raw = _shm.seq_read(a + _STATUS_SEQ, a + _STATUS_DATA, STATUS_SIZE,
                            self.timeout, self._watch)
        if raw is None:
            self._torn()
        tools = self._tools
        if _shm.load64(a + _TOOLS_DATA) != tools[0]:
            tools = self._read_tools()
        return Snapshot._make(raw, tools[1])

    def _torn(self) -> NoReturn:
        self._check()
        raise ChannelError(
            f"no consistent status snapshot within {self.timeout:g} s: the "
            f"task (pid {self.pid}) never finishes an update")

    def _read_tools(self) -> tuple[int, tuple[Any, ...]]:
        """Copy the tool table (its version changed)."""
        a = self.address
        head = _TOOL_HEAD.size
        count = min(_shm.load64(a + _TOOLS_COUNT), MAX_TOOLS)
        while True:
            raw = _shm.seq_read(a + _TOOLS_SEQ, a + _TOOLS_DATA,
                                head + count * TOOL_ENTRY_SIZE,
                                self.timeout, self._watch)
            if raw is None:
                self._torn()
            version, _generation, n = _TOOL_HEAD.unpack_from(raw)
            if n > MAX_TOOLS:
                raise ChannelError(f"the task's tool table says {n} "
                                   f"entries, at most {MAX_TOOLS} fit")
            if n <= count:
                break
            count = n           # it grew between the two reads
        self._tools = (version, tuple(
            unpack_tool(raw, head + i * TOOL_ENTRY_SIZE) for i in range(n)))
        return self._tools


class ErrorReader(_Attached):
    """A client's side of the error channel: the messages the task
    posted, as ``(kind, text)``.

    It starts with the oldest message no reader has taken yet (the
    shared "consumed" mark), so that a message posted before any client
    connected is not lost; from then on it sees every message, whatever
    other readers take (the reference's error channel gives a message to
    the first reader only).  ``lost`` counts the messages that were
    overwritten before this reader got to them (the ring holds
    RING_SIZE).
    """

    def __init__(self, address: int, size: int) -> None:
        super().__init__(address, size)
        self.lost = 0
        self._lock = threading.Lock()
        count = _shm.load64(address + _MSG_COUNT)
        start = min(_shm.load64(address + _MSG_CONSUMED), count)
        if count - start > RING_SIZE:
            self.lost = count - RING_SIZE - start
            start = count - RING_SIZE
        self._next = start

    @property
    def pending(self) -> int:
        """How many messages wait for this reader (at most RING_SIZE);
        takes none of them."""
        count = _shm.load64(self.address + _MSG_COUNT)
        return max(0, min(count - self._next, RING_SIZE))

    def poll(self) -> Optional[tuple[int, str]]:
        """The next message, or None when there is none (never blocks).
        Once the task has closed the channel or died, the messages left
        are still read, then ChannelGone."""
        a = self.address
        with self._lock:
            self._check_block()
            while True:
                count = _shm.load64(a + _MSG_COUNT)
                r = self._next
                if r >= count:
                    self._check_task()
                    return None
                if count - r > RING_SIZE:
                    self.lost += count - RING_SIZE - r
                    r = count - RING_SIZE
                state, kind, text = _shm.slot_read(
                    a + _MSG_SLOTS + (r % RING_SIZE) * _SLOT_SIZE, r,
                    TEXT_SIZE)
                self._next = r + 1
                if state == 1:
                    _shm.raise_to(a + _MSG_CONSUMED, r + 1)
                    return kind, text.decode("utf-8", "surrogateescape")
                # overwritten while we got to it (or garbage): lost
                self.lost += 1
