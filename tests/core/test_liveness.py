"""Liveness: a dead process never leaves outputs alive.

The way a user works: ``halrun -f x.hal`` hosts an instance and starts
programs with ``loadusr``; the host is then SIGKILLed and the programs
must end within a bound (a pidfd watch of the host in every process with
a userspace component; PR_SET_PDEATHSIG for the host's own children).  A
userspace component SIGKILLed in turn is marked ``dead`` by the host,
which sets its out pins (and the signals they drive) to zero.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers import data_path
from helpers.halcompile import child_env, halcompile
from helpers.liveness import (
    BOUND,
    Hosts,
    guards_of,
    hosts_fixture,
    program,
    read_pid,
    tag,
    wait_ended,
)
from helpers.polling import wait_for

COMP_PY = """\
import os, sys, time
import hal
h = hal.component(sys.argv[1])
h.newpin("enable", hal.HAL_BIT, hal.HAL_OUT)
h.newpin("speed", hal.HAL_FLOAT, hal.HAL_OUT)
h.newpin("count", hal.HAL_S32, hal.HAL_OUT)
h.newpin("cmd", hal.HAL_BIT, hal.HAL_IN)
h["enable"] = True
h["speed"] = 2.5
h["count"] = -7
h.ready()
with open(sys.argv[2] + ".tmp", "w") as f:
    f.write(str(os.getpid()))
os.rename(sys.argv[2] + ".tmp", sys.argv[2])
try:
    while True:
        time.sleep(0.05)
except KeyboardInterrupt:       # SIGTERM, as LinuxCNC's hal module does
    raise SystemExit(0)
"""


@pytest.fixture
def hosts(tmp_path: Path) -> Iterator[Hosts]:
    yield from hosts_fixture(tmp_path)


def write_comp(tmp_path: Path) -> Path:
    script = tmp_path / "comp.py"
    script.write_text(COMP_PY)
    return script


# ------------------------------------------------------- the host dies


def test_loadusr_python_component_ends_when_host_is_sigkilled(tmp_path,
                                                              hosts):
    script = write_comp(tmp_path)
    host = hosts.make("py", f"loadusr -Wn victim {sys.executable} {script} "
                      f"victim {tmp_path / 'pid'}\n")
    pid = read_pid(tmp_path / "pid")
    hosts.pids.append(pid)
    host.kill()
    assert wait_ended(pid, 10) < BOUND


def test_component_of_an_attached_halcmd_ends_with_the_host(tmp_path,
                                                            hosts):
    """A program that an attached halcmd started is not a child of the
    host: it watches the host itself, and says why it ends."""
    script = write_comp(tmp_path)
    host = hosts.make("att", "")
    host.up()
    with open(tmp_path / "prog.err", "w+") as err:
        subprocess.run([program("halcmd"), "loadusr", "-Wn", "victim",
                        sys.executable, str(script), "victim",
                        str(tmp_path / "pid")], cwd=tmp_path, env=host.env,
                       stderr=err, stdout=subprocess.DEVNULL, timeout=60,
                       check=True)
        pid = read_pid(tmp_path / "pid")
        hosts.pids.append(pid)
        host_pid = host.proc.pid
        host.kill()
        assert wait_ended(pid, 10) < BOUND
        err.seek(0)
        text = err.read()
    assert (f"comp.py: HAL instance '{tag('att')}': its host (pid "
            f"{host_pid}) is gone; ending (pid {pid})") in text, text
    assert "Traceback" not in text


def test_loadusr_program_without_hal_ends_with_its_host(tmp_path, hosts):
    """PR_SET_PDEATHSIG: any program the host started gets SIGTERM."""
    script, pidfile = plain_program(tmp_path)
    host = hosts.make("plain", f"loadusr {script}\n")
    pid = read_pid(pidfile)
    hosts.pids.append(pid)
    host.kill()
    assert wait_ended(pid, 10) < BOUND


def plain_program(tmp_path: Path) -> tuple[Path, Path]:
    """A shell script that writes its pid and sleeps: no HAL in it."""
    pidfile = tmp_path / "pid"
    script = tmp_path / "plain.sh"
    script.write_text(f"#!/bin/sh\necho $$ > {pidfile}.tmp\n"
                      f"mv {pidfile}.tmp {pidfile}\nexec sleep 60\n")
    script.chmod(0o755)
    return script, pidfile


def test_program_of_an_attached_halcmd_ends_with_the_host(tmp_path, hosts):
    """``loadusr sleep 60`` from another terminal: not the host's child
    and no HAL program, so a halsdk-guard process ends it with the host;
    the halcmd's captured output does not wait for the guard."""
    script, pidfile = plain_program(tmp_path)
    host = hosts.make("attplain", "")
    host.up()
    with open(tmp_path / "halcmd.out", "w+") as out:
        # the program inherits halcmd's output, as in the reference
        subprocess.run([program("halcmd"), "loadusr", str(script)],
                       cwd=tmp_path, env=host.env, stdout=out,
                       stderr=subprocess.STDOUT, timeout=60, check=True)
        out.seek(0)
        assert "Traceback" not in out.read()
    pid = read_pid(pidfile)
    hosts.pids.append(pid)
    guards = guards_of(pid)
    assert len(guards) == 1, guards
    hosts.pids.extend(guards)
    host.kill()
    assert wait_ended(pid, 10) < BOUND
    assert wait_ended(guards[0], 10) < BOUND


