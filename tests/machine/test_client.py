"""The native client of a running machine (halsdk.machine.connect) against
a real ``halsdk run`` of the example mill in another process: every
command path, refusals with the task's reasons, the command handles, the
typed status, the error channel, the asyncio helpers, bounded waits, and
the host killed under a client."""

from __future__ import annotations

import asyncio
import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import repo_path
from helpers.docblocks import code_blocks
from helpers.running_machine import client_env, mill_ini, running_machine

import halsdk
from halsdk.channels.cmdproto import RCS_DONE, RCS_ERROR, CommandError
from halsdk.channels.shmchannel import ToolResult
from halsdk.machine import (
    ChannelError,
    ChannelGone,
    Command,
    InterpState,
    MachineClient,
    MachineError,
    MachineTimeout,
    RemoteStatus,
    TaskMode,
    TaskState,
    connect,
)
from halsdk.machine.client import kind_name
from halsdk.machine.remote_status import (
    RemoteAxis,
    RemoteJoint,
    RemoteSpindle,
    exec_state_name,
)
from halsdk.testing import private_instance_name

#: a machine running in real time whose position the tests read exactly:
#: run alone in CI (beside another test the sim's servo lags)
pytestmark = pytest.mark.serial

PART = "G21 G90\nG0 X2 Y1\nG1 X3 F600\nM2\n"
# slow feed moves (1 mm/s): a program that is still running when paused
SLOW = "G21 G90\nG1 X10 F60\nG1 Y10\nG1 X0\nG1 Y0\nM2\n"


def quick_ini(folder: Path) -> Path:
    """The mill with every joint homing where it stands, at 0 (no move)."""
    ini = mill_ini(folder)
    ini.write_text(re.sub(r"^HOME_OFFSET = .*$", "HOME_OFFSET = 0",
                          ini.read_text(), flags=re.M))
    return ini


@pytest.fixture(scope="module")
def machine(tmp_path_factory):
    folder = tmp_path_factory.mktemp("client-machine")
    with running_machine(folder, ini=quick_ini(folder)) as m:
        yield m
    assert "Traceback" not in "".join(m.output)


@pytest.fixture
def m(machine):
    with connect(machine.instance, timeout=10) as client:
        yield client


def ready(c: MachineClient, mode: TaskMode = TaskMode.MANUAL) -> None:
    """Idle, on, homed, overrides at 100 %, in ``mode``; errors drained."""
    c.abort()
    c.wait_for(lambda st: st.interp_state is InterpState.IDLE, 30)
    if c.status().task_state is not TaskState.ON:
        c.estop_reset()
        c.on()
    if not c.status().all_homed:
        c.mode(TaskMode.MANUAL)
        c.home(wait=True, timeout=60)
    c.feed_override(1.0)
    c.rapid_override(1.0)
    c.mode(mode)
    c.errors()


def test_connect_without_a_machine_says_so():
    name = private_instance_name()
    with pytest.raises(ChannelError) as e:
        connect(name)
    assert str(e.value) == (f"no machine is running on instance {name} "
                            "(start one with: halsdk run machine.ini)")
    assert not isinstance(e.value, ChannelGone)
    # nothing was created on the way
    assert not [n for n in os.listdir("/dev/shm") if n.endswith(name)]


def test_connect_to_hal_without_a_task_and_one_instance_per_process():
    name = private_instance_name()
    with halsdk.Hal(name, create=True):
        with pytest.raises(ChannelError, match=re.escape(
                f"no machine is running on instance {name} (HAL runs there, "
                "but no task) (start one with: halsdk run machine.ini)")):
            connect(name)
        other = private_instance_name()
        with pytest.raises(ChannelError, match="one instance per process"):
            connect(other)


