"""The cia402 CANopen driver against simulated CiA 402 drives on
python-can's virtual bus: in-process, through loadusr, and the example."""

from __future__ import annotations

import logging
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import can
import pytest
from helpers import repo_path
from helpers.fixtures import factory

from halsdk.driverkit import IOLoop
from halsdk.drivers.cia402 import statemachine as sm
from halsdk.drivers.cia402.__main__ import main
from halsdk.drivers.cia402.codes import emcy_text
from halsdk.drivers.cia402.config import ConfigError, load
from halsdk.drivers.cia402.driver import Cia402Driver
from halsdk.testing import private_instance_name

EXAMPLE = repo_path("examples", "cia402")
_channels = iter(range(10**6))


def wait_for(cond, timeout: float = 5.0, what: str = "condition") -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.01)


def write_ini(tmp_path: Path, drives: str, bus: str = "") -> Path:
    path = tmp_path / "drives.ini"
    channel = f"cia402-test-{os.getpid()}-{next(_channels)}"
    path.write_text(f"[BUS]\nCHANNEL = {channel}\nPERIOD = 0.01\n"
                    f"SIMULATE = 1\n{textwrap.dedent(bus)}\n"
                    + textwrap.dedent(drives))
    return path


CSP_DRIVE = """
    [DRIVE_0]
    NODE_ID = 1
    MODE = csp
    POSITION_SCALE = 1000
    HEARTBEAT_TIMEOUT = 0.3
    HEARTBEAT_PERIOD = 0.05
"""


class Rig:
    def __init__(self, hal, path: Path):
        self.hal = hal
        self.driver = Cia402Driver(load(str(path)))
        self.loop = IOLoop(self.driver, period=self.driver.config.period)
        self.loop.start_thread()
        wait_for(lambda: all(hal.getp(f"cia402.{d.cfg.num}.operational")
                             for d in self.driver.drives), what="operational")

    def pin(self, name: str):
        return self.hal.getp(f"cia402.{name}")

    def wait_pin(self, name: str, cond, timeout: float = 5.0) -> None:
        wait_for(lambda: cond(self.pin(name)), timeout, name)

    def stop(self) -> None:
        self.loop.stop()


@pytest.fixture
def rig_for(hal, tmp_path):
    def make(drives: str = CSP_DRIVE, bus: str = "") -> Rig:
        return Rig(hal, write_ini(tmp_path, drives, bus))
    with factory(make, Rig.stop) as made:
        yield made


def enable(rig: Rig, num: int = 0) -> None:
    rig.hal.setp(f"cia402.{num}.enable", True)
    rig.wait_pin(f"{num}.state", lambda s: s == sm.OPERATION_ENABLED)
    assert rig.pin(f"{num}.enabled")


def test_statusword_decoding_and_commands():
    assert sm.decode(0x0250) == sm.SWITCH_ON_DISABLED
    assert sm.decode(0x0231) == sm.READY_TO_SWITCH_ON
    assert sm.decode(0x0233) == sm.SWITCHED_ON
    assert sm.decode(0x1637) == sm.OPERATION_ENABLED
    assert sm.decode(0x0217) == sm.QUICK_STOP_ACTIVE
    assert sm.decode(0x021F) == sm.FAULT_REACTION_ACTIVE
    assert sm.decode(0x0218) == sm.FAULT
    assert sm.decode(0x0000) == sm.NOT_READY
    assert sm.command(sm.SWITCH_ON_DISABLED, True, False) == 0x06
    assert sm.command(sm.READY_TO_SWITCH_ON, True, False) == 0x07
    assert sm.command(sm.SWITCHED_ON, True, False) == 0x0F
    assert sm.command(sm.OPERATION_ENABLED, False, False) == 0x06
    assert sm.command(sm.OPERATION_ENABLED, True, True) == 0x02
    assert emcy_text(0x2310) == "continuous over-current"
    assert emcy_text(0x2399) == "current, device output side"
    assert emcy_text(0x5123) == "device hardware"


