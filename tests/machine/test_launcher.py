"""``halsdk run machine.ini``: start a machine from its INI file, run it,
shut it down cleanly; errors name the file and line."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import repo_path

from halsdk.machine.launcher import Launcher, LaunchError
from halsdk.testing import private_instance_name

MILL = repo_path("examples", "motion", "mill3.ini")


def halsdk_run(tmp_path: Path, *args: str, **kw) -> subprocess.Popen:
    env = dict(os.environ, HALSDK_INSTANCE=private_instance_name())
    return subprocess.Popen([sys.executable, "-m", "halsdk.machine.cli", "run", *args],
                            cwd=str(tmp_path), env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            **kw)


def shm_of(proc_env_instance: str) -> list[str]:
    return [n for n in os.listdir("/dev/shm") if proc_env_instance in n]


def test_runs_the_example_mill_for_a_while(tmp_path):
    proc = halsdk_run(tmp_path, str(MILL), "--seconds", "0.5")
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert "machine running" in out and "stopped" in out


def test_ctrl_c_stops_it_cleanly(tmp_path):
    proc = halsdk_run(tmp_path, str(MILL))
    line = proc.stdout.readline()
    assert "machine running" in line, proc.stderr.read()
    time.sleep(0.2)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err
    assert "stopped" in out


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_missing_halfile_key_is_named(tmp_path):
    ini = write(tmp_path, "m.ini", "[KINS]\nJOINTS = 1\n")
    proc = halsdk_run(tmp_path, str(ini), "--seconds", "0")
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 1
    assert f"{ini}: [HAL]HALFILE is missing" in err


def test_a_failing_hal_file_names_its_line_and_leaves_nothing(tmp_path):
    write(tmp_path, "m.hal", "loadrt and2\nsetp nosuch.pin 1\n")
    ini = write(tmp_path, "m.ini", "[HAL]\nHALFILE = m.hal\n")
    name = private_instance_name()
    env = dict(os.environ, HALSDK_INSTANCE=name)
    proc = subprocess.run([sys.executable, "-m", "halsdk.machine.cli", "run",
                           str(ini)], cwd=str(tmp_path), env=env, text=True,
                          capture_output=True, timeout=60)
    assert proc.returncode == 1
    assert "m.hal:2:" in proc.stderr and "nosuch.pin" in proc.stderr
    assert shm_of(name) == []


def test_a_bad_motion_key_names_the_ini_line(tmp_path):
    text = MILL.read_text().replace("HALFILE = mill3.hal",
                                    f"HALFILE = {MILL.parent / 'mill3.hal'}")
    text = text.replace("MAX_ACCELERATION = 300\nMIN_FERROR",
                        "MAX_ACCELERATION = fast\nMIN_FERROR", 1)
    ini = write(tmp_path, "mill.ini", text)
    number = next(n for n, line in enumerate(text.splitlines(), 1)
                  if "= fast" in line)
    proc = halsdk_run(tmp_path, str(ini), "--seconds", "0")
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1
    assert (f"{ini}:{number}: [JOINT_2]: MAX_ACCELERATION = 'fast' is not a "
            "number") in err


def test_in_process_start_configures_motion(monkeypatch):
    monkeypatch.setenv("HALSDK_INSTANCE", private_instance_name())
    machine = Launcher(str(MILL))
    machine.start(realtime=False)
    try:
        st = machine.motion.status()
        assert [j.vel_limit for j in st.joints[:3]] == [50, 50, 30]
        assert st.joints[2].min_pos_limit == -80
    finally:
        machine.shutdown()
    assert machine.hal is None


def test_an_unreadable_ini_is_an_error(tmp_path):
    with pytest.raises(LaunchError, match="nothing.ini: cannot read"):
        Launcher(str(tmp_path / "nothing.ini"))


PROBE = """\
import signal, sys, time
from halsdk.component import component

with open(sys.argv[1]) as f:                # relative: the INI's folder
    value = int(f.read())
comp = component("probe")
comp.newpin("value", "s32", "out")
comp["value"] = value
comp.ready()


def ended(*_):
    with open("ended", "w") as f:
        f.write("SIGTERM")
    comp.exit()
    sys.exit(0)


signal.signal(signal.SIGTERM, ended)
while True:
    time.sleep(0.02)
"""


def test_hal_files_run_in_the_ini_folder_and_programs_are_ended(tmp_path):
    machine = tmp_path / "machine"
    machine.mkdir()
    write(machine, "probe.py", PROBE)
    write(machine, "probe.conf", "42\n")
    write(machine, "more.hal", "net answer probe.value\n")
    write(machine, "m.hal", f"loadusr -Wn probe {sys.executable} probe.py "
          "probe.conf\nsource more.hal\n")
    ini = write(machine, "m.ini", "[HAL]\nHALFILE = m.hal\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    proc = halsdk_run(elsewhere, str(ini), "--seconds", "0.3")
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    # the program found its relative configuration, ran in the machine's
    # folder, and was ended by the shutdown, not left behind
    assert (machine / "ended").read_text() == "SIGTERM"
    assert not (elsewhere / "ended").exists()


def test_wait_ends_when_a_signal_stops_it(tmp_path):
    """stop() is the SIGINT/SIGTERM handler, run on the waiting thread
    itself: wait() ends however the signal falls into it (a
    threading.Event there could deadlock its set() against the
    interrupted wait())."""
    ini = tmp_path / "m.ini"
    ini.write_text("[HAL]\nHALFILE = m.hal\n")
    machine = Launcher(str(ini))
    old = signal.signal(signal.SIGALRM, machine.stop)
    try:
        for delay in [0.001 * k for k in range(1, 40)]:
            machine._stopping = False
            signal.setitimer(signal.ITIMER_REAL, delay)
            start = time.monotonic()
            machine.wait(30)
            assert time.monotonic() - start < 20    # it did not hang
            assert machine._stopping
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    machine._stopping = False
    start = time.monotonic()
    machine.wait(0.2)                   # no signal: the time given
    assert time.monotonic() - start >= 0.2