def test_the_status_is_typed_and_frozen(m, machine):
    st = m.status()
    assert isinstance(st, RemoteStatus)
    assert isinstance(st.task_state, TaskState)
    assert isinstance(st.task_mode, TaskMode)
    assert isinstance(st.interp_state, InterpState)
    assert st.task_pid == machine.proc.pid == m.task_pid
    assert st.ini_filename == str(machine.ini)
    assert st.axis_names == "XYZ" and st.axis_mask == 7
    assert len(st.joints) == len(st.homed) == len(st.joint_position) == 3
    assert all(isinstance(j, RemoteJoint) for j in st.joints)
    assert [j.index for j in st.joints] == [0, 1, 2]
    assert all(isinstance(a, RemoteAxis) for a in st.axes)
    assert st.axes[0].max_position_limit == 201.0
    assert len(st.spindles) == 1 and isinstance(st.spindles[0], RemoteSpindle)
    assert len(st.position) == len(st.g5x_offset) == 9
    assert len(st.din) == len(st.dout) == 64
    assert all(isinstance(v, bool) for v in st.dout)
    # the example's tool table: the spindle (entry 0), then T1..T4
    assert [t.id for t in st.tool_table][1:5] == [1, 2, 3, 4]
    assert isinstance(st.tool_table[1], ToolResult)
    assert st.tool_table[1].comment == "6 mm end mill"
    assert exec_state_name(st.exec_state) in ("DONE", "WAITING_FOR_MOTION")
    with pytest.raises(dataclasses.FrozenInstanceError):
        st.file = "x"                                   # type: ignore[misc]
    # the raw snapshot is there too, by the reference's names
    assert m.snapshot().joints == 3


def test_a_status_round_trips_through_json(m):
    ready(m)
    m.flood(True)
    st = m.status()
    text = json.dumps(st.as_dict())
    back = RemoteStatus.from_dict(json.loads(text))
    assert back == st
    assert back.heartbeat == st.heartbeat
    assert back.task_state is TaskState.ON and back.flood is True
    assert back.joints == st.joints and back.tool_table == st.tool_table
    assert json.loads(text)["task_state"] == 4      # numbers, as the reference
    # heartbeat apart, an unchanged machine has an equal status
    assert dataclasses.replace(st, heartbeat=st.heartbeat + 7) == st
    assert dataclasses.replace(st, flood=False) != st
    with pytest.raises(halsdk.HalError, match="missing: file"):
        RemoteStatus.from_dict({k: v for k, v in st.as_dict().items()
                                if k != "file"})
    m.flood(False)


def test_state_commands_and_their_refusals(m):
    m.estop()
    st = m.status()
    assert st.task_state is TaskState.ESTOP and st.estop and not st.enabled
    with pytest.raises(MachineError, match=re.escape(
            "machine on refused: the machine is in E-stop (reset the E-stop "
            "first)")):
        m.on()
    with pytest.raises(MachineError, match="needs MDI mode|not on"):
        m.mdi("G0 X1")
    cmd = m.estop_reset()
    assert isinstance(cmd, Command) and cmd.done and cmd.error is None
    assert cmd.state == RCS_DONE
    assert m.status().task_state is TaskState.ESTOP_RESET
    m.on()
    assert m.status().task_state is TaskState.ON and m.status().enabled
    m.off()
    assert m.status().task_state is TaskState.ESTOP_RESET     # as reported
    m.state("on")
    m.state(TaskState.ON)                                   # already: fine
    with pytest.raises(halsdk.HalError, match="expected one of"):
        m.state("sideways")
    # every refusal is on the error channel too
    kinds = m.errors()
    assert (11, "machine on refused: the machine is in E-stop (reset the "
            "E-stop first)") in kinds


def test_home_unhome_and_the_command_handle(m):
    ready(m)
    m.unhome()
    assert m.status().homed == (False, False, False)
    cmd = m.home(wait=True, timeout=60)
    assert cmd.name == "home" and cmd.serial == m.last_serial
    assert cmd.done and cmd.error is None and cmd.state == RCS_DONE
    assert m.status().all_homed
    m.unhome(1)
    assert m.status().homed == (True, False, True)
    cmd = m.home(1)                          # no wait: a handle to wait on
    cmd.wait(60)
    assert m.status().homed == (True, True, True)
    with pytest.raises(MachineError, match=re.escape(
            "home: joint 7 does not exist (the machine has joints 0 to 2)")):
        m.home(7)
    m.mode(TaskMode.MDI)
    with pytest.raises(MachineError, match="home refused: needs MANUAL mode"):
        m.home()
    assert "needs MANUAL mode" in repr(m.errors())


def test_jog_increment_continuous_and_teleop(m):
    ready(m)
    x0 = m.status().position[0]
    m.jog(0, 10.0, 1.0, wait=True, timeout=30)
    assert m.status().position[0] == pytest.approx(x0 + 1.0, abs=1e-6)
    m.jog(0, -10.0, 1.0, wait=True, timeout=30)       # the sign of velocity
    assert m.status().position[0] == pytest.approx(x0, abs=1e-6)
    m.jog(1, 5.0)                                      # continuous
    m.wait_for(lambda st: st.joints[1].velocity > 1.0, 30)
    m.jog_stop(1)
    st = m.wait_for(lambda st: st.inpos and st.joints[1].velocity == 0, 30)
    assert st.position[1] > 0
    with pytest.raises(MachineError, match="needs teleop mode"):
        m.jog("X", 10.0, 1.0)
    m.teleop_enable(True)
    assert m.status().motion_mode == 3
    m.jog("x", 10.0, 1.0, wait=True, timeout=30)
    assert m.status().position[0] == pytest.approx(x0 + 1.0, abs=1e-6)
    m.teleop_enable(False)
    with pytest.raises(halsdk.HalError, match="not an axis letter"):
        m.jog("Q", 1.0)
    with pytest.raises(MachineError, match="joint 5 does not exist"):
        m.jog(5, 1.0, 1.0)