def test_enable_and_csp_follows(rig_for):
    rig = rig_for()
    hal = rig.hal
    rig.wait_pin("0.state", lambda s: s == sm.READY_TO_SWITCH_ON)  # off
    assert not rig.pin("0.enabled") and not rig.pin("0.fault")
    enable(rig)
    assert rig.pin("0.controlword") == sm.CW_ENABLE_OPERATION
    hal.setp("cia402.0.position-cmd", 2.5)
    rig.wait_pin("0.position-fb", lambda p: abs(p - 2.5) < 1e-9)
    assert rig.pin("0.target-reached")
    assert rig.driver.sim[1].position == pytest.approx(2500)
    hal.setp("cia402.0.enable", False)
    rig.wait_pin("0.state", lambda s: s == sm.READY_TO_SWITCH_ON)
    hal.setp("cia402.0.position-cmd", 5.0)      # disabled: no motion
    time.sleep(0.1)
    assert rig.pin("0.position-fb") == pytest.approx(2.5)
    assert hal.getp("cia402.connected") and not hal.getp("cia402.fault")
    assert hal.getp("cia402.period") > 0


def test_exit_switches_the_power_stage_off_before_nmt_stop(rig_for):
    rig = rig_for()
    enable(rig)
    sim = rig.driver.sim[1]
    assert sim.state == sm.OPERATION_ENABLED
    rig.stop()                      # the driver closes the bus
    # "shutdown" arrived before NMT stop: ready to switch on, not the
    # switch on disabled that a bare NMT stop leaves behind
    assert sim.get(0x6040) == sm.CW_SHUTDOWN
    assert sim.state == sm.READY_TO_SWITCH_ON
    assert sim.nmt_state != 5


def test_csv_velocity(rig_for):
    rig = rig_for(CSP_DRIVE.replace("csp", "csv"))
    enable(rig)
    rig.hal.setp("cia402.0.velocity-cmd", -4.0)
    rig.wait_pin("0.velocity-fb", lambda v: v == pytest.approx(-4.0))
    first = rig.pin("0.position-fb")
    time.sleep(0.2)
    assert rig.pin("0.position-fb") < first - 0.4     # integrates
    assert rig.driver.sim[1].get(0x6060) == sm.MODE_CSV
    rig.hal.setp("cia402.0.quick-stop", True)
    rig.wait_pin("0.state", lambda s: s == sm.QUICK_STOP_ACTIVE)
    rig.wait_pin("0.velocity-fb", lambda v: v == 0.0)   # braked
    assert rig.pin("0.controlword") == sm.CW_QUICK_STOP
    rig.hal.setp("cia402.0.quick-stop", False)
    rig.wait_pin("0.state", lambda s: s == sm.OPERATION_ENABLED)


def test_pp_move_reaches_target(rig_for):
    rig = rig_for(CSP_DRIVE.replace("csp", "pp") + """
    PROFILE_VELOCITY = 20
    PROFILE_ACCELERATION = 200
    """)
    sim = rig.driver.sim[1]
    assert sim.get(0x6081) == 20000 and sim.get(0x6083) == 200000
    enable(rig)
    assert rig.pin("0.target-reached")
    rig.hal.setp("cia402.0.position-cmd", 3.0)
    rig.wait_pin("0.target-reached", lambda t: not t)
    top = 0.0
    deadline = time.monotonic() + 5
    while not rig.pin("0.target-reached") and time.monotonic() < deadline:
        top = max(top, abs(rig.pin("0.velocity-fb")))
        time.sleep(0.005)
    assert rig.pin("0.position-fb") == pytest.approx(3.0)
    assert 5.0 < top <= 20.0 + 1e-6                  # profile velocity
    assert not rig.pin("0.controlword") & sm.CW_NEW_SETPOINT   # handshake
    rig.hal.setp("cia402.0.position-cmd", 1.0)       # a second set-point
    rig.wait_pin("0.position-fb", lambda p: p == pytest.approx(1.0))
    rig.wait_pin("0.target-reached", bool)


