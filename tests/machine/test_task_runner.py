"""The task thread of ``halsdk run`` (halsdk.machine.runner.TaskRunner):
one task per instance, stepped cycles, a bug inside a cycle leaves the
machine in E-stop and is reported once, the host killed is an answer to
every client and not a hang."""

from __future__ import annotations

import os
import signal

import pytest
from helpers.running_machine import halsdk_command, mill_ini, running_machine

import halsdk
from halsdk.channels.cmdclient import CommandClient
from halsdk.channels.errors import ChannelGone
from halsdk.channels.shmchannel import (
    BLOCK_NAME,
    ErrorReader,
    StatusReader,
)
from halsdk.machine.controller import OPERATOR_ERROR, RCS_DONE, RCS_ERROR
from halsdk.machine.launcher import Launcher
from halsdk.machine.runner import TaskError, TaskRunner
from halsdk.machine.task import TaskState
from halsdk.testing import private_instance_name


@pytest.fixture
def stepped(tmp_path, monkeypatch):
    """The mill started in this process, threads stepped, with a task
    runner whose cycles the test calls itself (no thread)."""
    monkeypatch.setenv("HALSDK_INSTANCE", private_instance_name())
    launcher = Launcher(str(mill_ini(tmp_path)))
    launcher.start(realtime=False)
    runner = None
    try:
        runner = TaskRunner(launcher, realtime=False, cycle_time=0.01)
        yield launcher, runner
    finally:
        if runner is not None:
            runner.stop()
        launcher.shutdown()


def test_a_stepped_cycle_steps_the_servo_thread(stepped):
    launcher, runner = stepped
    before = runner.ctl.motion.status().heartbeat
    for _ in range(5):
        runner.cycle()
    # 10 ms task cycle, 1 ms servo period: 10 servo cycles per task cycle
    assert runner.ctl.motion.status().heartbeat - before == 50
    address, size = launcher.hal.shared_block(BLOCK_NAME)
    snap = StatusReader(address, size).poll()
    assert snap.heartbeat == runner.ctl.heartbeat
    assert snap.task_state == int(TaskState.ESTOP)
    assert snap.ini_filename.endswith("mill.ini")


def test_a_second_task_on_the_instance_is_refused(stepped):
    launcher, runner = stepped
    with pytest.raises(TaskError, match=r"has a task already \(pid \d+\)"):
        TaskRunner(launcher, realtime=False)


def test_a_bug_in_a_cycle_is_reported_once_and_estops(stepped, capsys):
    launcher, runner = stepped
    ctl = runner.ctl
    ctl.issue("state", {"state": int(TaskState.ESTOP_RESET)})
    for _ in range(3):
        runner.cycle()
    ctl.issue("state", {"state": int(TaskState.ON)})
    runner.cycle()
    assert ctl.task.state is TaskState.ON
    address, size = launcher.hal.shared_block(BLOCK_NAME)
    errors = ErrorReader(address, size)
    while errors.poll() is not None:
        pass

    def broken() -> None:
        raise KeyError("boom")
    ctl.cycle = broken                          # type: ignore[method-assign]
    for _ in range(4):
        runner.cycle()
    got = []
    while (m := errors.poll()) is not None:
        got.append(m)
    internal = [t for k, t in got if "internal error" in t]
    assert len(internal) == 1 and got[0][0] == OPERATOR_ERROR
    assert "KeyError" in internal[0] and "E-stop" in internal[0]
    assert ctl.task.state is TaskState.ESTOP
    assert "Traceback" in capsys.readouterr().err      # for the log


def test_commands_through_the_socket_and_their_answers(stepped):
    import threading
    launcher, runner = stepped
    runner.start()                              # the real thread
    client = CommandClient(launcher.hal.private_socket_path("task"))
    try:
        serial = client.send("mdi", line="G0 X1")
        state, why = client.wait(serial, 10)
        assert state == RCS_ERROR and "not on" in why
        serial = client.send("state", state=int(TaskState.ESTOP_RESET))
        assert client.wait(serial, 10) == (RCS_DONE, None)
        assert threading.active_count() >= 2
    finally:
        client.close()