def test_guard_ends_with_its_program(tmp_path, hosts):
    """A program that ends first leaves no guard behind, and the host
    lives on."""
    script, pidfile = plain_program(tmp_path)
    host = hosts.make("guardend", "")
    host.up()
    subprocess.run([program("halcmd"), "loadusr", str(script)],
                   cwd=tmp_path, env=host.env, stdout=subprocess.DEVNULL,
                   timeout=60, check=True)
    pid = read_pid(pidfile)
    hosts.pids.append(pid)
    guards = guards_of(pid)
    assert len(guards) == 1, guards
    hosts.pids.extend(guards)
    os.kill(pid, signal.SIGTERM)
    assert wait_ended(guards[0], 10) < BOUND
    assert host.proc.poll() is None


HOST_THREAD_PY = """\
import sys, threading, time
import halsdk
hal = halsdk.Hal(sys.argv[1])
threading.Thread(target=hal.spawn, args=([sys.argv[2]],)).start()
time.sleep(120)
"""


def test_program_started_off_the_main_thread_ends_with_the_host(
        tmp_path, hosts):
    """PR_SET_PDEATHSIG follows the starting thread, which may end long
    before the host: Hal.spawn from another thread uses a guard."""
    script, pidfile = plain_program(tmp_path)
    (tmp_path / "host.py").write_text(HOST_THREAD_PY)
    name = tag("thread")
    host = subprocess.Popen([sys.executable, str(tmp_path / "host.py"),
                             name, str(script)], cwd=tmp_path,
                            env=child_env(HALSDK_INSTANCE=name))
    try:
        pid = read_pid(pidfile)
        hosts.pids.append(pid)
        time.sleep(0.2)             # the starting thread has ended
        assert wait_for(lambda: guards_of(pid), 10)
        hosts.pids.extend(guards_of(pid))
        host.kill()
        host.wait()
        assert wait_ended(pid, 10) < BOUND
    finally:
        if host.poll() is None:
            host.kill()
            host.wait()
        subprocess.run([program("halrun"), "-U"], cwd=tmp_path,
                       env=child_env(HALSDK_INSTANCE=name),
                       capture_output=True, timeout=60)


