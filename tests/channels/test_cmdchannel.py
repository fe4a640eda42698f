"""The task's command channel (issue 17, part B): framing, handshake,
commands and replies, and the faults of clients (garbage, version, killed
mid-frame, not reading) and of the task (gone).

A fake task (a thread calling ``service()`` in a loop, finishing the
submitted commands at its next cycle) stands for the task controller; the
socket lives in the test's tmp_path, so no HAL instance is needed.
"""

from __future__ import annotations

import collections
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator
from typing import Any, Optional

import pytest
from helpers.polling import wait_for
from helpers.processes import ended_at_exit
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from halsdk.channels import cmdproto
from halsdk.channels.cmdclient import CommandClient
from halsdk.channels.cmdproto import (
    COMMANDS,
    MAX_FRAME,
    RCS_DONE,
    RCS_ERROR,
    RCS_EXEC,
    CommandError,
    FrameError,
    FrameReader,
)
from halsdk.channels.cmdserver import CommandServer, Peer
from halsdk.channels.errors import ChannelError, ChannelGone
from halsdk.errors import HalError, InvalidError

# every wait of the tests is bounded by this; none asserts a duration
BOUND = 10.0


# ------------------------------------------------------------ fake task


class FakeTask:
    """A task thread: serves the channel and finishes each submitted
    command at its next cycle (``error_msg`` is refused with its text), in
    order; ``hold()`` keeps them pending until ``release()``."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.submitted: list[tuple[int, str, int, str, dict]] = []
        self.reports: list[str] = []
        self.pending: collections.deque = collections.deque()
        self.failing: set[str] = set()     # names submit() raises for
        self._go = threading.Event()
        self._go.set()
        self._stop = threading.Event()
        self.server = CommandServer(path, self._submit, self.reports.append,
                                    task_pid=os.getpid())
        self.thread = threading.Thread(target=self._run, daemon=True,
                                       name="fake-task")
        self.thread.start()

    def _submit(self, peer: Peer, serial: int, name: str, args: dict) -> None:
        if name in self.failing:
            raise RuntimeError("the fake task is out of order")
        self.submitted.append((peer.pid, peer.name, serial, name, args))
        self.pending.append((peer, serial, name, args))

    def _run(self) -> None:
        while not self._stop.is_set():
            self.server.service(0.01)
            while self._go.is_set() and self.pending:
                peer, serial, name, args = self.pending.popleft()
                if name == "error_msg":
                    self.server.reply(peer, serial, RCS_ERROR,
                                      f"refused: {args['text']}")
                else:
                    self.server.reply(peer, serial, RCS_DONE)

    def hold(self) -> None:
        self._go.clear()

    def release(self) -> None:
        self._go.set()

    def of(self, pid: int) -> list[tuple[int, str, int, str, dict]]:
        return [s for s in self.submitted if s[0] == pid]

    def stop(self) -> None:
        """Stop the thread, then close the server (in this thread, once
        the task thread no longer uses it)."""
        if self.thread.is_alive():
            self._stop.set()
            self.thread.join(BOUND)
            assert not self.thread.is_alive()
        self.server.close()


def socket_path(tmp_path: Any) -> str:
    path = os.path.join(str(tmp_path), "task.sock")
    if len(path) > 100:         # a Unix socket path has at most 107 bytes
        path = os.path.join(tempfile.mkdtemp(prefix="cmd"), "task.sock")
    return path


@pytest.fixture
def task(tmp_path: Any) -> Iterator[FakeTask]:
    fake = FakeTask(socket_path(tmp_path))
    try:
        yield fake
    finally:
        fake.stop()


# ------------------------------------------------------------ raw client


class Raw:
    """A hand-driven client: frames and bytes as a test wants them."""

    def __init__(self, path: str, hello: bool = True,
                 version: int = cmdproto.PROTOCOL_VERSION) -> None:
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.sock.settimeout(BOUND)
        self.sock.connect(path)
        self.reader = FrameReader()
        self.messages: collections.deque = collections.deque()
        if hello:
            self.put(cmdproto.client_hello(os.getpid(), "raw", version))
            self.answer = self.get()

    def put(self, message: dict) -> None:
        self.sock.sendall(cmdproto.encode(message))

    def get(self) -> Optional[dict]:
        """The next frame, None at the end of the stream."""
        while not self.messages:
            for message in self.reader.frames():
                self.messages.append(message)
            if self.messages:
                break
            data = self.sock.recv(65536)
            if not data:
                return None
            self.reader.feed(data)
        return self.messages.popleft()

    def until_closed(self) -> bytes:
        """Read to the end of the stream (the server closed it)."""
        rest = b""
        while True:
            try:
                data = self.sock.recv(65536)
            except ConnectionResetError:
                return rest
            if not data:
                return rest
            rest += data

    def close(self) -> None:
        self.sock.close()


def command(serial: int, name: str, **args: Any) -> dict:
    return {"serial": serial, "cmd": name, "args": args}


# ------------------------------------------------------------- framing


MESSAGES = st.dictionaries(
    st.text(max_size=8),
    st.none() | st.booleans() | st.integers(-10**12, 10**12)
    | st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=40),
    max_size=6)


@given(st.lists(MESSAGES, max_size=8), st.data())
@settings(max_examples=60, deadline=None)
def test_frames_survive_any_split(messages: list[dict], data: Any) -> None:
    stream = b"".join(cmdproto.encode(m) for m in messages)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)),
                                     max_size=6)))
    reader, got, start = FrameReader(), [], 0
    for cut in [*cuts, len(stream)]:
        reader.feed(stream[start:cut])
        start = cut
        got.extend(reader.frames())
    assert got == messages
    assert reader.pending == 0


def framed(body: bytes) -> bytes:
    return len(body).to_bytes(4, "big") + body


@pytest.mark.parametrize("frame, words", [
    (b"\0\0\0\0", "length 0"),
    ((MAX_FRAME + 1).to_bytes(4, "big"), f"at most {MAX_FRAME}"),
    (framed(b"\xff\xfe"), "not UTF-8"),
    (framed(b"{x}"), "not valid JSON"),
    (framed(b"NaN"), "not valid JSON"),
    (framed(b'{"a": NaN}'), "NaN is not a JSON number"),
    (framed(b'{"a": -Infinity}'), "Infinity is not a JSON number"),
    (framed(b"[]"), "JSON array, not an object"),
    (framed(b"4"), "JSON number, not an object"),
    (framed(b"[" * 60000), "not valid JSON"),
])
def test_bad_frames_say_what_is_wrong(frame: bytes, words: str) -> None:
    reader = FrameReader()
    reader.feed(frame)
    with pytest.raises(FrameError, match=words):
        list(reader.frames())


def test_oversize_message_is_not_framed() -> None:
    with pytest.raises(FrameError, match="a frame carries at most 65536"):
        cmdproto.encode({"line": "x" * MAX_FRAME})
    assert len(cmdproto.encode({"line": "x" * 1000})) > 1000


# ------------------------------------------------------------- commands


def test_table_covers_the_reference_command_methods() -> None:
    reference = ["abort", "auto", "brake", "debug", "display_msg",
                 "error_msg", "feedrate", "flood", "home", "jog",
                 "load_tool_table", "maxvel", "mdi", "mist", "mode",
                 "override_limits", "program_open", "rapidrate",
                 "reset_interpreter", "set_adaptive_feed",
                 "set_analog_output", "set_block_delete",
                 "set_digital_output", "set_feed_hold", "set_feed_override",
                 "set_max_limit", "set_min_limit", "set_optional_stop",
                 "set_spindle_override", "spindle", "spindleoverride",
                 "state", "task_plan_synch", "teleop_enable", "text_msg",
                 "tool_offset", "traj_mode", "unhome"]
    assert set(reference) <= set(COMMANDS)
    assert "task_plan_sync" in COMMANDS
    assert cmdproto.canonical("task_plan_synch") == "task_plan_sync"
    assert (cmdproto.RCS_DONE, cmdproto.RCS_EXEC, cmdproto.RCS_ERROR) \
        == (1, 2, 3)
    assert cmdproto.signature("jog") == ("action:int, joint_mode:bool, "
                                         "index:int, velocity:float=0.0, "
                                         "distance:float=0.0")


@pytest.mark.parametrize("name, args, expected", [
    ("home", {"joint": 0}, {"joint": 0}),
    ("home", {"joint": 2.0}, {"joint": 2}),
    ("abort", None, {}),
    ("jog", {"action": 1, "joint_mode": True, "index": 0},
     {"action": 1, "joint_mode": True, "index": 0, "velocity": 0.0,
      "distance": 0.0}),
    ("feedrate", {"scale": 1}, {"scale": 1.0}),
    ("flood", {"on": 1}, {"on": True}),
    ("spindle", {"direction": -1, "speed": 1000},
     {"direction": -1, "speed": 1000.0, "spindle": 0,
      "wait_for_speed": False}),
    ("mdi", {"line": "G0 X1"}, {"line": "G0 X1"}),
    ("task_plan_synch", {}, {}),
])
def test_validate_fills_defaults(name: str, args: Any, expected: dict) -> None:
    got = cmdproto.validate(name, args)
    assert got == expected
    assert [type(v) for v in got.values()] \
        == [type(v) for v in expected.values()]


@pytest.mark.parametrize("name, args, words", [
    ("hom", {}, "unknown command 'hom' .did you mean 'home'.."),
    (7, {}, "the command has no name"),
    ("home", {}, "missing argument 'joint' .home takes joint:int."),
    ("home", {"joint": 0, "axis": 1}, "unknown argument 'axis'"),
    ("home", {"joint": True}, "'joint' must be an integer, got true"),
    ("home", {"joint": 0.5}, "'joint' must be an integer"),
    ("home", {"joint": 1 << 40}, "an integer from -2147483648"),
    ("home", [0], "the arguments must be a JSON object"),
    ("feedrate", {"scale": "1"}, "'scale' must be a finite number"),
    ("feedrate", {"scale": float("inf")}, "finite number"),
    ("feedrate", {"scale": False}, "finite number"),
    ("flood", {"on": 2}, "'on' must be a boolean"),
    ("mdi", {"line": 5}, "'line' must be a string"),
    ("mdi", {"line": "G0\0"}, "without NUL"),
])
def test_validate_says_what_is_wrong(name: Any, args: Any, words: str) -> None:
    with pytest.raises(CommandError, match=words) as info:
        cmdproto.validate(name, args)
    assert isinstance(info.value, HalError)


# ----------------------------------------------------- commands, replies


def test_command_round_trip(task: FakeTask) -> None:
    with CommandClient(task.path, name="ctl") as client:
        assert client.serial == 0 and client.task_pid == os.getpid()
        serial = client.send("home", joint=0)
        assert serial == client.serial == 1
        assert client.wait_received(serial, BOUND)[0] in (RCS_EXEC, RCS_DONE)
        assert client.wait(serial, BOUND) == (RCS_DONE, None)
        assert client.state_of(serial) == RCS_DONE
        assert task.submitted == [(os.getpid(), "ctl", 1, "home",
                                   {"joint": 0})]
        # the task refuses: the reason comes back
        serial = client.send("error_msg", text="no way")
        assert client.wait(serial, BOUND) == (RCS_ERROR, "refused: no way")
        # the channel refuses a bad command; the connection stays
        serial = client.send("home", axis=0)
        state, error = client.wait_received(serial, BOUND)
        assert state == RCS_ERROR and "unknown argument 'axis'" in error
        serial = client.send("task_plan_synch")
        assert client.wait(serial, BOUND) == (RCS_DONE, None)
        assert task.submitted[-1][2:] == (4, "task_plan_sync", {})
        with pytest.raises(InvalidError, match="serial 9 was not sent"):
            client.wait(9, 0)
    assert task.reports == []


def test_wait_times_out_and_resumes(task: FakeTask) -> None:
    task.hold()
    with CommandClient(task.path) as client:
        serial = client.send("mdi", line="G0 X1")
        assert client.wait_received(serial, BOUND) == (RCS_EXEC, None)
        assert client.wait(serial, 0.05) == (-1, None)
        assert client.wait(serial, 0) == (-1, None)
        assert client.state_of(serial) == RCS_EXEC
        task.release()
        assert client.wait(serial, BOUND) == (RCS_DONE, None)


def test_clients_in_threads(task: FakeTask) -> None:
    results: dict[int, list] = {}

    def run(n: int) -> None:
        with CommandClient(task.path, name=f"t{n}") as client:
            serials = [client.send("debug", level=n * 100 + i)
                       for i in range(40)]
            results[n] = [client.wait(s, BOUND) for s in serials]

    threads = [threading.Thread(target=run, args=(n,)) for n in range(5)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(BOUND)
    assert results == {n: [(RCS_DONE, None)] * 40 for n in range(5)}
    for n in range(5):      # each client's commands submitted in its order
        mine = [s for s in task.submitted if s[1] == f"t{n}"]
        assert [(s[2], s[4]["level"]) for s in mine] \
            == [(i + 1, n * 100 + i) for i in range(40)]


def test_one_client_shared_by_threads(task: FakeTask) -> None:
    with CommandClient(task.path) as client:
        outcomes: list = []

        def run() -> None:
            for _ in range(30):
                serial = client.send("abort")
                outcomes.append(client.wait(serial, BOUND))

        threads = [threading.Thread(target=run) for _ in range(4)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join(BOUND)
        assert outcomes == [(RCS_DONE, None)] * 120
        assert sorted(s[2] for s in task.submitted) == list(range(1, 121))


CLIENT = """
import sys
from halsdk.channels.cmdclient import CommandClient
client = CommandClient(sys.argv[1], name="sub")
serials = [client.send("set_digital_output", index=i, value=i % 2 == 0)
           for i in range(20)]
