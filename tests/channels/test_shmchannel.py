"""The task's status and error channels in HAL shared memory
(halsdk.channels.shmchannel): every field round trip, padding and
truncation, no torn snapshot while a writer in another process publishes
continuously, refused headers, the task closed or dead, the message ring
(order, wrap, lost count, late readers) and the tool table generation.

Run as a script (``python test_shmchannel.py writer``), this file is the
writer process of the torn-read test.
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import random
import select
import subprocess
import sys
import time
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import halsdk
from halsdk.channels import shmchannel as sc
from halsdk.channels.errors import ChannelError, ChannelGone
from halsdk.channels.shmchannel import (
    BLOCK_NAME,
    RING_SIZE,
    TEXT_SIZE,
    ErrorReader,
    Snapshot,
    StatusReader,
    StatusWriter,
    ToolResult,
    block_size,
)
from halsdk.channels.statusfields import (
    AXIS_FIELDS,
    FIELDS,
    JOINT_FIELDS,
    LAYOUT_VERSION,
    MAX_AXES,
    MAX_JOINTS,
    MAX_SPINDLES,
    MAX_TOOLS,
    SPINDLE_FIELDS,
    TOOL_COMMENT_SIZE,
    TOOL_FIELDS,
)
from halsdk.errors import InvalidError

GROUPS = (("joint", JOINT_FIELDS, MAX_JOINTS), ("axis", AXIS_FIELDS, MAX_AXES),
          ("spindle", SPINDLE_FIELDS, MAX_SPINDLES))
DEFAULT = {"i": 0, "b": False, "d": 0.0, "s": ""}
TYPE = {"i": int, "b": bool, "d": float, "s": str}
NO_FIXTURE_CHECK = settings(
    deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                          HealthCheck.too_slow])


@pytest.fixture
def block(hal) -> tuple[int, int]:
    """The channel's block in the test's private instance."""
    comp = hal.new_component("shmtest")
    return hal.new_shared_block(BLOCK_NAME, block_size(), comp)


@pytest.fixture
def writer(block) -> StatusWriter:
    return StatusWriter(*block, os.getpid())


# ------------------------------------------------------------ the oracle

def cut(text: str, size: int) -> str:
    """What a reader gets of ``text`` sent through ``size`` bytes: the
    longest prefix of whole characters that fits."""
    return text.encode()[:size].decode("utf-8", "ignore")


def reader_view(snap: dict[str, Any], pid: int) -> dict[str, Any]:
    """What a reader must see for a published snapshot mapping: missing
    fields 0/""/False, tuples padded, strings cut, every group padded
    to its maximum with zero dicts."""
    out: dict[str, Any] = {}
    for name, kind, count in FIELDS:
        v = snap.get(name)
        if kind == "s":
            out[name] = cut(v or "", count)
        elif count == 1:
            out[name] = TYPE[kind](DEFAULT[kind] if v is None else v)
        else:
            v = list(v or ())
            out[name] = tuple(TYPE[kind](x) for x in v) + \
                (DEFAULT[kind],) * (count - len(v))
    if snap.get("task_pid") is None:
        out["task_pid"] = pid
    out["closed"] = False
    for name, fields, most in GROUPS:
        rows = list(snap.get(name) or ())
        rows += [{}] * (most - len(rows))
        out[name] = tuple({k: TYPE[kind](row.get(k, DEFAULT[kind]))
                           for k, kind in fields} for row in rows)
    return out


def same(a: Any, b: Any) -> bool:
    """Equal, with NaN equal to NaN (and the types equal too)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return (math.isnan(a) and math.isnan(b)) or a == b
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return a == b


def assert_view(snap: Snapshot, expected: dict[str, Any]) -> None:
    got = snap.as_dict()
    for name, value in expected.items():
        assert same(got[name], value), (name, got[name], value)


# ------------------------------------------------------------ round trip