def test_injected_fault_logged_and_reset(rig_for, caplog):
    rig = rig_for()
    enable(rig)
    with caplog.at_level(logging.INFO, "halsdk.drivers.cia402"):
        rig.driver.sim[1].inject_fault(0x2310)
        rig.wait_pin("0.fault", bool)
        rig.wait_pin("0.state", lambda s: s == sm.FAULT)
        time.sleep(0.1)
    assert rig.pin("0.fault-code") == 0x2310
    assert rig.pin("0.error-register") == 0x03
    assert not rig.pin("0.enabled")
    text = "cia402.0 (node 1): EMCY 0x2310 continuous over-current, " \
           "error register 0x03"
    errors = [r.getMessage() for r in caplog.records
              if r.levelno >= logging.ERROR]
    assert errors == [text]                            # once
    assert "over-current" in rig.driver.drives[0].fault_text
    rig.hal.setp("cia402.0.fault-reset", True)        # rising edge
    rig.wait_pin("0.state", lambda s: s == sm.OPERATION_ENABLED)
    assert not rig.pin("0.fault") and rig.pin("0.fault-code") == 0
    assert rig.driver.drives[0].fault_text == ""


def test_following_error_injected_over_sdo(rig_for, caplog):
    rig = rig_for(CSP_DRIVE + "SDO = 0x6065:00 500\n")
    sim = rig.driver.sim[1]
    assert sim.get(0x6065) == 500
    enable(rig)
    with caplog.at_level(logging.ERROR, "halsdk.drivers.cia402"):
        rig.hal.setp("cia402.0.position-cmd", 50.0)   # far beyond 0.5 mm
        rig.wait_pin("0.fault-code", lambda c: c == 0x8611)
    assert "EMCY 0x8611 following error" in caplog.text
    # the manufacturer object 0x2000 injects a fault by SDO as well
    rig.hal.setp("cia402.0.position-cmd", rig.pin("0.position-fb"))
    rig.hal.setp("cia402.0.fault-reset", True)
    rig.wait_pin("0.state", lambda s: s == sm.OPERATION_ENABLED)
    rig.hal.setp("cia402.0.fault-reset", False)
    rig.driver.drives[0].sdo.download(0x2000, 0, b"\x10\x32")
    rig.wait_pin("0.fault-code", lambda c: c == 0x3210)


def test_heartbeat_lost_then_recovery(rig_for, caplog):
    rig = rig_for()
    enable(rig)
    sim = rig.driver.sim[1]
    with caplog.at_level(logging.INFO, "halsdk.drivers.cia402"):
        sim.stop_heartbeat()
        rig.wait_pin("0.heartbeat-lost", bool)
        assert rig.pin("0.fault") and rig.pin("0.fault-code") == 0x8130
        assert not rig.pin("0.operational") and not rig.pin("0.enabled")
        assert rig.pin("0.state") == sm.NO_DATA
        sim.resume_heartbeat()
        rig.wait_pin("0.operational", bool)
        rig.wait_pin("0.state", lambda s: s == sm.OPERATION_ENABLED)
    assert not rig.pin("0.fault") and not rig.pin("0.heartbeat-lost")
    assert "heartbeat lost (none for 0.3 s)" in caplog.text
    # a node that falls silent and restarts is configured again
    sim.go_offline()
    rig.wait_pin("0.heartbeat-lost", bool)
    sim.go_online()
    rig.wait_pin("0.state", lambda s: s == sm.OPERATION_ENABLED)
    assert sim.nmt_state == 5