bad = client.send("set_digital_output", index=0)
print([client.wait(s, 10) for s in serials] == [(1, None)] * 20,
      client.wait(bad, 10)[0], client.serial)
"""


def test_clients_in_subprocesses(task: FakeTask) -> None:
    # run in the socket's folder: from the checkout's root, "-c" would
    # import the checkout's (unbuilt) halsdk instead of the installed one
    procs = [subprocess.Popen([sys.executable, "-c", CLIENT, task.path],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, cwd=os.path.dirname(task.path))
             for _ in range(3)]
    for proc in procs:
        with ended_at_exit(proc):
            out, err = proc.communicate(timeout=BOUND * 3)
        assert proc.returncode == 0, err
        assert out.split() == ["True", "3", "21"]
        mine = task.of(proc.pid)
        assert [(s[2], s[4]["index"]) for s in mine] \
            == [(i + 1, i) for i in range(20)]
    assert task.reports == []


def _valid_args(name: str) -> st.SearchStrategy[dict]:
    values = {int: st.integers(-1000, 1000),
              float: st.floats(-1e6, 1e6, allow_nan=False),
              bool: st.booleans(),
              str: st.text(st.characters(blacklist_characters="\0"),
                           max_size=20)}
    required = {a.name: values[a.type] for a in COMMANDS[name] if a.required}
    optional = {a.name: values[a.type] for a in COMMANDS[name]
                if not a.required}
    return st.fixed_dictionaries(required, optional=optional)


VALID = st.sampled_from(sorted(COMMANDS)).flatmap(
    lambda name: st.tuples(st.just(name), _valid_args(name)))
INVALID = st.one_of(
    st.tuples(st.sampled_from(["homee", "", "nope"]), st.just({})),
    st.tuples(st.just("home"), st.just({})),
    st.tuples(st.just("home"), st.fixed_dictionaries(
        {"joint": st.text(max_size=3) | st.booleans() | st.none()})),
    st.tuples(st.just("mdi"), st.just({"line": "G0", "extra": 1})))


def test_every_valid_command_gets_one_final_reply_in_order(
        task: FakeTask) -> None:
    raw = Raw(task.path)
    serial = 0

    @given(st.lists(st.tuples(st.booleans(), VALID, INVALID), max_size=20))
    @settings(max_examples=40, deadline=None,
              suppress_health_check=[HealthCheck.too_slow])
    def check(batch: list) -> None:
        nonlocal serial
        first = serial + 1
        sent: dict[int, tuple[str, dict, bool]] = {}
        frames = b""
        for good, valid, invalid in batch:
            serial += 1
            name, args = valid if good else invalid
            sent[serial] = (name, args, good)
            frames += cmdproto.encode(command(serial, name, **args))
        serial += 1
        frames += cmdproto.encode(command(serial, "abort"))
        raw.sock.sendall(frames)            # all at once: pipelined
        replies: dict[int, list] = collections.defaultdict(list)
        firsts: list[int] = []
        finals: list[int] = []
        while True:
            reply = raw.get()
            assert reply is not None
            if not replies[reply["serial"]]:
                firsts.append(reply["serial"])
            replies[reply["serial"]].append(reply)
            if reply["state"] != RCS_EXEC and len(replies[reply["serial"]]) > 1:
                finals.append(reply["serial"])
            if reply["serial"] == serial and reply["state"] == RCS_DONE:
                break
        # each command is answered (received, or refused) in the order it
        # came; the submitted ones get one final reply each, in order (a
        # refusal by the channel does not wait for the commands before it)
        assert firsts == list(range(first, serial + 1))
        assert finals == [n for n in range(first, serial + 1)
                          if n == serial or sent[n][2]]
        for n, (name, _args, good) in sent.items():
            states = [r["state"] for r in replies[n]]
            if good:
                assert states == [RCS_EXEC,
                                  RCS_ERROR if name == "error_msg"
                                  else RCS_DONE]
            else:
                assert states == [RCS_ERROR]
                assert replies[n][-1]["error"]
        submitted = [s[2] for s in task.submitted if s[2] >= first]
        assert submitted == [n for n in range(first, serial + 1)
                             if n == serial or sent[n][2]]

    try:
        check()
    finally:
        raw.close()
    assert task.reports == []


# ----------------------------------------------------------- handshake


def test_version_mismatch_is_refused_with_words(
        task: FakeTask, monkeypatch: pytest.MonkeyPatch) -> None:
    raw = Raw(task.path, version=2)
    assert raw.answer["ok"] is False
    assert raw.answer["error"] == ("client speaks version 2, this task "
                                   "version 1")
    assert raw.get() is None            # then it closed
    raw.close()
    import halsdk.channels.cmdclient as cmdclient
    monkeypatch.setattr(cmdclient, "PROTOCOL_VERSION", 2)
    with pytest.raises(ChannelError, match="refused this client: client "
                       "speaks version 2, this task version 1"):
        CommandClient(task.path)
    assert wait_for(lambda: len(task.reports) == 2, BOUND)
    assert all("version 2" in r for r in task.reports)


def test_first_frame_must_be_a_hello(task: FakeTask) -> None:
    raw = Raw(task.path, hello=False)
    raw.put(command(1, "abort"))
    answer = raw.get()
    assert answer is not None and answer["ok"] is False
    assert "not the hello" in answer["error"]
    assert raw.get() is None
    assert task.submitted == []
    assert wait_for(lambda: len(task.reports) == 1, BOUND)


def test_a_silent_client_is_dropped(task: FakeTask) -> None:
    task.server.handshake_timeout = 0.1
    raw = Raw(task.path, hello=False)
    raw.until_closed()
    assert wait_for(lambda: len(task.reports) == 1, BOUND)
    assert "sent no hello" in task.reports[0]


def test_another_user_is_refused(task: FakeTask) -> None:
    task.server._uid = os.getuid() + 1      # as if the task ran as another
    with pytest.raises(ChannelError, match="closed the connection during "
                       "the handshake"):
        CommandClient(task.path)
    assert wait_for(lambda: len(task.reports) == 1, BOUND)
    assert f"runs as uid {os.getuid()}" in task.reports[0]


def test_no_machine(tmp_path: Any) -> None:
    path = socket_path(tmp_path)
    with pytest.raises(ChannelError, match="no machine is running on "
                       "instance task .no task socket at"):
        CommandClient(path)
    named = os.path.join(os.path.dirname(path),
                         f"halsdk-{os.getuid()}-mill.task.sock")
    with pytest.raises(ChannelError, match="on instance mill .no task"):
        CommandClient(named)
    stale = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    stale.bind(path)                    # a socket file nobody listens on
    stale.close()
    with pytest.raises(ChannelGone, match="the task that served .* is gone"):
        CommandClient(path)
    # a new task replaces the stale file; a second one is refused
    server = CommandServer(path, lambda *a: None, print, task_pid=1)
    try:
        with pytest.raises(ChannelError, match="another task already "
                           "serves"):
            CommandServer(path, lambda *a: None, print, task_pid=2)
        assert os.stat(path).st_mode & 0o777 == 0o600
    finally:
        server.close()
    assert not os.path.exists(path)
    with open(path, "w"):
        pass
    with pytest.raises(ChannelError, match="not a socket is in the way"):
        CommandServer(path, lambda *a: None, print, task_pid=1)
    with pytest.raises(ChannelError, match="longer than a Unix socket"):
        CommandServer("/tmp/" + "x" * 120, lambda *a: None, print,
                      task_pid=1)


# ---------------------------------------------------------------- faults


def _healthy(task: FakeTask) -> None:
    with CommandClient(task.path, timeout=BOUND) as client:
        assert client.wait(client.send("abort"), BOUND) == (RCS_DONE, None)


@pytest.mark.parametrize("greeted", [False, True])
def test_garbage_closes_that_connection_only(task: FakeTask,
                                             greeted: bool) -> None:
    @given(st.binary(max_size=300))
    @settings(max_examples=40, deadline=None,
              suppress_health_check=[HealthCheck.too_slow])
    def check(garbage: bytes) -> None:
        before = len(task.submitted)
        task.reports.clear()
        raw = Raw(task.path, hello=greeted)
        try:
            raw.sock.sendall(garbage)
            raw.sock.shutdown(socket.SHUT_WR)
            rest = raw.until_closed()
        finally:
            raw.close()
        assert len(task.submitted) == before        # nothing applied
        if garbage:             # said once, with the client's pid
            assert wait_for(lambda: len(task.reports) == 1, BOUND)
            assert f"pid {os.getpid()}" in task.reports[0]
        else:
            assert rest == b"" and not task.reports
        _healthy(task)
        assert len(task.reports) <= 1

    check()


def test_oversize_frame(task: FakeTask) -> None:
    raw = Raw(task.path)
    raw.sock.sendall((MAX_FRAME + 1).to_bytes(4, "big") + b"{")
    assert raw.until_closed() == b""
    raw.close()
    assert wait_for(lambda: len(task.reports) == 1, BOUND)
    assert "a frame of 65537 bytes, at most 65536" in task.reports[0]
    with CommandClient(task.path) as client:
        with pytest.raises(CommandError, match="cannot be sent: .*at most"):
            client.send("mdi", line="x" * MAX_FRAME)
        assert client.serial == 0           # nothing went out
        assert client.wait(client.send("abort"), BOUND) == (RCS_DONE, None)


def test_frame_without_serial(task: FakeTask) -> None:
    raw = Raw(task.path)
    raw.put({"cmd": "abort"})
    assert raw.get() is None
    raw.close()
    assert wait_for(lambda: len(task.reports) == 1, BOUND)
    assert "without a valid serial" in task.reports[0]


HALF = """
import os, socket, sys, time
from halsdk.channels import cmdproto
sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
sock.connect(sys.argv[1])
sock.sendall(cmdproto.encode(cmdproto.client_hello(os.getpid(), "half")))
whole = cmdproto.encode({"serial": 1, "cmd": "abort", "args": {}})
half = cmdproto.encode({"serial": 2, "cmd": "mdi", "args": {"line": "G0"}})
sock.sendall(whole + half[:int(sys.argv[2])])
print("ready", flush=True)
time.sleep(60)
"""


@pytest.mark.parametrize("cut", [2, 11])
def test_client_killed_mid_frame(task: FakeTask, cut: int) -> None:
    proc = subprocess.Popen([sys.executable, "-c", HALF, task.path, str(cut)],
                            stdout=subprocess.PIPE, text=True,
                            cwd=os.path.dirname(task.path))
    with ended_at_exit(proc):
        assert proc.stdout is not None
        assert proc.stdout.readline() == "ready\n"
        assert wait_for(lambda: task.of(proc.pid), BOUND)
        proc.send_signal(signal.SIGKILL)
        proc.wait(BOUND)
    assert wait_for(lambda: not any(p.pid == proc.pid
                                    for p in task.server.peers), BOUND)
    assert [s[2:4] for s in task.of(proc.pid)] == [(1, "abort")]
    assert len(task.reports) == 1
    assert f"pid {proc.pid} ('half')" in task.reports[0]
    assert "middle of a frame" in task.reports[0]
    _healthy(task)


def test_a_client_that_never_reads(task: FakeTask) -> None:
    task.server.max_queued = 32 * 1024
    raw = Raw(task.path)
    other = CommandClient(task.path, name="other")
    frames = b"".join(cmdproto.encode(command(n, "abort"))
                      for n in range(1, 201))
    try:
        for _ in range(400):            # far more than the queue takes
            try:
                raw.sock.sendall(frames)
            except OSError:             # EPIPE / ECONNRESET: dropped
                break
            # the others are still served
            assert other.wait(other.send("abort"), BOUND) == (RCS_DONE, None)
            if task.reports:
                break
        assert wait_for(lambda: len(task.reports) == 1, BOUND)
        assert "stopped reading its replies" in task.reports[0]
        assert f"pid {os.getpid()} ('raw')" in task.reports[0]
        assert wait_for(lambda: [p.name for p in task.server.peers]
                        == ["other"], BOUND)
        assert other.wait(other.send("abort"), BOUND) == (RCS_DONE, None)
        assert len(task.reports) == 1
    finally:
        raw.close()
        other.close()


def test_commands_of_a_client_that_left_go_on(task: FakeTask) -> None:
    task.hold()
    client = CommandClient(task.path, name="gone")
    serials = [client.send("unhome", joint=j) for j in range(3)]
    assert client.wait_received(serials[-1], BOUND) == (RCS_EXEC, None)
    client.close()
    with pytest.raises(ChannelError, match="client is closed"):
        client.send("abort")
    assert wait_for(lambda: not task.server.peers, BOUND)
    task.release()                  # the task replies to a gone peer
    assert wait_for(lambda: not task.pending, BOUND)
    assert [s[2] for s in task.submitted] == [1, 2, 3]
    assert task.reports == []


def test_submit_failure_is_answered(task: FakeTask) -> None:
    task.failing.add("mist")
    with CommandClient(task.path) as client:
        state, error = client.wait(client.send("mist", on=True), BOUND)
        assert state == RCS_ERROR
        assert "could not take command 'mist': the fake task is out" in error
        assert client.wait(client.send("abort"), BOUND) == (RCS_DONE, None)
    assert len(task.reports) == 1


def _gone_check(call: Callable[[], object]) -> None:
    with pytest.raises(ChannelGone, match=r"the machine is gone: the task "
                       rf"\(pid {os.getpid()}\) closed the command channel"):
        call()


def test_task_gone(task: FakeTask) -> None:
    idle = CommandClient(task.path, timeout=BOUND)
    waiting = CommandClient(task.path, timeout=BOUND)
    task.hold()
    serial = waiting.send("home", joint=1)
    assert waiting.wait_received(serial, BOUND) == (RCS_EXEC, None)
    outcome: list = []

    def wait_for_ever() -> None:
        try:
            outcome.append(waiting.wait(serial, None))
        except ChannelError as exc:
            outcome.append(exc)

    thread = threading.Thread(target=wait_for_ever)
    thread.start()
    task.stop()
    thread.join(BOUND)
    assert not thread.is_alive()
    assert isinstance(outcome[0], ChannelGone)
    _gone_check(lambda: idle.send("abort"))
    _gone_check(lambda: idle.send("abort"))        # and on every call after
    _gone_check(lambda: waiting.state_of(serial))
    assert idle.serial == 0
    idle.close()
    waiting.close()


def test_a_done_reply_before_the_end_still_counts(task: FakeTask) -> None:
    client = CommandClient(task.path)
    serial = client.send("abort")
    assert wait_for(lambda: not task.pending and task.submitted, BOUND)
    assert wait_for(lambda: not task.server.peers[0].queued, BOUND)
    task.stop()
    # the reply came before the end: it counts; the next send finds the end
    assert client.wait(serial, BOUND) == (RCS_DONE, None)
    assert client.wait(serial, BOUND) == (RCS_DONE, None)
    _gone_check(lambda: client.send("abort"))
    client.close()


def test_reply_json_is_compact_and_ordered(task: FakeTask) -> None:
    raw = Raw(task.path)
    assert raw.answer == {"hello": "halsdk-task", "version": 1, "ok": True,
                          "task_pid": os.getpid()}
    raw.put(command(5, "abort"))
    assert raw.get() == {"serial": 5, "state": RCS_EXEC}
    assert raw.get() == {"serial": 5, "state": RCS_DONE}
    raw.close()
    assert json.loads(cmdproto.encode({"a": 1})[4:]) == {"a": 1}
