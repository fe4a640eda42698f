"""Multi-process tests of the halsdk core.

Attached processes, userspace components living in other processes, the
request channel to the host, processes that die (SIGKILL, also while they
hold the instance mutex), stale and foreign instances, and the permissions
of the segment and of the channel.

The children are the small scripts in ``tests/data/multiprocess/``, started
with the test's environment, so they attach to the test's private instance
(the ``hal`` fixture sets ``$HALSDK_INSTANCE``).  They talk to the test with
lines on stdout that are read with a deadline, and every child is killed and
awaited when its test ends, whatever happened.
"""

from __future__ import annotations

import faulthandler
import json
import mmap
import os
import queue
import signal
import stat
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any, Callable, Optional

import pytest
from helpers import data_path

import halsdk
from halsdk.core import _core, channel
from halsdk.errors import ConflictError, InstanceError

DATA = data_path("multiprocess")
SHM_DIR = "/dev/shm"
TIMEOUT = 10.0          # seconds to wait for anything a child should do


# ---------------------------------------------------------------- helpers


class Child:
    """A child Python process whose stdout lines are read with a deadline.

    Two daemon threads drain stdout (into a queue) and stderr (kept for
    error messages), so reading never blocks past its timeout and a chatty
    child never blocks on a full pipe.
    """

    def __init__(self, *args: str):
        self.proc = subprocess.Popen(
            [sys.executable, *args], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            bufsize=1)
        self.pid = self.proc.pid
        self._lines: queue.Queue[Optional[str]] = queue.Queue()
        self._stderr: list[str] = []
        threading.Thread(target=self._pump_stdout, daemon=True).start()
        threading.Thread(target=self._pump_stderr, daemon=True).start()

    def _pump_stdout(self) -> None:
        for line in self.proc.stdout:
            self._lines.put(line.rstrip("\n"))
        self._lines.put(None)

    def _pump_stderr(self) -> None:
        for line in self.proc.stderr:
            self._stderr.append(line)

    def _why(self) -> str:
        err = "".join(self._stderr).strip()
        return f"\n--- stderr of child {self.pid} ---\n{err}" if err else ""

    def readline(self, timeout: float = TIMEOUT) -> str:
        """The next stdout line; AssertionError on timeout or exit."""
        try:
            line = self._lines.get(timeout=timeout)
        except queue.Empty:
            raise AssertionError(f"child {self.pid} printed nothing within "
                                 f"{timeout:g} s{self._why()}") from None
        if line is None:
            self._lines.put(None)           # later reads see the end too
            try:
                code = self.proc.wait(timeout=TIMEOUT)
            except subprocess.TimeoutExpired:
                code = None
            raise AssertionError(f"child {self.pid} closed its stdout "
                                 f"(exit code {code}){self._why()}")
        return line

    def read_json(self, timeout: float = TIMEOUT) -> dict:
        return json.loads(self.readline(timeout))

    def send(self, obj: Any) -> None:
        self.proc.stdin.write(json.dumps(obj) + "\n")
        self.proc.stdin.flush()

    def call(self, method: str, *args: Any, **kwargs: Any) -> dict:
        """Have a driver child call ``Hal.<method>``; its JSON reply."""
        self.send({"call": method, "args": list(args), "kwargs": kwargs})
        return self.read_json()

    def close_stdin(self) -> None:
        try:
            self.proc.stdin.close()
        except OSError:
            pass

    def kill(self) -> int:
        """SIGKILL the child (if still running) and reap it."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
        return self.proc.wait(timeout=TIMEOUT)

    def close(self) -> None:
        try:
            self.kill()
        finally:
            self.close_stdin()
            for stream in (self.proc.stdout, self.proc.stderr):
                try:
                    stream.close()
                except OSError:
                    pass


@pytest.fixture
def spawn() -> Iterator[Callable[..., Child]]:
    """Start scripts of tests/data/multiprocess; all are killed at the end.

    List this fixture after ``hal`` so that the children die before the
    instance is removed.
    """
    children: list[Child] = []

    def start(script: str, *args: str) -> Child:
        child = Child(str(DATA / script), *args)
        children.append(child)
        return child

    try:
        yield start
    finally:
        for child in children:
            child.close()


@pytest.fixture
def no_connection() -> Iterator[None]:
    """For tests that connect by themselves: this process must not use an
    instance yet (one instance per process), and must not keep one."""
    if halsdk.core.instance.current() is not None:
        pytest.fail("this process already uses a HAL instance; an earlier "
                    "test left it open")
    yield
    conn = halsdk.core.instance.current()
    if conn is not None:
        halsdk.core.instance._teardown(conn)
        pytest.fail("the test left this process connected to a HAL instance")


def start_driver(spawn: Callable[..., Child]) -> tuple[Child, dict]:
    """A driver child attached to the test's instance, and its hello."""
    child = spawn("driver.py")
    hello = child.read_json()
    assert hello.get("ready") is True, hello
    return child, hello