def test_mdi_waits_and_handles(m):
    ready(m, TaskMode.MANUAL)
    with pytest.raises(MachineError, match=re.escape(
            "MDI refused: needs MDI mode (the machine is in MANUAL)")):
        m.mdi("G0 X10")
    m.mode("mdi")
    m.mdi("G21 G90 G0 X10 Y5")
    st = m.status()
    assert st.position[:2] == pytest.approx((10.0, 5.0))
    assert st.command == "G21 G90 G0 X10 Y5"
    first = m.mdi("G0 X1", wait=False)
    second = m.mdi("G0 Y1", wait=False)               # queued behind it
    assert second.serial == first.serial + 1
    second.wait(30)
    first.wait(30)
    assert m.status().position[:2] == pytest.approx((1.0, 1.0))
    # an error while the line runs is the wait's MachineError
    with pytest.raises(MachineError, match="zero feed rate"):
        m.mdi("G1 X5 F0")
    assert any("zero feed rate" in text for _, text in m.errors())


def test_mdi_beyond_a_limit_is_always_the_waits_error(m):
    # motmod refuses the move after the line was read; the command must
    # end in that error, never in "done", however the cycles fall
    for _ in range(5):
        ready(m, TaskMode.MDI)
        m.mdi("G21 G90 G0 X0 Y0 Z0")
        with pytest.raises(MachineError,
                           match="outside the axis limits"):
            m.mdi("G0 X500", timeout=30)
        assert m.status().position[0] == pytest.approx(0.0)


def test_programs_open_relative_to_the_caller_and_run(m, tmp_path,
                                                      monkeypatch):
    ready(m, TaskMode.MDI)
    m.mdi("G21 G90 G0 X0 Y0 Z0")
    (tmp_path / "part.ngc").write_text(PART)
    monkeypatch.chdir(tmp_path)
    m.program_open("part.ngc")
    assert m.status().file == str(tmp_path / "part.ngc")
    with pytest.raises(MachineError, match="needs AUTO mode"):
        m.run()
    m.mode(TaskMode.AUTO)
    cmd = m.run(wait=True, timeout=60)
    assert cmd.done and cmd.error is None
    st = m.status()
    assert st.position[:3] == pytest.approx((3.0, 1.0, 0.0))
    assert st.interp_state is InterpState.IDLE
    # lines before start_line are read, not executed
    (tmp_path / "lines.ngc").write_text("G21 G90\nG0 X5\nG0 Y4\nM2\n")
    m.program_open(tmp_path / "lines.ngc")
    m.run(start_line=3, wait=True, timeout=60)
    assert m.status().position[:2] == pytest.approx((3.0, 4.0))
    with pytest.raises(MachineError, match="No such file"):
        m.program_open("missing.ngc")


def test_pause_step_resume_abort(m, tmp_path):
    ready(m, TaskMode.AUTO)
    (tmp_path / "slow.ngc").write_text(SLOW)
    m.program_open(tmp_path / "slow.ngc")
    with pytest.raises(MachineError, match="pause refused: nothing runs"):
        m.pause()
    with pytest.raises(MachineError, match="resume refused: not paused"):
        m.resume()
    run = m.run()
    assert not run.done
    m.wait_for(lambda st: st.current_vel > 0, 30)
    m.pause()
    st = m.wait_for(lambda st: st.paused, 30)
    assert st.interp_state is InterpState.PAUSED
    m.step()
    m.resume()
    assert m.status().interp_state in (InterpState.READING,
                                       InterpState.WAITING)
    with pytest.raises(MachineError, match="mode MDI refused: the "
                       "interpreter is"):
        m.mode(TaskMode.MDI)
    m.abort()
    with pytest.raises(MachineError, match="aborted"):
        run.wait(30)
    assert run.done and run.error == "aborted" and run.state == RCS_ERROR
    assert m.status().interp_state is InterpState.IDLE