def test_sdo_abort_in_config_names_the_object(hal, tmp_path, caplog):
    path = write_ini(tmp_path, CSP_DRIVE + "SDO = 0x2100:03 5 u8\n")
    driver = Cia402Driver(load(str(path)))
    loop = IOLoop(driver, period=0.01)
    with caplog.at_level(logging.ERROR, "halsdk.drivers.cia402"):
        loop.start_thread()
        try:
            wait_for(lambda: hal.getp("cia402.0.fault"), what="fault")
            time.sleep(0.6)                          # retried, logged once
            assert hal.getp("cia402.0.fault-code") == 0x6320
            assert hal.getp("cia402.0.abort-code") == 0x06020000
            assert not hal.getp("cia402.0.operational")
        finally:
            loop.stop()
    msg = (f"cia402.0 (node 1): SDO abort writing 0x2100:03 (SDO line "
           f"{path}:13): 0x06020000 object does not exist in the object "
           "dictionary")
    assert caplog.messages == [msg]


@pytest.mark.parametrize("drives, line, text", [
    ("[DRIVE_0]\nNODE_ID = 200\n", 7, "NODE_ID must be 1 to 127"),
    ("[DRIVE_0]\nNODE_ID = 1\nMODE = torque\n", 8, "MODE must be one of"),
    ("[DRIVE_0]\nNODE_ID = 1\nSPEED = 3\n", 8, "unknown key SPEED"),
    ("[DRIVE_0]\nNODE_ID = 1\nSDO = 0x2100:00 5\n", 8,
     "object 0x2100:00 is not in the EDS"),
    ("[DRIVE_0]\nNODE_ID = 1\nSDO = 0x6060 300\n", 8, "does not fit"),
    ("[DRIVE_0]\nNODE_ID = 1\nRPDO1 = 0x6040 0x6064\n", 8,
     "the driver cannot fill 0x6064"),
    ("[DRIVE_0]\nNODE_ID = 1\nTPDO1 = 0x6064\n", 8, "must map 0x6041"),
    ("[DRIVE_0]\nNODE_ID = 1\nEDS = nosuch.eds\n", 8, "cannot read EDS"),
    ("[DRIVE_0]\nNODE_ID = 1\n[DRIVE_1]\nNODE_ID = 1\n", 9,
     "node 1 is also DRIVE_0"),
    ("[DRIVE_0]\nNODE_ID = 1\nPOSITION_SCALE = x\n", 8, "not a number"),
])
def test_bad_config_names_file_and_line(tmp_path, drives, line, text):
    path = write_ini(tmp_path, drives)
    with pytest.raises(ConfigError) as info:
        load(str(path))
    assert str(info.value).startswith(f"{path}:{line}: ")
    assert text in str(info.value)


DRIVE = "[DRIVE_0]\nNODE_ID = 1\n"