def start_echo(spawn: Callable[..., Child], name: str, *flags: str) -> Child:
    """An echo_comp child whose component ``name`` is ready."""
    child = spawn("echo_comp.py", name, *flags)
    assert child.readline() == "ready"
    return child


def ok(reply: dict) -> Any:
    """The result of a successful driver reply."""
    assert reply.get("ok") is True, f"the child's request failed: {reply}"
    return reply["result"]


def failed(reply: dict, cls: type) -> str:
    """The message of a driver reply that failed with exception ``cls``."""
    assert reply.get("ok") is False, f"expected {cls.__name__}: {reply}"
    assert reply["class"] == cls.__name__, reply
    return reply["error"]


def wait_for(predicate: Callable[[], Any], what: str,
             timeout: float = TIMEOUT) -> Any:
    """Poll ``predicate`` until it is true; AssertionError after timeout."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:g} s waiting "
                                 f"for {what}")
        time.sleep(0.002)


def segment_file(instance: Optional[str] = None) -> str:
    """The /dev/shm path of an instance (default: $HALSDK_INSTANCE)."""
    return SHM_DIR + halsdk.core.instance.shm_name(instance)


def remove_instance_files(instance: str) -> None:
    """Last-resort cleanup of an instance left by a test's children."""
    for path in (segment_file(instance),
                 channel.socket_path(halsdk.core.instance.shm_name(instance))):
        try:
            os.unlink(path)
        except FileNotFoundError:
            pass


_TID_MASK = 0x3FFFFFFF      # owner thread id bits of a robust futex word
_HEADER_SCAN = 4096


class MutexOwner:
    """Reads which thread holds the instance mutex, without locking.

    A robust glibc mutex keeps its owner's thread id in its futex word.
    The word is found without knowing the header layout: take the lock from
    a thread of this process and look for the word that turns into that
    thread's id.  ``available`` is False if that fails (another libc).
    """

    def __init__(self, path: str):
        with open(path, "rb") as f:
            self._map = mmap.mmap(f.fileno(), _HEADER_SCAN,
                                  prot=mmap.PROT_READ)
        self.offset: Optional[int] = None
        before = self._words()
        holder = threading.Thread(target=_core.hold_lock_for_test,
                                  args=(0.3,), daemon=True)
        holder.start()
        while holder.is_alive() and self.offset is None:
            for i, word in enumerate(self._words()):
                if before[i] == 0 and word & _TID_MASK == holder.native_id:
                    self.offset = 4 * i
                    break
            time.sleep(0.001)
        holder.join(TIMEOUT)

    def _words(self) -> tuple:
        return struct.unpack_from(f"<{_HEADER_SCAN // 4}i", self._map, 0)

    @property
    def available(self) -> bool:
        return self.offset is not None

    def owner(self) -> int:
        """Thread id of the holder, 0 when the mutex is free."""
        return struct.unpack_from("<i", self._map, self.offset)[0] & _TID_MASK

    def close(self) -> None:
        self._map.close()


# ---------------------------------------------------------------- 1. attach