def test_overrides_spindle_coolant_io_and_tools(m):
    ready(m)
    m.feed_override(1.5)
    m.rapid_override(0.5)
    m.max_velocity(30.0)
    m.spindle_override(0.8)
    st = m.status()
    assert (st.feedrate, st.rapidrate, st.max_velocity) == (1.5, 0.5, 30.0)
    assert st.spindles[0].override == 0.8
    with pytest.raises(MachineError, match=re.escape(
            "feedrate: -1.0 is not a scale >= 0")):
        m.feed_override(-1)
    with pytest.raises(MachineError, match="not a scale from 0 to 1"):
        m.rapid_override(2)
    m.spindle_override(1.0)
    m.spindle("forward", 1000)
    sp = m.status().spindles[0]
    assert (sp.direction, sp.speed, sp.enabled) == (1, 1000.0, True)
    m.spindle_off()
    assert m.status().spindles[0].direction == 0
    with pytest.raises(halsdk.HalError, match="spindle direction"):
        m.spindle("sideways")
    m.flood(True)
    m.mist(True)
    assert (m.status().flood, m.status().mist) == (True, True)
    m.flood(False)
    m.mist(False)
    m.set_digital_output(0, True)
    m.set_analog_output(1, 2.5)
    st = m.wait_for(lambda st: st.dout[0], 30)
    assert st.aout[1] == 2.5
    m.set_digital_output(0, False)
    m.set_optional_stop(False)
    m.set_block_delete(True)
    assert (m.status().optional_stop, m.status().block_delete) == \
        (False, True)
    m.set_optional_stop(True)
    m.set_block_delete(False)
    m.set_max_limit("X", 150.0)
    assert m.status().axes[0].max_position_limit == 150.0
    m.set_max_limit(0, 201.0)
    m.debug(0)
    m.tool_offset(3, z=12.5, diameter=2.5)
    t3 = [t for t in m.status().tool_table if t.id == 3][0]
    assert (t3.zoffset, t3.diameter) == (12.5, 2.5)
    m.load_tool_table()                       # the file was saved
    t3 = [t for t in m.status().tool_table if t.id == 3][0]
    assert t3.zoffset == 12.5
    with pytest.raises(MachineError, match="tool 99 is not in the tool "
                       "table"):
        m.tool_offset(99, z=1.0)
    m.reset_interpreter()
    m.task_plan_sync()
    m.set_feed_override(True)
    m.set_spindle_override(True)
    m.set_feed_hold(True)
    m.set_adaptive_feed(False)


def test_bad_arguments_are_refused_before_sending(m):
    serial = m.last_serial
    with pytest.raises(CommandError, match="unknown command 'bogus'"):
        m.command("bogus")
    with pytest.raises(CommandError, match="must be an integer"):
        m.command("home", joint="all")
    with pytest.raises(halsdk.HalError, match="mode 'fast'"):
        m.mode("fast")
    assert m.last_serial == serial              # nothing went out
    assert m.command("debug", level=0).done


def test_messages_reach_every_client(machine, m):
    m.errors()
    with connect(machine.instance) as other:
        other.errors()
        m.text_msg("hello from a client")
        m.display_msg("on the screen")
        m.error_msg("an operator error")
        want = [(12, "hello from a client"), (13, "on the screen"),
                (11, "an operator error")]
        assert m.status().errors_pending == 3
        assert m.errors() == want
        assert m.status().errors_pending == 0
        assert other.errors(limit=1) == want[:1]  # each client sees them all
        assert other.errors() == want[1:]
    assert [kind_name(k) for k, _ in want] == ["text", "display", "error"]
    assert m.kind_name(1) == "error" and kind_name(2) == "text"
    assert m.errors() == [] and m.errors_lost == 0


def test_every_wait_is_bounded(m):
    ready(m, TaskMode.MDI)
    with pytest.raises(MachineTimeout) as e:
        m.wait_for(lambda st: False, timeout=0.05)
    assert isinstance(e.value, TimeoutError) and \
        isinstance(e.value, MachineError)
    crawl = m.mdi("G21 G90 G1 X100 F1", wait=False)      # 100 minutes
    with pytest.raises(MachineTimeout, match="mdi: not done within"):
        crawl.wait(0.05)
    assert not crawl.done and crawl.error is None
    with pytest.raises(MachineTimeout):
        m.mdi("G0 X0", timeout=0.05)           # queued behind the crawl
    m.abort()
    with pytest.raises(MachineError, match="aborted"):
        crawl.wait(30)
    assert crawl.done and crawl.error == "aborted"