@pytest.mark.parametrize("text, line, message", [
    ("[BUS]\nPERIOD = 1e300\n" + DRIVE, 2, "PERIOD must be at most 1,"),
    ("[BUS]\nPERIOD = nan\n" + DRIVE, 2, "'nan' is not a finite number"),
    ("[BUS]\nPERIOD = inf\n" + DRIVE, 2, "'inf' is not a finite number"),
    ("[BUS]\nSDO_TIMEOUT = 1e300\n" + DRIVE, 2,
     "SDO_TIMEOUT must be at most 60,"),
    ("[BUS]\nBITRATE = 1.5\n" + DRIVE, 2, "BITRATE must be a whole"),
    ("[BUS]\nBITRATE = 1e300\n" + DRIVE, 2, "BITRATE must be at most"),
    ("[BUS]\nINTERFACE = nosuch\n" + DRIVE, 2, "unknown INTERFACE"),
    ("[BUS]\n[DRIVE_0]\nNODE_ID = nan\n", 3, "not a finite number"),
    ("[BUS]\n" + DRIVE + "HEARTBEAT_TIMEOUT = inf\n", 4,
     "not a finite number"),
    ("[BUS]\n" + DRIVE + "HEARTBEAT_PERIOD = 1e300\n", 4,
     "HEARTBEAT_PERIOD must be at most 60,"),
    ("[BUS]\n" + DRIVE + "POSITION_SCALE = -inf\n", 4,
     "not a finite number"),
    ("[BUS]\n" + DRIVE + "MODE = pp\nPROFILE_VELOCITY = 1e300\n", 5,
     "PROFILE_VELOCITY times POSITION_SCALE must be at most"),
    # repeated sections merge and the first key wins in a plain INI
    # reader: both would hide a mistake, so both are errors
    ("[BUS]\n" + DRIVE + "[DRIVE_0]\nMODE = csv\n", 4,
     "[DRIVE_0] is given again (first at line 2)"),
    ("[BUS]\nPERIOD = 0.01\n" + DRIVE + "[BUS]\nPERIOD = 0.02\n", 5,
     "[BUS] is given again (first at line 1)"),
    ("[BUS]\n" + DRIVE + "NODE_ID = 2\n", 4,
     "[DRIVE_0]NODE_ID is given again (first at line 3)"),
    ("PERIOD = 0.01\n[BUS]\n" + DRIVE, 1, "PERIOD is outside a section"),
])
def test_bad_numbers_and_repeats_name_file_and_line(tmp_path, text, line,
                                                    message):
    path = tmp_path / "drives.ini"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load(str(path))
    assert str(info.value).startswith(f"{path}:{line}: ")
    assert message in str(info.value)


def test_sdo_lines_may_repeat(tmp_path):
    path = write_ini(tmp_path, CSP_DRIVE + "SDO = 0x6065:00 500\n"
                     "SDO = 0x6065:00 700\n")
    writes = load(str(path)).drives[0].sdo_writes
    assert [(w.index, w.value) for w in writes] == [(0x6065, 500),
                                                    (0x6065, 700)]


@pytest.mark.parametrize("argv, message", [
    (["--bogus"], "unrecognized arguments: --bogus"),
    (["--bogus", "drives.ini"], "unrecognized arguments: --bogus"),
    ([], "missing the drive configuration file"),
    (["-n"], "argument -n/--name: expected one argument"),
    (["-n", "", "drives.ini"], "-n/--name must not be empty"),
])
def test_usage_errors_exit_1_with_one_line(capsys, argv, message):
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"cia402: {message}")
    assert err.count("\n") == 1


def test_open_error_names_the_channel_and_is_logged_once(hal, tmp_path):
    """No INFO flood while the bus cannot be opened; one line in the
    format of the other programs, naming the interface and channel."""
    ini = tmp_path / "drives.ini"
    ini.write_text("[BUS]\nINTERFACE = socketcan\nCHANNEL = cia402-none\n"
                   "PERIOD = 0.01\n" + DRIVE)
    err_path = tmp_path / "stderr.txt"
    with open(err_path, "w") as err:
        proc = subprocess.Popen(
            [sys.executable, "-m", "halsdk.drivers.cia402", str(ini)],
            cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=err)
    try:
        wait_for(lambda: "open failed" in err_path.read_text(), 20,
                 "the open error")
        time.sleep(0.8)          # several reconnect attempts
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    lines = err_path.read_text().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("cia402: open failed: socketcan channel "
                               "cia402-none: ")