def test_attached_process_reads_and_writes_host_values(hal, spawn):
    with halsdk.component("host") as comp:
        comp.newpin("in-a", "float", "in")
        comp.newpin("in-u", "u32", "in")
        comp.newpin("out-b", "s32", "out")
        comp.newparam("gain", "float", "rw")
        comp.ready()
        comp["out-b"] = -42
        hal.setp("host.in-a", 1.5)
        hal.setp("host.gain", 0.25)
        hal.newsig("sig-free", "s64")
        hal.sets("sig-free", 123456789012)
        hal.net("sig-driven", "host.out-b")

        child, hello = start_driver(spawn)
        assert hal.is_host is True
        assert hello["is_host"] is False
        assert hello["instance"] == hal.instance

        # listing by glob sees what the host made
        assert ok(child.call("pins", "host.*")) == [
            "host.in-a", "host.in-u", "host.out-b"]
        assert ok(child.call("pins", "host.in-*")) == [
            "host.in-a", "host.in-u"]
        assert ok(child.call("params", "host.*")) == ["host.gain"]
        assert ok(child.call("signals", "sig-*")) == [
            "sig-driven", "sig-free"]
        assert ok(child.call("components", "host")) == ["host"]

        # values set by the host
        assert ok(child.call("getp", "host.in-a")) == 1.5
        assert ok(child.call("getp", "host.out-b")) == -42
        assert ok(child.call("getp", "host.gain")) == 0.25
        assert ok(child.call("gets", "sig-free")) == 123456789012
        assert ok(child.call("gets", "sig-driven")) == -42
        comp["out-b"] = 7                   # read live, not a snapshot
        assert ok(child.call("gets", "sig-driven")) == 7

        # values written by the child
        ok(child.call("setp", "host.in-a", -2.75))
        assert comp["in-a"] == -2.75
        assert hal.getp("host.in-a") == -2.75
        ok(child.call("setp", "host.gain", "4.5"))
        assert comp["gain"] == 4.5
        ok(child.call("sets", "sig-free", -5))
        assert hal.gets("sig-free") == -5

        # the setp/sets rules hold in the child as in the host
        failed(child.call("setp", "host.out-b", 1), halsdk.NotPermittedError)
        failed(child.call("sets", "sig-driven", 1), ConflictError)
        failed(child.call("getp", "host.nothing"), halsdk.NotFoundError)
        assert comp["out-b"] == 7

        # signals and links made by the child are the host's too
        ok(child.call("newsig", "child-sig", "u32"))
        ok(child.call("net", "child-sig", "host.in-u"))
        ok(child.call("sets", "child-sig", 99))
        sig = hal.signal("child-sig")
        assert sig.type == halsdk.U32
        assert sig.readers == 1
        assert hal.pin("host.in-u").signal == sig
        assert comp["in-u"] == 99

        child.send({"exit": True})
        assert child.proc.wait(TIMEOUT) == 0
        hal.check()


# ---------------------------------------------------------------- 2. requests