def test_loadusr_programs_end_when_host_exits_normally(tmp_path, hosts):
    """The host's normal end (here SIGTERM to halrun) ends them too."""
    script = write_comp(tmp_path)
    host = hosts.make("term", f"loadusr -Wn victim {sys.executable} "
                      f"{script} victim {tmp_path / 'pid'}\n")
    pid = read_pid(tmp_path / "pid")
    hosts.pids.append(pid)
    host.proc.terminate()
    host.proc.wait(20)
    assert wait_ended(pid, 10) < BOUND
    assert "Traceback" not in host.stderr()


# ----------------------------------------------- the host is stopped


def test_component_ends_when_its_host_is_stopped(tmp_path, hosts):
    """A stopped host (SIGSTOP, a debugger) runs no thread: a program
    that drives hardware from its pins ends, as with a dead host, saying
    so; the host, continued, finds the component dead."""
    script = write_comp(tmp_path)
    host = hosts.make("stop", f"loadusr -Wn victim {sys.executable} "
                      f"{script} victim {tmp_path / 'pid'}\n"
                      "net en victim.enable\n")
    pid = read_pid(tmp_path / "pid")
    hosts.pids.append(pid)
    # the host is past its loadusr -W (stopped there, it would find the
    # program gone before it was seen ready: an error of the HAL file)
    assert wait_for(lambda: "victim.enable" in host.halcmd(
        "-s", "show", "sig", "en").stdout, 10)
    host_pid = host.proc.pid
    os.kill(host_pid, signal.SIGSTOP)
    try:
        assert wait_ended(pid, 10) < BOUND
    finally:
        os.kill(host_pid, signal.SIGCONT)
    assert wait_for(lambda: "dead" in host.halcmd("-s", "show", "comp",
                                                  "victim").stdout, 10)
    assert host.halcmd("-s", "getp", "victim.enable").stdout.strip() \
        == "FALSE"
    text = host.stderr()
    assert (f"comp.py: HAL instance '{tag('stop')}': its host (pid "
            f"{host_pid}) is stopped; ending (pid {pid})") in text, text
    assert "Traceback" not in text


def test_a_group_stopped_and_continued_together_lives_on(tmp_path, hosts):
    """Ctrl-Z and fg stop and continue the host and its programs
    together: that is no stopped host, and nothing ends."""
    script = write_comp(tmp_path)
    host = hosts.make("group", f"loadusr -Wn victim {sys.executable} "
                      f"{script} victim {tmp_path / 'pid'}\n",
                      new_session=True)
    pid = read_pid(tmp_path / "pid")
    hosts.pids.append(pid)
    for _ in range(5):
        os.killpg(host.proc.pid, signal.SIGSTOP)
        time.sleep(0.2)
        os.killpg(host.proc.pid, signal.SIGCONT)
        time.sleep(0.2)
    assert host.proc.poll() is None
    assert "ready" in host.halcmd("-s", "show", "comp", "victim").stdout
    assert "is stopped" not in host.stderr()


@pytest.fixture(scope="module")
def hcuser(tmp_path_factory: pytest.TempPathFactory) -> str:
    folder = str(tmp_path_factory.mktemp("live-hc"))
    proc = halcompile("--compile", str(data_path("comps", "hcuser.comp")),
                      cwd=folder)
    assert proc.returncode == 0, proc.stderr
    return folder


def test_halcompile_userspace_component_ends_with_the_host(tmp_path, hosts,
                                                           hcuser):
    """user_mainloop is C that never returns to Python: the watch is a
    thread of the core, and SIGTERM ends the program at once."""
    host = hosts.make("hc", "", HALSDK_PATH=hcuser)
    host.up()
    with open(tmp_path / "prog.err", "w+") as err:
        subprocess.run([program("halcmd"), "loadusr", "-W", "hcuser"],
                       cwd=tmp_path, env=host.env, stderr=err,
                       stdout=subprocess.DEVNULL, timeout=60, check=True)
        pid = host.comp_pid("hcuser")
        hosts.pids.append(pid)
        host.kill()
        assert wait_ended(pid, 10) < BOUND
        err.seek(0)
        text = err.read()
    assert "hcuser: HAL instance" in text and "is gone; ending" in text