def text_of(size: int) -> st.SearchStrategy[str]:
    """Strings up to about three times ``size`` bytes, multi-byte
    characters included (so that some are cut mid-character)."""
    chars = st.characters(blacklist_characters="\x00",
                          blacklist_categories=("Cs",))
    short = st.text(chars, max_size=40)
    return st.one_of(short, st.tuples(st.text(chars, min_size=1, max_size=6),
                                      st.integers(0, size)).map(
                                          lambda t: t[0] * t[1]))


INT64 = st.integers(-2**63, 2**63 - 1)
VALUE = {"i": INT64, "b": st.booleans(), "d": st.floats(width=64)}


def field_strategy(kind: str, count: int) -> st.SearchStrategy[Any]:
    if kind == "s":
        return text_of(count)
    if count == 1:
        return VALUE[kind] | st.none()
    return st.lists(VALUE[kind], max_size=count).map(tuple)


def group_strategy(fields, most: int) -> st.SearchStrategy[list[dict]]:
    row = st.fixed_dictionaries({}, optional={k: VALUE[kind]
                                              for k, kind in fields})
    return st.lists(row, max_size=most)


SNAPSHOTS = st.fixed_dictionaries(
    {}, optional={**{name: field_strategy(kind, count)
                     for name, kind, count in FIELDS},
                  **{name: group_strategy(fields, most)
                     for name, fields, most in GROUPS}})


def test_every_field_round_trips(block, writer):
    reader = StatusReader(*block)

    @settings(NO_FIXTURE_CHECK, max_examples=40)
    @given(SNAPSHOTS)
    def check(snap):
        writer.publish(snap)
        assert_view(reader.poll(), reader_view(snap, os.getpid()))

    check()


def test_every_field_has_the_readers_type(block, writer):
    snap = {name: (1 if kind != "s" else "x") if count == 1
            else (1,) * count for name, kind, count in FIELDS}
    writer.publish(snap)
    got = StatusReader(*block).poll()
    for name, kind, count in FIELDS:
        value = getattr(got, name)
        if count == 1 or kind == "s":
            assert type(value) is TYPE[kind], name
        else:
            assert type(value) is tuple and len(value) == count, name
            assert all(type(x) is TYPE[kind] for x in value), name
    for name, _fields, most in GROUPS:
        rows = getattr(got, name)
        assert type(rows) is tuple and len(rows) == most
    assert set(got.as_dict()) == ({n for n, _, _ in FIELDS}
                                  | {"joint", "axis", "spindle", "tool_table"})


def test_a_new_channel_reads_zero_and_the_task_pid(block, writer):
    snap = StatusReader(*block).poll()
    assert_view(snap, reader_view({}, os.getpid()))
    assert snap.task_pid == os.getpid() and snap.file == ""
    assert snap.joint[0]["jointType"] == 0 and snap.tool_table == ()


def test_short_tuples_are_padded_and_long_ones_refused(block, writer):
    writer.publish({"homed": (1, 1, 1), "ain": [0.5],
                    "joint": [{"homed": 1}], "spindle": [{"speed": 9}]})
    snap = StatusReader(*block).poll()
    assert snap.homed == (1, 1, 1) + (0,) * (MAX_JOINTS - 3)
    assert snap.ain[:2] == (0.5, 0.0) and len(snap.ain) == 64
    assert snap.joint[0]["homed"] == 1 and snap.joint[0]["units"] == 0.0
    assert snap.joint[1]["homed"] == 0 and len(snap.joint) == MAX_JOINTS
    assert snap.spindle[0]["speed"] == 9.0
    with pytest.raises(InvalidError, match="'homed' has 17 values"):
        writer.publish({"homed": (0,) * (MAX_JOINTS + 1)})
    with pytest.raises(InvalidError, match="'joint' has 17 entries"):
        writer.publish({"joint": [{}] * (MAX_JOINTS + 1)})