def test_attached_process_forwards_host_operations(hal, spawn):
    periods: list[int] = []
    hal.add_python_function("host-count", periods.append)
    child, _ = start_driver(spawn)

    # newthread, addf, step: done by the host, visible in the host
    assert ok(child.call("newthread", "req-thread", 1_000_000)) is None
    thread = hal.thread("req-thread")
    assert thread.period == 1_000_000
    assert thread.cycles == 0
    ok(child.call("addf", "host-count", "req-thread"))
    assert thread.functions == ["host-count"]
    assert hal.function("host-count").users == 1
    ok(child.call("step", 5, "req-thread"))
    assert thread.cycles == 5
    assert periods == [1_000_000] * 5
    ok(child.call("step", 3))
    assert thread.cycles == 8
    assert hal.time == 8_000_000

    # start and stop
    ok(child.call("start", False))
    assert thread.running
    wait_for(lambda: thread.cycles > 12, "the started thread to run")
    failed(child.call("step", 1), ConflictError)
    ok(child.call("stop"))
    assert not thread.running
    cycles = thread.cycles
    time.sleep(0.02)
    assert thread.cycles == cycles

    # Python functions are the host's business only
    msg = failed(child.call("add_python_function", "child-fn"),
                 halsdk.NotPermittedError)
    assert "child-fn" in msg
    assert hal.functions("child-fn") == []

    # errors raised in the host come back with their class and message
    failed(child.call("addf", "no-such-funct", "req-thread"),
           halsdk.NotFoundError)
    failed(child.call("newthread", "req-thread", 2_000_000),
           halsdk.ExistsError)
    for op, args in [("addf", ("no-such-funct", "req-thread")),
                     ("newthread", ("req-thread", 2_000_000)),
                     ("delthread", ("no-such-thread",)),
                     ("delf", ("no-such-funct", "req-thread")),
                     ("loadrt", ("nosuchmodule",)),
                     ("unload", ("no-such-comp",))]:
        with pytest.raises(halsdk.HalError) as in_host:
            getattr(hal, op)(*args)
        reply = child.call(op, *args)
        assert reply["ok"] is False, (op, reply)
        assert reply["class"] == type(in_host.value).__name__, (op, reply)
        assert reply["error"] == str(in_host.value), (op, reply)

    # delf and delthread
    ok(child.call("delf", "host-count", "req-thread"))
    assert hal.function("host-count").users == 0
    ok(child.call("delthread", "req-thread"))
    assert hal.threads("req-thread") == []
    assert not thread.exists
    hal.check()


def test_attached_process_loads_realtime_module_through_host(hal, spawn):
    # tand2 is a test component (tests/data/components), built by conftest.py
    child, _ = start_driver(spawn)
    assert ok(child.call("loadrt", "tand2", count=2)) == ["tand2"]
    comp = hal.component("tand2")
    assert comp.realtime
    assert comp.pid == os.getpid()          # loaded into the host
    assert [f.name for f in hal.functions("tand2.*")] == ["tand2.0",
                                                           "tand2.1"]
    failed(child.call("loadrt", "tand2"), halsdk.ExistsError)

    ok(child.call("newthread", "servo", 1_000_000, False))
    ok(child.call("addf", "tand2.0", "servo"))
    ok(child.call("addf", "tand2.1", "servo", 1))
    assert hal.thread("servo").functions == ["tand2.1", "tand2.0"]
    ok(child.call("setp", "tand2.0.in0", True))
    ok(child.call("setp", "tand2.0.in1", 1))
    assert hal.getp("tand2.0.out") is False
    ok(child.call("step", 1))
    assert hal.getp("tand2.0.out") is True
    assert ok(child.call("getp", "tand2.0.out")) is True

    ok(child.call("unloadrt", "tand2"))
    assert hal.components("tand2") == []
    assert hal.pins("tand2.*") == []
    assert hal.thread("servo").functions == []
    hal.check()


# ---------------------------------------------------------------- 3. child comp


def test_child_component_is_visible_and_wired_in_host(hal, spawn):
    child = start_echo(spawn, "childcomp")
    comp = hal.component("childcomp")
    assert comp.pid == child.pid
    assert comp.alive
    assert comp.ready
    assert not comp.realtime
    pins = hal.pins("childcomp.*")
    assert [p.name for p in pins] == [
        "childcomp.beat", "childcomp.in", "childcomp.out", "childcomp.pid"]
    assert {p.owner for p in pins} == {"childcomp"}
    assert hal.pin("childcomp.out").direction == halsdk.OUT

    # an out pin written by the child
    assert hal.getp("childcomp.pid") == child.pid
    beat = hal.getp("childcomp.beat")
    wait_for(lambda: hal.getp("childcomp.beat") != beat,
             "the child's heartbeat pin to change")

    # host-owned nets to the child's pins carry values both ways
    hal.net("cmd", "childcomp.in")
    hal.net("fb", "childcomp.out")
    assert hal.signal("cmd").readers == 1
    assert hal.signal("fb").writers == 1
    for value in (3.25, -7.5, 1e6):
        hal.sets("cmd", value)
        wait_for(lambda v=value: hal.gets("fb") == v,
                 f"the child to echo {value}")
        assert hal.getp("childcomp.out") == value
    hal.check()


