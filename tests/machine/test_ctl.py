"""``halsdk ctl`` (the installed console script) against a real
``halsdk run`` of the example mill: every command, refusals with the
task's reason on one stderr line, the exit codes scripts rely on (0 done,
1 refused, 2 usage, 3 no machine / gone, 4 timed out), ``--json``,
``--follow`` with ``--count`` and Ctrl-C, ``--instance`` and
``--timeout``, and the host killed under a follower."""

from __future__ import annotations

import json
import os
import re
import select
import signal
import subprocess
from pathlib import Path
from typing import Optional

import pytest
from helpers import repo_path
from helpers.docblocks import code_blocks
from helpers.running_machine import (
    client_env,
    halsdk_command,
    mill_ini,
    running_machine,
)

import halsdk
from halsdk.machine import (
    InterpState,
    RemoteStatus,
    TaskState,
    connect,
)
from halsdk.machine.ctl import main as ctl_main
from halsdk.testing import private_instance_name

SLOW = "G21 G90\nG1 X10 F60\nG1 Y10\nG1 X0\nG1 Y0\nM2\n"
LABELS = ("task state", "mode", "interp", "exec", "file", "line",
          "position", "homed", "tool", "overrides", "spindle", "coolant",
          "errors")


def quick_ini(folder: Path) -> Path:
    """The mill with every joint homing where it stands, at 0 (no move)."""
    ini = mill_ini(folder)
    ini.write_text(re.sub(r"^HOME_OFFSET = .*$", "HOME_OFFSET = 0",
                          ini.read_text(), flags=re.M))
    return ini


