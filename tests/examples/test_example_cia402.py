"""examples/cia402 machine: an XY table whose joints are two simulated CiA
402 drives (the cia402 driver, a userspace process) run by the motion
controller and the machine layer from machine.ini, in real time: turned
on, homed (absolute encoders), a square program run, the drives followed
it in operation enabled without a fault, and the machine shuts down
cleanly (drives disabled, driver ended)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import repo_path
from helpers.processes import ended_at_exit, sigterm

from halsdk.core import _core
from halsdk.ini import IniFile
from halsdk.machine import InterpState, Machine, TaskMode, TaskState
from halsdk.machine.launcher import Launcher
from halsdk.testing import private_instance_name

EXAMPLE = repo_path("examples", "cia402")
FILES = ("machine.ini", "machine.hal", "drives.ini", "square.ngc")
DRIVES = (0, 1)
OPERATION_ENABLED = 4
READY_TO_SWITCH_ON = 2
#: square.ngc ends here (machine coordinates: no work offset)
END = (35.0, 25.0)
#: one count is 0.001 mm (POSITION_SCALE 1000)
TOLERANCE = 0.002

pytestmark = pytest.mark.slow


def copy_example(folder: Path) -> Path:
    """The machine's files in ``folder``/machine; the tests start it from
    ``folder``: the HAL files run in the INI file's folder all the same."""
    (folder / "machine").mkdir()
    for name in FILES:
        shutil.copy(EXAMPLE / name, folder / "machine" / name)
    return folder / "machine" / "machine.ini"


def wait_for(check, what: str, timeout: float = 5.0) -> None:
    deadline = time.monotonic() + timeout
    while not check():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.01)


def alive(pid: int) -> bool:
    """The process runs (exists and is not a zombie)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def process_ended(pid: int) -> bool:
    """True when ``pid`` is gone (reaped here if it is our child)."""
    try:
        done, status = os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:       # not our child, or reaped already
        return not alive(pid)
    if done:
        assert os.waitstatus_to_exitcode(status) == 0
        return True
    return False


@pytest.fixture
def machine(tmp_path, monkeypatch, python_tools_first):
    monkeypatch.setenv("HALSDK_INSTANCE", private_instance_name())
    monkeypatch.chdir(tmp_path)
    launcher = Launcher(str(copy_example(tmp_path)))
    launcher.start(realtime=True)
    try:
        yield launcher
    finally:
        launcher.shutdown()


def test_square_on_two_cia402_drives_then_a_clean_shutdown(machine):
    hal = machine.hal
    ini = IniFile(machine.ini.path)
    # the wiring of machine.hal
    for n in DRIVES:
        assert hal.getp(f"cia402.{n}.enable") is False
    # the driver is ready once its pins exist; it configures the drives
    # over SDO in its first cycles, then they wait, switched off
    wait_for(lambda: all(hal.getp(f"cia402.{n}.state") == READY_TO_SWITCH_ON
                         for n in DRIVES), "the drives to be configured")

    m = Machine.from_launcher(machine)
    m.state(TaskState.ESTOP_RESET)
    m.state(TaskState.ON)
    # motion enables the amplifiers: the driver brings the drives up
    wait_for(lambda: all(hal.getp(f"cia402.{n}.enabled") for n in DRIVES),
             "the drives to be enabled")
    m.mode(TaskMode.MANUAL)
    m.home(timeout=5)               # absolute encoders: homed in place
    assert m.status().homed[:2] == (True, True)

    m.mode(TaskMode.AUTO)
    m.program_open(str(Path(machine.ini.path).parent / "square.ngc"))
    m.program_run()
    states: set[int] = set()
    faults = 0
    moved = [0.0, 0.0]
    deadline = time.monotonic() + 15
    while m.status().interp_state is not InterpState.IDLE:
        assert time.monotonic() < deadline, "the program did not end"
        m.update()
        for n in DRIVES:
            states.add(hal.getp(f"cia402.{n}.state"))
            faults += hal.getp(f"cia402.{n}.fault")
            moved[n] = max(moved[n], hal.getp(f"cia402.{n}.position-fb"))
    assert m.errors() == []
    # the drives were in operation enabled all the time and followed
    assert states == {OPERATION_ENABLED}
    assert faults == 0
    assert moved[0] >= 40 - TOLERANCE and moved[1] >= 30 - TOLERANCE

    # the feedback arrives one or two driver cycles after the command
    def at_end() -> bool:
        return all(abs(hal.getp(f"cia402.{n}.position-fb") - END[n])
                   <= TOLERANCE for n in DRIVES)
    wait_for(at_end, "the drives to reach the end of square.ngc", 2)
    st = m.status().motion
    for n in DRIVES:
        assert st.joints[n].pos_cmd == pytest.approx(END[n], abs=1e-9)
        assert hal.getp(f"cia402.{n}.fault-code") == 0
        # the delay of the feedback makes a following error, well within
        # the limits of machine.ini
        ferror = float(ini.get(f"JOINT_{n}", "FERROR"))
        assert 0 < st.joints[n].ferror_high_mark < ferror
        assert not st.joints[n].ferror_exceeded
    assert st.enabled

    # shutting down: motion disabled first, which switches the drives off
    driver_pid = _core.find("component", "cia402").pid
    machine.motion.disable()
    wait_for(lambda: all(hal.getp(f"cia402.{n}.state") == READY_TO_SWITCH_ON
                         for n in DRIVES), "the drives to be disabled")
    assert not any(hal.getp(f"cia402.{n}.enabled") for n in DRIVES)
    machine.shutdown()              # ends the driver (SIGTERM)
    wait_for(lambda: process_ended(driver_pid), "the driver to end")


def test_halsdk_run_and_sigterm_end_the_driver(tmp_path, python_tools_first):
    ini = copy_example(tmp_path)
    env = dict(os.environ, HALSDK_INSTANCE=private_instance_name())
    proc = subprocess.Popen([sys.executable, "-m", "halsdk.machine.cli", "run",
                             str(ini)], cwd=str(tmp_path), env=env,
                            text=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    with ended_at_exit(proc):
        line = proc.stdout.readline()       # once the machine runs
        assert "machine running" in line, proc.stderr.read()
        drivers = [int(pid) for pid in os.listdir("/proc")
                   if pid.isdigit()
                   and is_our_driver(pid, tmp_path / "machine")]
        assert len(drivers) == 1
        out, err = sigterm(proc, 20)
    assert proc.returncode == 0, err
    assert "stopped" in out
    wait_for(lambda: not alive(drivers[0]), "the driver to end")


def is_our_driver(pid: str, folder: Path) -> bool:
    """``pid`` is a cia402 program running in ``folder``."""
    try:
        with open(f"/proc/{pid}/cmdline") as f:
            words = f.read().split("\0")
        cwd = os.readlink(f"/proc/{pid}/cwd")
    except OSError:
        return False
    return cwd == str(folder) and "--simulate" in words and \
        any(os.path.basename(w) == "cia402" for w in words)