# ---------------------------------------------------------------- 4. SIGKILL


def test_sigkill_of_component_process(hal, spawn):
    periods: list[int] = []
    hal.newthread("host-thread", 1_000_000)
    hal.add_python_function("host-tick", periods.append, thread="host-thread")
    thread = hal.thread("host-thread")

    child = start_echo(spawn, "childcomp")
    hal.net("cmd", "childcomp.in")
    hal.net("fb", "childcomp.out")
    hal.sets("cmd", 2.5)
    wait_for(lambda: hal.gets("fb") == 2.5, "the child to echo 2.5")
    comp = hal.component("childcomp")

    hal.start(False)
    wait_for(lambda: len(periods) > 0, "the host thread to run")
    assert child.kill() == -signal.SIGKILL

    # the host lives on, its thread keeps running
    assert comp.exists
    assert not comp.alive
    ticks = len(periods)
    wait_for(lambda: len(periods) > ticks + 10,
             "the host thread to keep running")
    assert thread.running
    hal.check()
    hal.stop()
    cycles = thread.cycles
    hal.step(3)
    assert thread.cycles == cycles + 3

    # the host marks it dead and zeroes the signal its out pin drove
    # (tests/core/test_liveness.py); the signal it read keeps its value
    wait_for(lambda: comp.dead, "the host to mark the component dead")
    assert hal.gets("fb") == 0.0

    # the dead component is removed; its signals stay with their values
    hal.unload("childcomp")
    assert not comp.exists
    assert hal.components("childcomp") == []
    assert hal.pins("childcomp.*") == []
    fb, cmd = hal.signal("fb"), hal.signal("cmd")
    assert fb.value == 0.0
    assert cmd.value == 2.5
    assert (fb.writers, fb.readers, cmd.writers, cmd.readers) == (0, 0, 0, 0)
    hal.check()

    # the name is free again
    with halsdk.component("childcomp") as again:
        again.newpin("out", "float", "out")
        again.ready()
        assert hal.component("childcomp").pid == os.getpid()
        hal.net("fb", "childcomp.out")
        again["out"] = 9.5
        assert hal.gets("fb") == 9.5
    assert hal.components("childcomp") == []
    hal.check()


# ---------------------------------------------------------------- 5. mutex


def test_sigkill_while_holding_instance_mutex(hal, spawn):
    hal.newthread("rt", 1_000_000)
    thread = hal.thread("rt")
    hal.start(False)
    mutex = MutexOwner(segment_file())
    try:
        if mutex.available:
            # the host's watch of userspace components locks now and
            # then (halsdk.core.instance.Reaper)
            wait_for(lambda: mutex.owner() == 0, "the mutex to be free")
        recovered = hal.info()["recovered"]
        child, _ = start_driver(spawn)
        child.send({"hold_lock": 30})
        assert child.read_json() == {"locking": child.pid}
        if mutex.available:
            # the driver holds it from its main thread: tid == pid
            wait_for(lambda: mutex.owner() == child.pid,
                     "the child to hold the instance mutex")
        else:
            time.sleep(0.2)

        # running threads do not take the metadata lock
        cycles = thread.cycles
        wait_for(lambda: thread.cycles > cycles + 5,
                 "the thread to run while the mutex is held")

        assert child.kill() == -signal.SIGKILL
    finally:
        mutex.close()

    # The host locks again.  The core waits for the mutex holding the GIL,
    # so a join timeout alone could not end a hang: faulthandler ends the
    # whole run instead of letting it hang forever.
    # the host's component watch may be the first to lock and recover
    # the mutex (the child's death wakes it); there is one recovery either
    # way
    assert hal.info()["recovered"] in (recovered, recovered + 1)
    result: dict[str, Any] = {}

    def relock() -> None:
        try:
            result["signal"] = hal.newsig("after-kill", "float")
        except BaseException as exc:        # reported below
            result["error"] = exc

    faulthandler.dump_traceback_later(4 * TIMEOUT, exit=True)
    try:
        locker = threading.Thread(target=relock, daemon=True)
        started = time.monotonic()
        locker.start()
        locker.join(TIMEOUT)
        elapsed = time.monotonic() - started
    finally:
        faulthandler.cancel_dump_traceback_later()
    assert not locker.is_alive(), "the host could not lock the instance"
    assert "error" not in result, result
    assert elapsed < 2.0
    assert result["signal"].name == "after-kill"
    assert hal.info()["recovered"] == recovered + 1
    hal.check()
    assert thread.running

    # other processes can lock it too
    other, _ = start_driver(spawn)
    ok(other.call("newsig", "from-other", "bit"))
    assert hal.signal("from-other").type == halsdk.BIT
    assert hal.info()["recovered"] == recovered + 1
    hal.check()