def test_asyncio_helpers_never_block_the_loop(m):
    ready(m, TaskMode.MDI)
    m.mdi("G21 G90 G0 X0 Y0")

    async def scenario() -> list[RemoteStatus]:
        ticked = asyncio.Event()

        async def ticker() -> None:
            ticked.set()

        task = asyncio.ensure_future(ticker())
        # only true once the ticker ran: a wait that blocked the loop
        # would never see it
        await m.wait_for_async(lambda st: ticked.is_set(), timeout=30)
        await task
        cmd = m.mdi("G0 X7 Y2", wait=False)
        assert await cmd.wait_async(timeout=30) is cmd
        assert cmd.done and cmd.error is None
        seen = []
        async for st in m.follow(0.01):
            seen.append(st)
            if len(seen) == 1:
                m.mdi("G0 X8", wait=False)
            elif st.position[0] == pytest.approx(8.0) and st.inpos:
                break
        with pytest.raises(MachineTimeout):
            await m.wait_for_async(lambda st: False, timeout=0.05)
        # a line failing in its first cycle may already fail the send
        with pytest.raises(MachineError, match="zero feed rate"):
            bad = m.mdi("G1 X9 F0", wait=False)
            await bad.wait_async(timeout=30)
        return seen

    seen = asyncio.run(asyncio.wait_for(scenario(), 120))
    assert seen[0].position[:2] == pytest.approx((7.0, 2.0))
    assert all(a != b for a, b in zip(seen, seen[1:]))    # changes only


def test_the_python_examples_of_the_docs_run(machine, m):
    m.abort()
    m.estop()                           # where the first example starts
    m.mode(TaskMode.MANUAL)
    m.errors()
    out = []
    for code in code_blocks(repo_path("docs", "ctl.rst"), "python"):
        proc = subprocess.run([sys.executable, "-c", code],
                              env=client_env(machine.instance),
                              capture_output=True, text=True, timeout=120,
                              cwd=str(machine.ini.parent))
        assert proc.returncode == 0, code + proc.stdout + proc.stderr
        out.append(proc.stdout)
    assert len(out) == 3
    assert out[0] == "ON (10.0, 5.0) True\n"
    assert out[1] == "True None 1\n"
    assert out[2].splitlines()[0].startswith(("READING ", "WAITING "))
    assert m.status().position[:2] == pytest.approx((0.0, 0.0))


def test_a_stopped_host_times_out_a_killed_one_is_gone(tmp_path):
    with running_machine(tmp_path, ini=quick_ini(tmp_path)) as machine:
        c = connect(machine.instance, timeout=10)
        socket_path = halsdk.Hal.current().private_socket_path("task")
        try:
            c.estop_reset()
            c.on()
            c.home(wait=True, timeout=60)
            c.mode(TaskMode.MDI)
            crawl = c.mdi("G21 G90 G1 X100 F1", wait=False)
            # stopped: alive but not answering, its status still there
            machine.proc.send_signal(signal.SIGSTOP)
            c.timeout = 0.3
            with pytest.raises(MachineTimeout, match="did not take the "
                               "command within 0.3 s"):
                c.flood(True)
            assert c.status().task_pid == machine.proc.pid
            with pytest.raises(MachineTimeout, match="did not answer within"):
                connect(machine.instance, timeout=0.3)
            machine.proc.send_signal(signal.SIGKILL)
            machine.proc.wait(timeout=30)
            with pytest.raises(ChannelGone, match="the machine is gone"):
                c.status()
            with pytest.raises(ChannelGone, match="the machine is gone"):
                c.on()
            with pytest.raises(ChannelGone):
                crawl.wait(30)
            with pytest.raises(ChannelGone):
                for _ in range(3):          # what was left, then gone
                    c.errors()
            with pytest.raises(ChannelGone):
                asyncio.run(c.wait_for_async(lambda st: False, timeout=30))
            with pytest.raises(ChannelGone, match=re.escape(
                    f"no machine is running on instance {machine.instance}"
                    ": the machine is gone")):
                connect(machine.instance)
        finally:
            c.close()
            c.close()                        # twice is fine
        assert "closed" in repr(c)
        with pytest.raises(ChannelError, match="closed"):
            c.status()
        with pytest.raises(ChannelError, match="no machine is running on "
                           f"instance {machine.instance}"):
            connect(machine.instance)        # a host that is gone
    halsdk.cleanup(machine.instance)
    if os.path.exists(socket_path):
        os.unlink(socket_path)