@pytest.fixture(scope="module")
def machine(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ctl-machine")
    with running_machine(folder, ini=quick_ini(folder)) as m:
        yield m
    assert "Traceback" not in "".join(m.output)


def ctl(env: dict, *args: str, cwd: Optional[Path] = None,
        timeout: float = 60) -> subprocess.CompletedProcess:
    proc = subprocess.run(halsdk_command() + ["ctl", *args], env=env,
                          capture_output=True, text=True, timeout=timeout,
                          cwd=None if cwd is None else str(cwd))
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc


def ok(env: dict, *args: str, cwd: Optional[Path] = None) -> str:
    proc = ctl(env, *args, cwd=cwd)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    return proc.stdout


def refused(env: dict, *args: str, code: int = 1) -> str:
    """The one stderr line of a failed ctl, without its prefix."""
    proc = ctl(env, *args)
    assert proc.returncode == code, (proc.stdout, proc.stderr)
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("halsdk ctl: "), \
        proc.stderr
    return lines[0][len("halsdk ctl: "):]


def status(env: dict) -> dict:
    """The machine's status, as the native client reads it, in the plain
    form of ``halsdk ctl status --json`` (the setup and the checks use
    the native client: a ctl process takes a good half second)."""
    with connect(env["HALSDK_INSTANCE"]) as c:
        return c.status().as_dict()


def ready(env: dict, mode: str = "manual") -> None:
    """Idle, on, homed, overrides at 100 %, in ``mode``; the errors read
    (by this client: a ctl starts after them)."""
    with connect(env["HALSDK_INSTANCE"], timeout=10) as c:
        c.abort()
        c.wait_for(lambda st: st.interp_state is InterpState.IDLE, 30)
        if c.status().task_state is not TaskState.ON:
            c.estop_reset()
            c.on()
        if not c.status().all_homed:
            c.mode("manual")
            c.home(wait=True, timeout=60)
        c.feed_override(1.0)
        c.rapid_override(1.0)
        c.mode(mode)
        c.errors()


def first_line(proc: subprocess.Popen, timeout: float = 60) -> str:
    """The first line a follower prints (bounded)."""
    assert proc.stdout is not None
    ready_, _, _ = select.select([proc.stdout], [], [], timeout)
    assert ready_, "the follower printed nothing"
    return proc.stdout.readline()


def test_no_machine_is_exit_3_with_one_line():
    name = private_instance_name()
    proc = ctl(client_env(name), "status")
    assert proc.returncode == 3 and proc.stdout == ""
    assert proc.stderr == (f"halsdk ctl: no machine is running on instance "
                           f"{name} (start one with: halsdk run "
                           "machine.ini)\n")
    proc = ctl(client_env(name), "--instance", name + "x", "on")
    assert proc.returncode == 3 and f"instance {name}x " in proc.stderr


def test_usage_errors_are_exit_2_and_help_documents_the_codes(capsys):
    env = client_env(private_instance_name())
    for args in ([], ["fly"], ["mode", "fast"], ["home", "x"],
                 ["feed", "abc"], ["feed", "-1"], ["status", "--count", "0"],
                 ["--timeout", "-1", "status"], ["mdi"], ["run"]):
        assert ctl_main(args) == 2, args        # before any connection
        err = capsys.readouterr().err
        assert "usage: halsdk ctl" in err and "Traceback" not in err
    assert ctl_main(["--help"]) == 0
    out = capsys.readouterr().out
    for code, words in ((0, "done"), (1, "refused or failed"),
                        (2, "usage error"), (3, "no machine"),
                        (4, "timed out")):
        assert re.search(rf"^  {code}\s+{words}", out, re.M), out
    assert ctl_main(["status", "--help"]) == 0
    assert "exit codes" in capsys.readouterr().out
    # the console script: the same codes
    proc = ctl(env, "mode", "fast")
    assert proc.returncode == 2 and "invalid choice" in proc.stderr
    top = subprocess.run(halsdk_command() + ["--help"], capture_output=True,
                         text=True, timeout=60, env=env)
    assert top.returncode == 0 and "ctl" in top.stdout and "run" in top.stdout


def test_state_commands(machine):
    env = machine.env
    ok(env, "estop")
    st = json.loads(ok(env, "status", "--json"))
    assert st["task_state"] == 1 and st["estop"] is True
    assert refused(env, "on") == ("machine on refused: the machine is in "
                                  "E-stop (reset the E-stop first)")
    ok(env, "estop-reset")
    assert status(env)["task_state"] == 2
    ok(env, "on")
    st = status(env)
    assert st["task_state"] == 4 and st["enabled"] is True
    ok(env, "off")
    assert status(env)["task_state"] == 2
    ok(env, "on")


def test_status_prints_a_readable_block(machine):
    ready(machine.env)
    out = ok(machine.env, "status")
    rows = dict((line[:12].strip(), line[13:]) for line in out.splitlines())
    assert tuple(rows) == LABELS
    assert rows["task state"] == "ON" and rows["mode"] == "MANUAL"
    assert rows["interp"] == "IDLE" and rows["exec"] == "DONE"
    assert rows["homed"] == "all (3 joints)"
    assert re.fullmatch(r"X -?\d+\.\d{3}  Y -?\d+\.\d{3}  Z -?\d+\.\d{3}",
                        rows["position"])
    assert rows["overrides"] == "feed 100%  rapid 100%  spindle 100%"
    assert rows["errors"] == "0 unread"


def test_status_json_is_a_remote_status(machine):
    out = ok(machine.env, "status", "--json")
    assert len(out.splitlines()) == 1
    back = RemoteStatus.from_dict(json.loads(out))
    assert back.task_pid == machine.proc.pid
    assert back.ini_filename == str(machine.ini)


def test_mode_home_and_unhome(machine):
    env = machine.env
    ready(env)
    ok(env, "unhome")
    assert status(env)["homed"] == [False, False, False]
    ok(env, "home", "--wait")
    assert status(env)["homed"] == [True, True, True]
    ok(env, "unhome", "1")
    assert status(env)["homed"] == [True, False, True]
    ok(env, "home", "1", "--wait")
    assert status(env)["homed"] == [True, True, True]
    assert refused(env, "home", "7") == ("home: joint 7 does not exist (the "
                                         "machine has joints 0 to 2)")
    ok(env, "mode", "mdi")
    assert status(env)["task_mode"] == 3
    assert refused(env, "home").startswith("home refused: needs MANUAL mode")
    ok(env, "mode", "auto")
    assert status(env)["task_mode"] == 2


def test_mdi(machine):
    env = machine.env
    ready(env, "manual")
    assert refused(env, "mdi", "G0 X10") == ("MDI refused: needs MDI mode "
                                             "(the machine is in MANUAL)")
    ok(env, "mdi", "--mode", "G21 G90 G0 X10 Y5")     # waits for the moves
    st = status(env)
    assert st["task_mode"] == 3
    assert st["position"][:2] == pytest.approx([10.0, 5.0])
    ok(env, "mdi", "--no-wait", "G0 X0")
    ok(env, "mdi", "G0 Y0")                            # runs after it
    assert status(env)["position"][:2] == pytest.approx([0.0, 0.0])
    assert "zero feed rate" in refused(env, "mdi", "G1 X5 F0")


def test_run(machine, tmp_path):
    env = machine.env
    ready(env, "mdi")
    ok(env, "mdi", "G21 G90 G0 X0 Y0 Z0")
    (tmp_path / "part.ngc").write_text("G21 G90\nG0 X2 Y1\nG1 X3 F600\nM2\n")
    proc = ctl(env, "run", "part.ngc", cwd=tmp_path)
    assert proc.returncode == 1 and proc.stderr == (
        "halsdk ctl: program run refused: needs AUTO mode (the machine is "
        "in MDI)\n")
    ok(env, "run", "--mode", "--wait", "part.ngc", cwd=tmp_path)
    st = status(env)
    assert st["file"] == str(tmp_path / "part.ngc")
    assert st["position"][:3] == pytest.approx([3.0, 1.0, 0.0])
    assert st["interp_state"] == 1 and st["task_mode"] == 2
    (tmp_path / "lines.ngc").write_text("G21 G90\nG0 X5\nG0 Y4\nM2\n")
    ok(env, "run", "--wait", "--start-line", "3", "lines.ngc", cwd=tmp_path)
    assert status(env)["position"][:2] == pytest.approx([3.0, 4.0])
    proc = ctl(env, "run", "missing.ngc", cwd=tmp_path)
    assert proc.returncode == 1 and "No such file" in proc.stderr


def test_pause_step_resume_abort(machine, tmp_path):
    env = machine.env
    ready(env, "auto")
    assert refused(env, "pause") == "pause refused: nothing runs"
    assert refused(env, "resume") == "resume refused: not paused"
    assert refused(env, "step") == "step refused: pause first"
    (tmp_path / "slow.ngc").write_text(SLOW)
    ok(env, "run", "slow.ngc", cwd=tmp_path)
    assert status(env)["interp_state"] in (2, 4)
    ok(env, "pause")
    assert status(env)["interp_state"] == 3
    ok(env, "step")
    ok(env, "resume")
    assert status(env)["interp_state"] in (2, 4)
    ok(env, "abort")
    assert status(env)["interp_state"] == 1


def test_feed_and_rapid_overrides(machine):
    env = machine.env
    ready(env)
    ok(env, "feed", "150%")
    assert status(env)["feedrate"] == 1.5
    ok(env, "feed", "0.8")
    ok(env, "rapid", "0.5")
    st = status(env)
    assert (st["feedrate"], st["rapidrate"]) == (0.8, 0.5)
    assert "overrides    feed 80%  rapid 50%" in ok(env, "status")
    assert refused(env, "rapid", "2") == ("rapidrate: 2.0 is not a scale "
                                          "from 0 to 1")
    ok(env, "feed", "1")
    ok(env, "rapid", "1")


def test_errors(machine):
    env = machine.env
    ready(env, "auto")
    refused(env, "pause")                   # posted on the error channel
    assert "errors       1 unread" in ok(env, "status")
    assert ok(env, "errors") == "error: pause refused: nothing runs\n"
    assert ok(env, "errors") == ""          # read: the next one starts after
    refused(env, "resume")
    line = json.loads(ok(env, "errors", "--json"))
    assert line == {"kind": 11, "name": "error",
                    "text": "resume refused: not paused"}
    # --count takes no more than it prints: the others stay for later
    with connect(machine.instance) as c:
        for word in ("one", "two", "three"):
            c.text_msg(word)
    assert ok(env, "errors", "--count", "1") == "text: one\n"
    assert ok(env, "errors") == "text: two\ntext: three\n"


def test_follow_with_count(machine):
    env = machine.env
    ready(env)
    follow = subprocess.Popen(
        halsdk_command() + ["ctl", "status", "--follow", "--json", "--count",
                            "2", "--interval", "0.02"],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        first = json.loads(first_line(follow))
        for i in range(100):                # changes until it has two
            if follow.poll() is not None:
                break
            ok(env, "feed", "1.25" if i % 2 == 0 else "1")
        out, err = follow.communicate(timeout=60)
    finally:
        if follow.poll() is None:
            follow.kill()
            follow.communicate()
    assert follow.returncode == 0 and "Traceback" not in err
    second = json.loads(out.splitlines()[0])
    assert len(out.splitlines()) == 1
    assert RemoteStatus.from_dict(first) != RemoteStatus.from_dict(second)
    ok(env, "feed", "1")


def test_errors_follow_with_count(machine):
    env = machine.env
    ready(env, "auto")
    follow = subprocess.Popen(
        halsdk_command() + ["ctl", "errors", "--follow", "--count", "1",
                            "--interval", "0.02"],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        refused(env, "pause")
        out, err = follow.communicate(timeout=60)
    finally:
        if follow.poll() is None:
            follow.kill()
            follow.communicate()
    assert follow.returncode == 0, err
    assert out == "error: pause refused: nothing runs\n"


def test_ctrl_c_ends_a_follow_with_0(machine):
    follow = subprocess.Popen(
        halsdk_command() + ["ctl", "status", "--follow"], env=machine.env,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert first_line(follow).startswith("task state")
        follow.send_signal(signal.SIGINT)
        out, err = follow.communicate(timeout=60)
    finally:
        if follow.poll() is None:
            follow.kill()
            follow.communicate()
    assert follow.returncode == 0 and err == ""


def test_a_follower_nobody_reads_keeps_whole_lines_and_the_last_state(
        machine):
    """The reader reads only at the end: the pipe fills (a JSON status is
    several KiB), the follower blocks in its write, Ctrl-C comes then.
    Every line is still a whole object, the last one the final state."""
    ready(machine.env)
    follow = subprocess.Popen(
        halsdk_command() + ["ctl", "status", "--follow", "--json",
                            "--interval", "0.01"],
        env=machine.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        with connect(machine.instance) as c:
            assert first_line(follow).startswith(b"{")
            for i in range(30):             # some 150 KiB of statuses
                c.feed_override(1.0 + (i % 2) / 4)
                beat = c.status().heartbeat
                c.wait_for(lambda st, b=beat: st.heartbeat >= b + 5, 30)
            c.feed_override(0.375)
        follow.send_signal(signal.SIGINT)
        out, err = follow.communicate(timeout=60)
    finally:
        if follow.poll() is None:
            follow.kill()
            follow.communicate()
    assert follow.returncode == 0 and err == b""
    statuses = [json.loads(line) for line in out.splitlines()]
    assert statuses[-1]["feedrate"] == 0.375
    ok(machine.env, "feed", "1")


def test_timeout_is_exit_4(machine):
    env = machine.env
    ready(env)
    reason = refused(env, "--timeout", "1", "mdi", "--mode",
                     "G21 G90 G1 X100 F1", code=4)
    assert reason.startswith("mdi: not done within")
    assert "goes on in the machine" in reason
    assert status(env)["interp_state"] != 1            # it does
    ok(env, "abort")


def test_instance_option_before_and_after_the_command(machine):
    env = dict(machine.env)
    del env["HALSDK_INSTANCE"]
    name = machine.instance
    for args in (["--instance", name, "status", "--json"],
                 ["status", "--json", "--instance", name],
                 ["--instance", "elsewhere", "status", "--instance", name,
                  "--json"]):
        assert json.loads(ok(env, *args))["task_pid"] == machine.proc.pid
    assert "timeout" not in ok(env, "--timeout", "10", "--instance", name,
                               "errors")


def test_the_shell_examples_of_the_docs_run(machine, tmp_path):
    with connect(machine.instance) as c:
        c.abort()
        c.estop()                       # where the example starts
        c.mode("manual")
    (tmp_path / "part.ngc").write_text("G21 G90\nG0 X20 Y20 Z1\nM2\n")
    # the installed console script first on PATH, as the page types it
    folder = os.path.dirname(halsdk_command()[0])
    env = dict(machine.env, PATH=folder + os.pathsep + os.environ["PATH"])
    [block] = code_blocks(repo_path("docs", "ctl.rst"), "console")
    outputs = []
    for line in block.splitlines():
        assert line.startswith("$ halsdk ctl ")
        proc = subprocess.run(["bash", "-c", line[2:]], env=env,
                              cwd=str(tmp_path), capture_output=True,
                              text=True, timeout=120)
        assert proc.returncode == 0, (line, proc.stderr)
        outputs.append(proc.stdout)
    assert "position     X 20.000  Y 20.000  Z 1.000" in outputs[-2]
    assert f"file         {tmp_path / 'part.ngc'}" in outputs[-2]


def test_a_stopped_host_is_4_a_killed_one_ends_followers_with_3(
        tmp_path):
    with running_machine(tmp_path, ini=quick_ini(tmp_path)) as machine:
        env = machine.env
        with connect(machine.instance):
            socket_path = halsdk.Hal.current().private_socket_path("task")
        refused(env, "on")                  # a message for the follower
        followers = [subprocess.Popen(
            halsdk_command() + ["ctl", *args], env=env,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for args in (["status", "--follow", "--interval", "0.02"],
                         ["errors", "--follow", "--interval", "0.02"])]
        try:
            assert first_line(followers[0]).startswith("task state")
            assert first_line(followers[1]).startswith("error: machine on "
                                                       "refused")
            # stopped: alive but not answering
            machine.proc.send_signal(signal.SIGSTOP)
            for args in (["on"], ["status"]):
                reason = refused(env, "--timeout", "0.5", *args, code=4)
                assert "did not answer within 0.5 s" in reason
            machine.proc.send_signal(signal.SIGKILL)
            machine.proc.wait(timeout=30)
            results = [f.communicate(timeout=60) for f in followers]
        finally:
            for f in followers:
                if f.poll() is None:
                    f.kill()
                    f.communicate()
        for f, (_out, err) in zip(followers, results):
            assert f.returncode == 3, err
            assert err.startswith("halsdk ctl: the machine is gone") and \
                err.count("\n") == 1, err
        reason = refused(env, "status", code=3)
        assert reason.startswith(f"no machine is running on instance "
                                 f"{machine.instance}")
        assert refused(env, "estop", code=3).startswith("no machine")
    halsdk.cleanup(machine.instance)
    if os.path.exists(socket_path):
        os.unlink(socket_path)