# ---------------------------------------------------------------- 6. unload


def test_unload_live_child_component_terminates_it(hal, spawn):
    child = start_echo(spawn, "childcomp")
    hal.net("fb", "childcomp.out")
    comp = hal.component("childcomp")
    started = time.monotonic()
    hal.unload("childcomp")
    assert time.monotonic() - started < 5.0
    assert child.proc.wait(TIMEOUT) == -signal.SIGTERM
    assert not comp.exists
    assert hal.components("childcomp") == []
    assert hal.pins("childcomp.*") == []
    assert hal.signal("fb").writers == 0
    hal.check()


def test_unload_child_ignoring_sigterm_conflicts(hal, spawn):
    child = start_echo(spawn, "stubborn", "--ignore-term")
    comp = hal.component("stubborn")
    started = time.monotonic()
    with pytest.raises(ConflictError) as err:
        hal.unload("stubborn", timeout=0.5)
    assert 0.5 <= time.monotonic() - started < 5.0
    assert "stubborn" in str(err.value)
    assert str(child.pid) in str(err.value)

    # nothing was removed and the child still works
    assert child.proc.poll() is None
    assert comp.exists and comp.alive
    beat = hal.getp("stubborn.beat")
    wait_for(lambda: hal.getp("stubborn.beat") != beat,
             "the child to keep running")

    assert child.kill() == -signal.SIGKILL
    hal.unload("stubborn")
    assert not comp.exists
    assert hal.pins("stubborn.*") == []
    hal.check()


# ---------------------------------------------------------------- 7. instances


def test_attach_to_missing_instance(no_connection):
    name = f"no-such-instance-{os.getpid()}"
    assert not os.path.exists(segment_file(name))
    with pytest.raises(InstanceError) as err:
        halsdk.Hal(name, create=False)
    assert f"no HAL instance '{name}'" in str(err.value)
    assert not os.path.exists(segment_file(name))     # nothing created
    assert halsdk.core.instance.current() is None