# ---------------------------------------------- a userspace comp dies


def test_sigkilled_component_is_marked_dead_and_outputs_go_to_zero(
        tmp_path, hosts):
    script = write_comp(tmp_path)
    host = hosts.make("dead", f"loadusr -Wn victim {sys.executable} {script}"
                      f" victim {tmp_path / 'pid'}\n"
                      "net en victim.enable\nnet spd victim.speed\n")
    pid = read_pid(tmp_path / "pid")
    hosts.pids.append(pid)
    assert wait_for(lambda: host.halcmd("-s", "gets", "en", check=False)
                    .stdout.strip() == "TRUE", 20)
    rows = host.halcmd("show", "comp", "victim").stdout
    assert " ready" in rows, rows
    os.kill(pid, signal.SIGKILL)
    assert wait_for(lambda: "dead" in host.halcmd("show", "comp", "victim")
                    .stdout, 10)
    # linked out pins: through the signal; unlinked: the pin itself
    assert host.halcmd("-s", "gets", "en").stdout.strip() == "FALSE"
    assert float(host.halcmd("-s", "gets", "spd").stdout) == 0.0
    assert host.halcmd("-s", "getp", "victim.count").stdout.strip() == "0"
    # listed until unloaded, so that users see what died
    host.halcmd("unloadusr", "victim")
    assert "victim" not in host.halcmd("show", "comp").stdout
    assert host.proc.poll() is None             # the host is fine


def test_dead_component_through_the_python_api(hal, tmp_path):
    """The same through halsdk: the test process is the host."""
    code = textwrap.dedent("""\
        import sys, halsdk
        c = halsdk.component("pyvictim")
        c.newpin("on", "bit", "out")
        c.newpin("io", "s32", "io")
        c["on"] = True
        c["io"] = 5
        c.ready()
        print("ready", flush=True)
        sys.stdin.read()
        """)
    hal.newsig("on", "bit")
    child = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path,
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             text=True, env=child_env())
    try:
        assert child.stdout.readline() == "ready\n"
        hal.net("on", "pyvictim.on")
        assert hal.gets("on") is True
        comp = hal.find("component", "pyvictim")
        assert comp.ready and not comp.dead
        child.kill()
        child.wait()
        assert wait_for(lambda: comp.dead, 10)
        assert not comp.ready
        assert hal.gets("on") is False
        assert hal.getp("pyvictim.io") == 5         # io pins are kept
        hal.unload("pyvictim")
        assert hal.find("component", "pyvictim") is None
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def test_component_that_exits_normally_is_not_marked(hal, tmp_path):
    code = ("import halsdk\nc = halsdk.component('tidy')\n"
            "c.newpin('on', 'bit', 'out')\nc.ready()\nc.exit()\n")
    subprocess.run([sys.executable, "-c", code], cwd=tmp_path, check=True,
                   env=child_env(), timeout=60)
    assert hal.find("component", "tidy") is None


def test_a_ctrl_c_during_the_exit_does_not_cut_the_teardown(tmp_path,
                                                           hosts):
    """A SIGINT and a SIGTERM while the process ends (halrun's unloadusr
    and a user's Ctrl-C together) arrive in the middle of the teardown:
    the teardown still completes, without a traceback."""
    host = hosts.make("ctrlc", "")
    host.up()
    code = textwrap.dedent("""\
        import os, signal, time
        import halsdk
        import halsdk.core.instance as instance
        c = halsdk.component("late")
        c.newpin("out", "bit", "out")
        c.ready()
        real = instance._teardown
        def teardown(conn):
            os.kill(os.getpid(), signal.SIGINT)
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.2)    # the signals are handled before detach
            real(conn)
        instance._teardown = teardown
    """)
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path,
                          env=host.env, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    assert "late" not in host.halcmd("-s", "show", "comp").stdout