def test_the_host_killed_is_an_answer_not_a_hang(tmp_path):
    with running_machine(tmp_path) as machine:
        hal = halsdk.Hal(machine.instance)
        sock = hal.private_socket_path("task")
        try:
            address, size = hal.shared_block(BLOCK_NAME)
            status = StatusReader(address, size)
            assert status.poll().task_pid == machine.proc.pid
            client = CommandClient(hal.private_socket_path("task"))
            serial = client.send("state", state=int(TaskState.ESTOP_RESET))
            assert client.wait(serial, 10) == (RCS_DONE, None)
            machine.proc.send_signal(signal.SIGKILL)
            machine.proc.wait(timeout=10)
            with pytest.raises(ChannelGone, match="gone"):
                status.poll()
            with pytest.raises(ChannelGone):
                serial = client.send("state", state=int(TaskState.ON))
                client.wait(serial, 10)
        finally:
            hal.close()
    # halrun -U (run by the fixture) removed the dead task's socket too
    assert not os.path.exists(sock)


def test_a_second_halsdk_run_on_the_instance_is_refused(tmp_path):
    import subprocess
    with running_machine(tmp_path) as machine:
        second = subprocess.run(
            halsdk_command() + ["run", str(machine.ini), "--seconds", "1"],
            env=machine.env, capture_output=True, text=True, timeout=60)
        assert second.returncode == 1
        assert f"instance '{machine.instance}' already has a host (pid " \
            f"{machine.proc.pid})" in second.stderr
        assert "Traceback" not in second.stderr


def turn_on_and_home(runner: TaskRunner) -> None:
    ctl = runner.ctl
    for name, args in (("state", {"state": int(TaskState.ESTOP_RESET)}),
                       ("state", {"state": int(TaskState.ON)}),
                       ("home", {"joint": -1})):
        ticket = ctl.issue(name, args)
        for _ in range(200):
            if ticket.done:
                break
            runner.cycle()
        assert ticket.state == RCS_DONE, ticket
    for _ in range(200):
        runner.cycle()
        if all(ctl.motion.status().homed):
            return
    raise AssertionError("not homed")


def test_the_status_follows_a_dwell_and_a_subroutine_call(stepped, tmp_path):
    launcher, runner = stepped
    turn_on_and_home(runner)
    address, size = launcher.hal.shared_block(BLOCK_NAME)
    reader = StatusReader(address, size)
    errors = ErrorReader(address, size)
    (tmp_path / "twice.ngc").write_text(
        "o<twice> sub\nG4 P0.3\no<twice> endsub\n")
    prog = tmp_path / "p.ngc"
    prog.write_text("G21 G90\no<twice> call\nG0 X1\nM2\n")
    ctl = runner.ctl
    ctl.subroutine_path = [str(tmp_path)]
    for name, args in (("mode", {"mode": 2}),
                       ("program_open", {"path": str(prog)}),
                       ("auto", {"action": 0, "line": 0})):
        assert ctl.issue(name, args).state != RCS_ERROR
    levels, delays = set(), []
    for _ in range(100):
        runner.cycle()
        snap = reader.poll()
        levels.add(snap.call_level)
        delays.append(snap.delay_left)
        if snap.interp_state == 1:
            break
    got = []
    while (m := errors.poll()) is not None:
        got.append(m)
    assert not [m for m in got if m[0] == OPERATOR_ERROR], got
    assert levels == {0, 1}
    # the dwell counted down in steps of one task cycle (10 servo periods)
    left = [d for d in delays if d > 0]
    assert left and max(left) <= 0.3 + 1e-9
    assert all(a > b for a, b in zip(left, left[1:]))
    assert snap.position[0] == pytest.approx(1)