def test_stale_instance_is_reported_and_cleaned_up(no_connection, spawn,
                                                   monkeypatch):
    tag = f"mp-{os.getpid()}-"
    stale, live = tag + "stale", tag + "live"
    other_file = os.path.join(SHM_DIR, "not-halsdk-" + tag + "x")
    try:
        with open(other_file, "wb") as f:       # not ours: never touched
            f.write(b"x")
        dead_host = spawn("host.py", stale)
        assert dead_host.readline() == f"ready {dead_host.pid}"
        live_host = spawn("host.py", live)
        assert live_host.readline() == f"ready {live_host.pid}"
        stale_socket = channel.socket_path(halsdk.core.instance.shm_name(stale))
        assert os.path.exists(segment_file(stale))
        assert os.path.exists(stale_socket)

        assert dead_host.kill() == -signal.SIGKILL
        # a client is told; it neither attaches nor removes anything
        with pytest.raises(InstanceError) as err:
            halsdk.Hal(stale, create=False)
        assert str(err.value) == (f"no HAL instance '{stale}' is running: "
                                  f"its host (pid {dead_host.pid}) is gone")
        assert halsdk.core.instance.current() is None
        assert os.path.exists(segment_file(stale))

        # cleanup() scans /dev/shm; let it see only this test's entries, so
        # that it cannot remove what concurrent test runs are creating
        real_listdir = os.listdir

        def listdir(path: str = ".") -> list[str]:
            names = real_listdir(path)
            if os.path.realpath(path) == os.path.realpath(SHM_DIR):
                names = [n for n in names if tag in n]
            return names

        monkeypatch.setattr(os, "listdir", listdir)
        # the sockets go first, the segment last: another halrun -U that
        # finds the segment gone must find its sockets gone too
        unlinked: list[str] = []
        real_unlink = os.unlink

        def unlink(path: str, *args: Any, **kw: Any) -> None:
            real_unlink(path, *args, **kw)
            unlinked.append(os.path.basename(path))

        monkeypatch.setattr(os, "unlink", unlink)
        removed = halsdk.cleanup()
        monkeypatch.undo()
        assert removed == [halsdk.core.instance.shm_name(stale)[1:]]
        assert unlinked == [os.path.basename(stale_socket), removed[0]]
        assert not os.path.exists(segment_file(stale))
        assert not os.path.exists(stale_socket)
        assert os.path.exists(segment_file(live))
        assert os.path.exists(other_file)
        with pytest.raises(InstanceError, match="no HAL instance"):
            halsdk.Hal(stale, create=False)

        # the live instance was left alone and still works
        with halsdk.Hal(live, create=False) as other:
            assert not other.is_host
            assert other.info()["host_pid"] == live_host.pid
        assert halsdk.core.instance.current() is None
        live_host.close_stdin()
        assert live_host.readline() == "closed"
        assert live_host.proc.wait(TIMEOUT) == 0
        assert not os.path.exists(segment_file(live))
    finally:
        for name in (stale, live):
            remove_instance_files(name)
        os.unlink(other_file)


@pytest.mark.parametrize("create", [True, None])
def test_a_dead_hosts_instance_is_taken_over(no_connection, spawn, capfd,
                                             create):
    name = f"mp-{os.getpid()}-takeover"
    try:
        dead_host = spawn("host.py", name)
        assert dead_host.readline() == f"ready {dead_host.pid}"
        sock = channel.socket_path(halsdk.core.instance.shm_name(name))
        old_inode = os.stat(segment_file(name)).st_ino
        assert dead_host.kill() == -signal.SIGKILL
        capfd.readouterr()
        with halsdk.Hal(name, create=create) as hal:
            assert hal.is_host
            assert hal.info()["host_pid"] == os.getpid()
            assert os.stat(segment_file(name)).st_ino != old_inode
            assert os.path.exists(sock)         # this host's own socket
            hal.newsig("fresh", "float")
            assert [s.name for s in hal.signals()] == ["fresh"]
        err = capfd.readouterr().err
        assert err == (f"halsdk: HAL instance '{name}': its host (pid "
                       f"{dead_host.pid}) is gone; taking the instance "
                       "over\n")
        assert not os.path.exists(segment_file(name))
    finally:
        remove_instance_files(name)


def test_a_live_hosts_instance_is_never_taken_over(no_connection, spawn):
    name = f"mp-{os.getpid()}-live-host"
    try:
        host = spawn("host.py", name)
        assert host.readline() == f"ready {host.pid}"
        inode = os.stat(segment_file(name)).st_ino
        with pytest.raises(InstanceError,
                           match=f"already has a host \\(pid {host.pid}\\)"):
            halsdk.Hal(name, create=True)
        assert os.stat(segment_file(name)).st_ino == inode
    finally:
        remove_instance_files(name)