def test_strings_are_cut_at_a_character_boundary(block, writer):
    reader = StatusReader(*block)
    size = dict((n, c) for n, _, c in FIELDS)["file"]
    for text, chars in [("é" * 600, 512),          # 2-byte: cut exactly
                        ("ab" + "€" * 400, 2 + 340),  # 3-byte: cut before one
                        ("a" * size, size), ("😀" * 300, 256)]:
        writer.publish({"file": text})
        got = reader.poll().file
        assert got == text[:chars] and len(got.encode()) <= size


def test_a_value_of_the_wrong_type_names_its_field(block, writer):
    writer.publish({"task_state": 2, "file": "a.ngc"})
    with pytest.raises(InvalidError, match="'task_state'"):
        writer.publish({"task_state": 1.5})
    with pytest.raises(InvalidError, match=r"joint\[2\]\.velocity"):
        writer.publish({"joint": [{}, {}, {"velocity": "fast"}]})
    with pytest.raises(InvalidError, match="'position'"):
        writer.publish({"position": (0.0, "x")})
    snap = StatusReader(*block).poll()      # nothing of those was published
    assert (snap.task_state, snap.file) == (2, "a.ngc")


def test_a_snapshot_is_read_only(block, writer):
    writer.publish({"task_state": 2})
    snap = StatusReader(*block).poll()
    with pytest.raises(AttributeError):
        snap.task_state = 3
    with pytest.raises(AttributeError):
        snap.new_name = 1
    assert snap.task_state == 2
    assert snap == StatusReader(*block).poll()


# ------------------------------------------------------------ torn reads