def test_bad_config_exits_1_with_message(tmp_path):
    path = write_ini(tmp_path, "[DRIVE_0]\nNODE_ID = 1\nMODE = torque\n")
    proc = subprocess.run(
        [sys.executable, "-m", "halsdk.drivers.cia402", str(path)],
        cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1
    assert proc.stderr.startswith(f"cia402: {path}:8: MODE must be")
    assert "Traceback" not in proc.stderr


def test_unknown_node_and_malformed_frames_ignored(rig_for, caplog):
    rig = rig_for()
    enable(rig)
    junk = can.Bus(interface="virtual", channel=rig.driver.config.channel)
    try:
        with caplog.at_level(logging.WARNING, "halsdk.drivers.cia402"):
            for _ in range(3):
                junk.send(can.Message(arbitration_id=0x185, data=b"\1\2",
                                      is_extended_id=False))   # node 5
                junk.send(can.Message(arbitration_id=0x701, data=b"\5\5\5",
                                      is_extended_id=False))   # heartbeat
                junk.send(can.Message(arbitration_id=0x181, data=b"\1",
                                      is_extended_id=False))   # TPDO1
                junk.send(can.Message(arbitration_id=0x81, data=b"\1\2",
                                      is_extended_id=False))   # EMCY
                junk.send(can.Message(arbitration_id=0x1234567,
                                      data=b"", is_extended_id=True))
            rig.wait_pin("malformed-frames", lambda n: n >= 9)
            rig.wait_pin("unknown-frames", lambda n: n >= 6)
            time.sleep(0.1)
    finally:
        junk.shutdown()
    assert rig.pin("malformed-frames") == 9
    assert rig.pin("unknown-frames") == 6
    warnings = [r.getMessage() for r in caplog.records]
    assert len(warnings) == 5 and all("ignoring" in w for w in warnings)
    assert rig.pin("0.state") == sm.OPERATION_ENABLED
    assert not rig.pin("0.fault") and not rig.hal.getp("cia402.fault")


def _halrun(tmp_path: Path, hal_text: str, stdin: str
            ) -> subprocess.CompletedProcess:
    (tmp_path / "run.hal").write_text(hal_text)
    env = dict(os.environ, HALSDK_INSTANCE=private_instance_name())
    proc = subprocess.Popen(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-I", "-f",
         "run.hal"], cwd=tmp_path, env=env, stdin=subprocess.PIPE,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out, err = proc.communicate(stdin, timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


def test_loadusr_with_name_and_unloadusr(tmp_path, python_tools_first):
    write_ini(tmp_path, CSP_DRIVE)
    proc = _halrun(
        tmp_path, "loadusr -Wn axes cia402 -n axes --simulate drives.ini\n"
        "setp axes.0.enable 1\nsetp axes.0.position-cmd 1.5\n",
        "loadusr -w sleep 1\ngetp axes.0.state\ngetp axes.0.position-fb\n"
        "unloadusr axes\nloadusr -w sleep 0.5\nlist comp\n")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = proc.stdout.split("\n")
    assert lines[:2] == ["4", "1.5"]
    assert "axes" not in lines[2]
    assert "Traceback" not in proc.stderr


def test_example_two_drives_follow(tmp_path, python_tools_first):
    for name in ("cia402.hal", "drives.ini"):
        shutil.copy(EXAMPLE / name, tmp_path / name)
    probe = ("getp cia402.0.state\ngetp cia402.1.state\n"
             "getp cia402.0.fault\ngetp cia402.1.fault\n"
             "getp ramp-x.out\ngetp cia402.0.position-fb\n"
             "getp ramp-y.out\ngetp cia402.1.position-fb\n")
    proc = _halrun(tmp_path, (tmp_path / "cia402.hal").read_text(),
                   "loadusr -w sleep 1.5\n" + probe
                   + "loadusr -w sleep 0.5\n" + probe)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    values = proc.stdout.split()
    assert len(values) == 16, proc.stdout
    first, second = values[:8], values[8:]
    for sample in (first, second):
        assert sample[:4] == ["4", "4", "FALSE", "FALSE"]
        x_cmd, x_fb, y_cmd, y_fb = map(float, sample[4:])
        # the feedback lags the command by a few 10 ms cycles at most
        assert abs(x_fb - x_cmd) < 2.0 and abs(y_fb - y_cmd) < 2.0
    assert float(first[5]) != float(second[5])       # X moves
    assert float(first[7]) != float(second[7])       # Y moves
    assert max(abs(float(v)) for v in first[4:] + second[4:]) > 1.0