def test_racing_takeovers_make_one_host(no_connection, spawn):
    # several processes find the same dead host at once: one removes the
    # old segment and hosts, the others attach to that new host; nobody
    # removes the instance another one just created
    name = f"mp-{os.getpid()}-race"
    try:
        dead_host = spawn("host.py", name)
        assert dead_host.readline() == f"ready {dead_host.pid}"
        assert dead_host.kill() == -signal.SIGKILL
        racers = [spawn("take_over.py", name) for _ in range(4)]
        for r in racers:
            assert r.readline(30) == "loaded"
        for r in racers:
            r.proc.stdin.write("go\n")
            r.proc.stdin.flush()
        replies = [json.loads(r.readline(30)) for r in racers]
        hosts = [r for r in replies if r["is_host"]]
        assert len(hosts) == 1, replies
        assert {r["host_pid"] for r in replies} == {hosts[0]["pid"]}
        inode = os.stat(segment_file(name)).st_ino
        assert {r["inode"] for r in replies} == {inode}
    finally:
        remove_instance_files(name)


def test_foreign_segment_is_not_attached(no_connection):
    name = f"junk-{os.getpid()}"
    path = segment_file(name)
    garbage = b"this is not a HAL instance\n" * 200
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        os.write(fd, garbage)
        os.close(fd)
        for create in (False, None, True):
            with pytest.raises(InstanceError) as err:
                halsdk.Hal(name, create=create)
            assert halsdk.core.instance.shm_name(name)[1:] in str(err.value)
            assert "not a halsdk instance" in str(err.value)
        with open(path, "rb") as f:
            assert f.read() == garbage      # left untouched
        assert halsdk.core.instance.current() is None
    finally:
        os.unlink(path)


def test_instance_of_other_abi_version_is_not_attached(no_connection):
    name = f"abi-{os.getpid()}"
    path = segment_file(name)
    with halsdk.Hal(name, create=True, size=1 << 20) as own:
        facts = own.info()
        with open(path, "rb") as f:
            header = bytearray(f.read(_HEADER_SCAN))
    assert not os.path.exists(path)
    # the header starts with the magic (8 bytes) and the ABI version
    assert struct.unpack_from("<I", header, 8)[0] == facts["abi"]
    other_abi = facts["abi"] + 98
    struct.pack_into("<I", header, 8, other_abi)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        os.write(fd, bytes(header))
        os.ftruncate(fd, facts["size"])
        os.close(fd)
        with pytest.raises(InstanceError) as err:
            halsdk.Hal(name, create=False)
        msg = str(err.value)
        assert halsdk.core.instance.shm_name(name) in msg
        assert f"ABI version {other_abi}" in msg
        assert halsdk.core.instance.current() is None
    finally:
        os.unlink(path)


# ---------------------------------------------------------------- 8. modes


def test_segment_and_channel_permissions(hal):
    shm = halsdk.core.instance.shm_name()
    assert shm == f"/halsdk-{os.getuid()}-{hal.instance}"
    seg = os.stat(SHM_DIR + shm)
    assert stat.S_IMODE(seg.st_mode) == 0o600
    assert seg.st_uid == os.getuid()

    sock_path = channel.socket_path(shm)
    sock = os.stat(sock_path)
    assert stat.S_ISSOCK(sock.st_mode)
    assert stat.S_IMODE(sock.st_mode) & 0o077 == 0
    folder = os.stat(os.path.dirname(sock_path))
    assert stat.S_ISDIR(folder.st_mode)
    assert stat.S_IMODE(folder.st_mode) == 0o700
    assert folder.st_uid == os.getuid()

    # it is the live channel of this host
    assert channel.request(shm, "ping") == os.getpid()


def test_idle_client_does_not_block_other_requests(hal):
    """A client that connects and says nothing must not hold up others."""
    import socket as _socket
    import time as _time

    from halsdk.core import channel
    shm = halsdk.core.instance.shm_name(hal.instance)
    idle = _socket.socket(_socket.AF_UNIX, _socket.SOCK_STREAM)
    idle.connect(channel.socket_path(shm))
    try:
        start = _time.monotonic()
        assert channel.request(shm, "ping", timeout=5) == os.getpid()
        assert _time.monotonic() - start < 5
    finally:
        idle.close()