def variants(seed: int) -> list[dict[str, Any]]:
    """Four snapshots of seed ``seed``; snapshot k differs from the others
    in every field, and its echo_serial_number is (seed + 1) * 4 + k."""
    rng = random.Random(seed)
    base: dict[str, Any] = {}
    for name, kind, count in FIELDS:
        if kind == "s":
            base[name] = "".join(rng.choice("aé€😀/") for _ in
                                 range(rng.randrange(count // 2)))
        elif kind == "d":
            base[name] = [rng.uniform(-1e6, 1e6) for _ in range(count)]
        elif kind == "b":
            base[name] = [rng.random() < 0.5 for _ in range(count)]
        else:
            base[name] = [rng.randrange(-2**40, 2**40) for _ in range(count)]
    for name, fields, most in GROUPS:
        base[name] = [{k: rng.uniform(-1e3, 1e3) if kind == "d"
                       else rng.random() < 0.5 if kind == "b"
                       else rng.randrange(2**30) for k, kind in fields}
                      for _ in range(most)]
    out = []
    for k in range(4):
        snap: dict[str, Any] = {}
        for name, kind, count in FIELDS:
            v = base[name]
            if kind == "s":
                snap[name] = f"{k}{v}"
            elif kind == "b":
                snap[name] = [x ^ bool(k & 1) for x in v]
            else:
                snap[name] = [x + k for x in v]
            if count == 1 and kind != "s":
                snap[name] = snap[name][0]
        for name, fields, _most in GROUPS:
            snap[name] = [{key: (value ^ bool(k & 1)) if kind == "b"
                           else value + k for (key, kind), value in
                           zip(fields, row.values())} for row in base[name]]
        snap["echo_serial_number"] = (seed + 1) * 4 + k
        snap["task_pid"] = None
        out.append(snap)
    return out


def writer_main() -> None:
    """The writer of the torn-read test, in a process of its own: it
    publishes the variants of the last seed read from stdin, round robin,
    as fast as it can, until stdin closes."""
    hal = halsdk.Hal()
    writer = StatusWriter(*hal.shared_block(BLOCK_NAME), os.getpid())
    print("ready", flush=True)
    snaps: list[dict[str, Any]] = [{}]
    n = 0
    while True:
        if n % 8 == 0 and select.select([sys.stdin], [], [], 0)[0]:
            line = sys.stdin.readline()
            if not line:
                break
            snaps = variants(int(line))
        writer.publish(snaps[n % len(snaps)])
        n += 1
    hal.close()


@contextlib.contextmanager
def writer_process(tmp_path) -> Iterator[subprocess.Popen]:
    proc = subprocess.Popen([sys.executable, os.path.abspath(__file__),
                             "writer"], cwd=str(tmp_path), text=True,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    try:
        assert select.select([proc.stdout], [], [], 60)[0], "no writer"
        assert proc.stdout.readline() == "ready\n"
        yield proc
    finally:
        proc.stdin.close()
        try:
            proc.wait(timeout=10)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def test_no_snapshot_is_torn(block, tmp_path):
    """A writer in another process publishes snapshots continuously, each
    different in every field from the one before; every snapshot a reader
    polls is exactly one of them, never a mix."""
    with writer_process(tmp_path) as proc:
        reader = StatusReader(*block)
        assert reader.pid == proc.pid
        views: dict[int, list[dict[str, Any]]] = {}

        @settings(NO_FIXTURE_CHECK, max_examples=12)
        @given(st.integers(0, 2**40))
        def check(seed):
            views[seed] = [reader_view(v, proc.pid) for v in variants(seed)]
            proc.stdin.write(f"{seed}\n")
            proc.stdin.flush()
            seen = set()
            polls = 0
            deadline = time.monotonic() + 60        # a hang guard only
            while len(seen) < 4 or polls < 300:
                assert time.monotonic() < deadline, "the writer stopped"
                snap = reader.poll()
                tag, k = divmod(snap.echo_serial_number, 4)
                tag -= 1
                if tag not in views:
                    continue                # the writer's first, empty one
                want = views[tag][k]
                # the first, a middle and the last field every time, all
                # of them every 16th poll
                assert snap.state == want["state"]
                assert snap.din == want["din"]
                assert snap.spindle[-1] == want["spindle"][-1]
                if polls % 16 == 0:
                    assert_view(snap, want)
                if tag == seed:
                    seen.add(k)
                    polls += 1

        check()


# ------------------------------------------------------------ bad headers

def poke32(addr: int, value: int) -> None:
    ctypes.c_uint32.from_address(addr).value = value


def test_a_block_without_a_writer_is_refused(block):
    with pytest.raises(ChannelError, match="not initialised"):
        StatusReader(*block)


def test_another_layout_version_is_refused_with_both_numbers(block, writer):
    addr, size = block
    poke32(addr + 4, LAYOUT_VERSION + 1)
    for reader in (StatusReader, ErrorReader):
        with pytest.raises(ChannelError, match=f"layout version "
                           f"{LAYOUT_VERSION + 1}, this client reads version "
                           f"{LAYOUT_VERSION}"):
            reader(addr, size)


def test_another_field_table_is_refused(block, writer):
    addr, size = block
    poke32(addr + 28, sc.TABLE_CRC ^ 1)
    with pytest.raises(ChannelError, match="another field table"):
        StatusReader(addr, size)


def test_bad_magic_and_small_blocks_are_refused(block, writer):
    addr, size = block
    with pytest.raises(ChannelError, match="needs"):
        StatusReader(addr, size - 1)
    with pytest.raises(ChannelError, match="needs"):
        StatusWriter(addr, size - 1, os.getpid())
    with pytest.raises(ChannelError, match="too small"):
        StatusReader(addr, 8)
    poke32(addr, 0x12345678)
    with pytest.raises(ChannelError, match="not a task channel"):
        StatusReader(addr, size)


# ------------------------------------------------------------ gone

def test_a_closed_channel_is_gone(block, writer):
    reader = StatusReader(*block)
    writer.post(12, "bye")
    errors = ErrorReader(*block)
    writer.close()
    with pytest.raises(ChannelGone, match=f"pid {os.getpid()}.*closed"):
        reader.poll()
    assert errors.poll() == (12, "bye")     # what was posted is still read
    with pytest.raises(ChannelGone, match="closed"):
        errors.poll()
    with pytest.raises(ChannelError, match="closed"):
        writer.publish({})
    writer.close()                          # twice is fine


def dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_dead_task_is_gone(block):
    StatusWriter(*block, dead_pid())
    with pytest.raises(ChannelGone, match="is dead"):
        StatusReader(*block).poll()
    with pytest.raises(ChannelGone, match="is dead"):
        ErrorReader(*block).poll()


@pytest.mark.parametrize("reap", [True, False], ids=["reaped", "zombie"])
def test_a_task_that_dies_is_gone(block, reap):
    child = subprocess.Popen(["sleep", "60"])
    try:
        StatusWriter(*block, child.pid)
        reader = StatusReader(*block)
        if not reap and not reader._watch.uses_pidfd:
            pytest.skip("no pidfd: a zombie looks alive to kill(pid, 0)")
        reader.poll()
        child.kill()
        if reap:
            child.wait()
        else:
            os.waitid(os.P_PID, child.pid, os.WEXITED | os.WNOWAIT)
        with pytest.raises(ChannelGone, match=f"pid {child.pid}\\) is dead"):
            reader.poll()
    finally:
        child.kill()
        child.wait()


def test_a_writer_stuck_in_an_update_is_reported(block, writer):
    addr, _ = block
    seq = ctypes.c_uint64.from_address(addr + sc._STATUS_SEQ)
    seq.value |= 1                          # odd: in the middle of a write
    reader = StatusReader(*block, timeout=0.05)
    with pytest.raises(ChannelError, match="never finishes an update"):
        reader.poll()
    seq.value += 1
    reader.poll()


def test_a_reused_block_is_gone(block, writer):
    reader = StatusReader(*block)
    ctypes.c_int64.from_address(block[0] + 16).value = os.getpid() + 1
    with pytest.raises(ChannelGone, match="removed or reused"):
        reader.poll()


# ------------------------------------------------------------ messages

def drain(reader: ErrorReader) -> list[tuple[int, str]]:
    out = []
    while (m := reader.poll()) is not None:
        out.append(m)
    return out


def test_messages_arrive_in_order_with_their_kind(block, writer):
    reader = ErrorReader(*block)
    assert reader.poll() is None
    sent = [(k, f"message {i}") for i, k in enumerate([1, 2, 3, 11, 12, 13])]
    for kind, text in sent:
        writer.post(kind, text)
    assert drain(reader) == sent and reader.lost == 0
    with pytest.raises(InvalidError, match="kind 4"):
        writer.post(4, "no such kind")


def test_a_long_message_is_cut_at_a_character_boundary(block, writer):
    writer.post(11, "€" * 1000)
    kind, text = ErrorReader(*block).poll()
    assert kind == 11 and text == "€" * (TEXT_SIZE // 3)
    assert TEXT_SIZE >= 1000


def test_a_late_reader_gets_what_nobody_read(block, writer):
    writer.post(11, "before any reader")
    first = ErrorReader(*block)
    writer.post(12, "second")
    writer.post(12, "third")
    assert first.poll() == (11, "before any reader")
    assert first.poll() == (12, "second")
    late = ErrorReader(*block)              # "third" is still unread
    writer.post(13, "fourth")
    assert drain(late) == [(12, "third"), (13, "fourth")]
    assert drain(first) == [(12, "third"), (13, "fourth")]
    assert ErrorReader(*block).poll() is None   # all consumed


def test_a_reader_that_falls_behind_counts_what_it_lost(block, writer):
    early = ErrorReader(*block)
    for i in range(RING_SIZE + 10):
        writer.post(2, str(i))
    late = ErrorReader(*block)
    for reader in (early, late):
        got = drain(reader)
        assert reader.lost == 10
        assert [t for _, t in got] == [str(i) for i in
                                       range(10, RING_SIZE + 10)]


@settings(deadline=None, max_examples=30)
@given(st.lists(st.tuples(st.sampled_from(["connect", "post", "drain"]),
                          st.integers(0, 2 * RING_SIZE)), max_size=12))
def test_every_reader_sees_every_later_message_or_counts_it(plan):
    """Readers connect and read at random moments while messages go in;
    each gets what a model of the ring says: from the first message
    nobody had read when it connected, in order, the overwritten ones
    counted in ``lost``."""
    with private_channel() as (addr, size, writer):
        # per reader: the reader, its model's next message, lost, got
        readers: list[list[Any]] = []
        posted = consumed = 0

        def drain_all() -> None:
            nonlocal consumed
            for entry in readers:
                reader, nxt, lost, got = entry
                if posted - nxt > RING_SIZE:
                    lost += posted - RING_SIZE - nxt
                    nxt = posted - RING_SIZE
                want = [str(i) for i in range(nxt, posted)]
                assert [t for _, t in drain(reader)] == want
                assert reader.lost == lost
                consumed = max(consumed, posted) if want else consumed
                entry[1:] = [posted, lost, got + want]

        for action, n in plan:
            if action == "connect":
                start = max(consumed, posted - RING_SIZE)
                readers.append([ErrorReader(addr, size), start,
                                start - consumed, []])
            elif action == "post":
                for _ in range(n):
                    writer.post(2, str(posted))
                    posted += 1
            else:
                drain_all()
        drain_all()


@contextlib.contextmanager
def private_channel() -> Iterator[tuple[int, int, StatusWriter]]:
    """A channel in an instance of its own (for hypothesis tests, whose
    examples must not share the function-scoped fixtures)."""
    name = f"pytest-{os.getpid()}-shm{next(_names)}"
    with halsdk.Hal(name, create=True, size=4 << 20) as hal:
        comp = hal.new_component("shmtest")
        addr, size = hal.new_shared_block(BLOCK_NAME, block_size(), comp)
        yield addr, size, StatusWriter(addr, size, os.getpid())


_names = iter(range(10**9))


# ------------------------------------------------------------ tools

def tool(i: int, **kw: Any) -> dict[str, Any]:
    return {"id": i, "zoffset": i / 10, "diameter": 2.0 * i, "pocket": i,
            "orientation": i % 9, "comment": f"tool {i}", **kw}


def test_the_tool_table_round_trips(block, writer):
    reader = StatusReader(*block)
    writer.publish_tools(1, [tool(1), tool(2, comment="€" * 100), {"id": 7}])
    table = reader.poll().tool_table
    assert all(isinstance(t, ToolResult) for t in table)
    assert [t.id for t in table] == [1, 2, 7]
    assert table[0]._asdict() == {**{k: DEFAULT[kind] for k, kind in
                                     TOOL_FIELDS},
                                  **tool(1), "zoffset": 0.1}
    assert table[1].comment == "€" * (TOOL_COMMENT_SIZE // 3)
    assert table[2].pocket == 0 and table[2].comment == ""
    with pytest.raises(InvalidError, match="at most"):
        writer.publish_tools(2, [{"id": 1}] * (MAX_TOOLS + 1))
    with pytest.raises(InvalidError, match="entry 1"):
        writer.publish_tools(2, [tool(1), tool(2, pocket="x")])


def test_the_tool_table_is_copied_only_when_its_generation_changes(block,
                                                                   writer):
    reader = StatusReader(*block)
    writer.publish_tools(5, [tool(1)])
    first = reader.poll().tool_table
    assert reader.poll().tool_table is first        # not copied again
    writer.publish_tools(5, [tool(9)])              # same generation: nothing
    assert reader.poll().tool_table is first
    writer.publish_tools(6, [tool(1), tool(2)])
    assert [t.id for t in reader.poll().tool_table] == [1, 2]
    writer.publish_tools(7, [])
    assert reader.poll().tool_table == ()
    # a reader that connects later gets the current table at once
    writer.publish_tools(8, [tool(i) for i in range(1, MAX_TOOLS + 1)])
    table = StatusReader(*block).poll().tool_table
    assert len(table) == MAX_TOOLS and table[-1].id == MAX_TOOLS


if __name__ == "__main__" and sys.argv[1:] == ["writer"]:
    writer_main()
