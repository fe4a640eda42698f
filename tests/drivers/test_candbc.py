"""The can-dbc driver (halsdk.drivers.candbc) on python-can's virtual bus."""

from __future__ import annotations

import itertools
import logging
import math
import os
import shutil
import subprocess
import sys

import can
import cantools
import pytest
from helpers import repo_path
from helpers.fixtures import factory
from helpers.polling import wait_for
from helpers.processes import ended_at_exit, sigterm

from halsdk.driverkit import FAULT_OPEN, FAULT_READ, IOLoop
from halsdk.drivers.candbc import (
    CanDbcDriver,
    ConfigError,
    hal_name,
    parse_args,
)
from halsdk.drivers.candbc.dbc import find_package_dbc
from halsdk.types import Direction, HalType

EXAMPLE = str(repo_path("examples", "candbc"))
DEMO = find_package_dbc("demo.dbc")
DB = cantools.database.load_file(DEMO)
P = "candbc.0."
_channels = itertools.count()


class FakeClock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def new_channel() -> str:
    return f"candbc-test-{os.getpid()}-{next(_channels)}"


class Rig:
    """Driver + loop on a fake clock, and a test-side bus on the channel."""

    def __init__(self, *args: str) -> None:
        self.channel = new_channel()
        self.config = parse_args(["--dbc", DEMO, "--interface", "virtual",
                                  "--channel", self.channel, *args])
        self.clock = FakeClock()
        self.driver = CanDbcDriver(self.config, clock=self.clock)
        self.loop = IOLoop(self.driver, period=0.005, backoff=0.1,
                           backoff_max=0.4, clock=self.clock)
        self.bus = can.Bus(interface="virtual", channel=self.channel)
        self.loop.start()
        self.step()                    # connects, sends the first frames

    def step(self, dt: float = 0.005, n: int = 1) -> None:
        for _ in range(n):
            self.clock.now += dt
            self.loop.cycle()

    def send(self, name: str, values: dict, **kw) -> None:
        msg = DB.get_message_by_name(name)
        data = msg.encode(values, **kw)
        self.bus.send(can.Message(arbitration_id=msg.frame_id,
                                  is_extended_id=False, data=data))

    def received(self) -> list[can.Message]:
        frames = []
        while (frame := self.bus.recv(timeout=0)) is not None:
            frames.append(frame)
        return frames

    def close(self) -> None:
        self.driver.shutdown()
        self.bus.shutdown()


@pytest.fixture
def rig(hal):
    with factory(Rig, Rig.close) as make:
        yield make


STATUS = {"ActualSpeed": -1234.5, "Enabled": 1, "State": 2,
          "MotorTemp": 61, "ErrorCode": 40000, "TorqueRaw": -700}


# -- names and types -----------------------------------------------------------
@pytest.mark.parametrize("dbc, hal", [
    ("EngineSpeed", "engine-speed"), ("engine_speed", "engine-speed"),
    ("ABSStatus", "abs-status"), ("VCU_RPMLimit", "vcu-rpm-limit"),
    ("Temp2Sensor", "temp2-sensor"), ("__x__Y", "x-y"), ("A", "a")])
def test_hal_name(dbc, hal):
    assert hal_name(dbc) == hal


def test_pins_names_types_directions(hal, rig):
    rig("--node", "PLC")
    pins = {p.name: (p.type, p.direction) for p in hal.pins("candbc.0.*")}
    out, inp = Direction.OUT, Direction.IN
    expect = {
        "drive-status.actual-speed": (HalType.FLOAT, out),
        "drive-status.enabled": (HalType.BIT, out),
        "drive-status.state": (HalType.U32, out),        # choices: raw
        "drive-status.motor-temp": (HalType.FLOAT, out),  # offset -40
        "drive-status.error-code": (HalType.U32, out),
        "drive-status.torque-raw": (HalType.S32, out),
        "drive-status.timeout": (HalType.BIT, out),
        "drive-status.count": (HalType.U32, out),
        "drive-info.info-page": (HalType.U32, out),
        "drive-info.run-hours": (HalType.U32, out),
        "drive-command.target-speed": (HalType.FLOAT, inp),
        "drive-command.enable-cmd": (HalType.BIT, inp),
        "drive-command.mode": (HalType.U32, inp),
        "drive-command.count": (HalType.U32, out),
        "rx-unknown": (HalType.U32, out), "rx-errors": (HalType.U32, out),
        "tx-errors": (HalType.U32, out), "fault": (HalType.BIT, out),
        "connected": (HalType.BIT, out),
    }
    for name, kind in expect.items():
        assert pins.get(P + name) == kind, name
    assert P + "drive-command.timeout" not in pins
    assert [c.name for c in hal.components("can-dbc")] == ["can-dbc"]


def test_name_clash_is_an_error_naming_both(tmp_path, hal):
    dbc = tmp_path / "clash.dbc"
    dbc.write_text(open(DEMO).read().replace("SG_ TorqueRaw",
                                             "SG_ error_code"))
    config = parse_args(["--dbc", str(dbc), "--interface", "virtual"])
    with pytest.raises(ConfigError) as info:
        CanDbcDriver(config)
    assert str(info.value) == (
        f"{dbc}: message 'DriveStatus': signals 'ErrorCode' and "
        "'error_code' both give the HAL name 'error-code'")
    # two messages
    dbc.write_text(open(DEMO).read().replace("DriveInfo:", "drive_info:")
                   .replace("BO_ 512 DriveCommand", "BO_ 512 DRIVEInfo"))
    with pytest.raises(ConfigError, match="messages 'DRIVEInfo' and "
                       "'drive_info' both give the HAL name 'drive-info'"):
        CanDbcDriver(parse_args(["--dbc", str(dbc), "--interface",
                                 "virtual"]))
    # a signal that would take a per-message pin name
    dbc.write_text(open(DEMO).read().replace("SG_ ErrorCode", "SG_ Count"))
    with pytest.raises(ConfigError, match="signal 'Count' gives the HAL "
                       "name 'count', which the driver uses itself"):
        CanDbcDriver(parse_args(["--dbc", str(dbc), "--interface",
                                 "virtual"]))


# -- receive -------------------------------------------------------------------
def test_decode_to_pins(hal, rig):
    r = rig("--node", "PLC")
    r.step()
    r.send("DriveStatus", STATUS)
    r.step()
    assert hal.getp(P + "drive-status.actual-speed") == pytest.approx(-1234.5)
    assert hal.getp(P + "drive-status.enabled") is True
    assert hal.getp(P + "drive-status.state") == 2
    assert hal.getp(P + "drive-status.motor-temp") == pytest.approx(61)
    assert hal.getp(P + "drive-status.error-code") == 40000
    assert hal.getp(P + "drive-status.torque-raw") == -700
    assert hal.getp(P + "drive-status.count") == 1
    r.send("DriveStatus", dict(STATUS, Enabled=0, State=3))
    r.send("DriveStatus", dict(STATUS, ActualSpeed=10))
    r.step()
    assert hal.getp(P + "drive-status.count") == 3
    assert hal.getp(P + "drive-status.actual-speed") == pytest.approx(10)


def test_multiplexed_message_updates_only_its_page(hal, rig):
    r = rig()                                  # everything received
    r.send("DriveInfo", {"InfoPage": 0, "FirmwareVersion": 517})
    r.step()
    assert hal.getp(P + "drive-info.firmware-version") == 517
    r.send("DriveInfo", {"InfoPage": 1, "RunHours": 123456})
    r.step()
    assert hal.getp(P + "drive-info.info-page") == 1
    assert hal.getp(P + "drive-info.run-hours") == 123456
    assert hal.getp(P + "drive-info.firmware-version") == 517    # held
    assert hal.getp(P + "drive-info.count") == 2


def test_malformed_and_unknown_frames(hal, rig, caplog):
    r = rig("--node", "PLC")
    with caplog.at_level(logging.ERROR, "halsdk.driverkit"):
        for _ in range(3):
            r.bus.send(can.Message(arbitration_id=0x100, data=b"\x01\x02",
                                   is_extended_id=False))
        r.bus.send(can.Message(arbitration_id=0x7FF, data=b"",
                               is_extended_id=False))
        r.bus.send(can.Message(arbitration_id=0x100, data=bytes(8),
                               is_extended_id=True))      # other id space
        r.bus.send(can.Message(arbitration_id=0x300, is_extended_id=False,
                               data=b"\x09\x00\x00\x00"))  # no page 9
        r.step()
        r.send("DriveStatus", STATUS)
        r.step(n=3)
    assert hal.getp(P + "rx-errors") == 4
    assert hal.getp(P + "rx-unknown") == 2
    assert hal.getp(P + "drive-status.count") == 1      # still decoding
    assert hal.getp(P + "drive-status.state") == 2
    assert not hal.getp(P + "fault")
    bad = [m for m in caplog.messages if "DriveStatus" in m]
    assert len(bad) == 1 and "2 data bytes, expected 8" in bad[0]
    assert len([m for m in caplog.messages if "DriveInfo" in m]) == 1


def test_timeout_sets_pin_holds_values_and_clears(hal, rig):
    r = rig("--node", "PLC")      # DriveStatus: 20 ms cycle x 3 = 60 ms
    assert r.config.timeouts["DriveStatus"] == pytest.approx(0.06)
    assert r.config.timeouts["DriveInfo"] == 0         # no cycle time
    r.step()
    r.send("DriveStatus", STATUS)
    r.step()
    r.step(0.01, 5)                                    # 50 ms of silence
    assert not hal.getp(P + "drive-status.timeout")
    r.step(0.01, 2)                                    # 70 ms
    assert hal.getp(P + "drive-status.timeout")
    assert hal.getp(P + "drive-status.error-code") == 40000   # held
    assert not hal.getp(P + "drive-info.timeout")
    r.send("DriveStatus", dict(STATUS, ErrorCode=7))
    r.step()
    assert not hal.getp(P + "drive-status.timeout")
    assert hal.getp(P + "drive-status.error-code") == 7


def test_timeout_options(hal, rig):
    r = rig("--timeout", "0.5", "--timeout", "drive-status=0.2")
    assert r.config.timeouts == pytest.approx(
        {"DriveStatus": 0.2, "DriveInfo": 0.5, "DriveCommand": 0.15})
    r.step(0.15)
    assert not hal.getp(P + "drive-status.timeout")
    r.step(0.1)
    assert hal.getp(P + "drive-status.timeout")
    assert hal.getp(P + "drive-command.timeout")
    assert not hal.getp(P + "drive-info.timeout")


# -- transmit ------------------------------------------------------------------
def decode(frame: can.Message) -> dict:
    return DB.decode_message(frame.arbitration_id, frame.data,
                             decode_choices=False)


def test_encode_from_pins_with_limits(hal, rig):
    r = rig("--node", "PLC")
    (first,) = r.received()                  # sent at connect
    assert decode(first) == {"TargetSpeed": 0, "EnableCmd": 0, "Mode": 0}
    hal.setp(P + "drive-command.target-speed", 1500.26)
    hal.setp(P + "drive-command.enable-cmd", True)
    hal.setp(P + "drive-command.mode", 2)
    r.step(0.05)
    (frame,) = r.received()
    assert frame.arbitration_id == 0x200 and len(frame.data) == 4
    values = decode(frame)
    assert values["TargetSpeed"] == pytest.approx(1500.3)
    assert values["EnableCmd"] == 1 and values["Mode"] == 2
    assert hal.getp(P + "drive-command.count") == 2
    # out of range: clamped to the DBC range, choices to their bits
    hal.setp(P + "drive-command.target-speed", 1e9)
    hal.setp(P + "drive-command.mode", 77)
    r.step(0.05)
    values = decode(r.received()[-1])
    assert values["TargetSpeed"] == pytest.approx(3000)
    assert values["Mode"] == 3
    for bad, expect in ((-math.inf, -3000), (math.nan, 0)):
        hal.setp(P + "drive-command.target-speed", bad)
        r.step(0.05)
        assert decode(r.received()[-1])["TargetSpeed"] == pytest.approx(
            expect)
    assert hal.getp(P + "tx-errors") == 0 and not hal.getp(P + "fault")


def test_cyclic_transmit_counted_on_fake_clock(hal, rig):
    r = rig("--node", "PLC")
    assert r.config.periods == {"DriveCommand": 0.05}   # GenMsgCycleTime
    r.step(0.005, 195)                                  # 975 ms
    frames = r.received()
    assert len(frames) == 20                            # at 0, 50 ... 950
    assert hal.getp(P + "drive-command.count") == 20
    assert not [f for f in frames if f.arbitration_id != 0x200]


def test_period_option_and_on_change(hal, rig):
    r = rig("--tx", "DriveCommand", "--rx", "DriveStatus",
            "--period", "DriveCommand=0.2", "--on-change")
    r.step(0.01, 90)
    assert len(r.received()) == 5                       # 0, 0.2 ... 0.8
    hal.setp(P + "drive-command.mode", 1)
    r.step(0.01)
    (frame,) = r.received()
    assert decode(frame)["Mode"] == 1
    r.step(0.01, 15)                                    # rhythm restarted
    assert r.received() == []
    r.step(0.01, 10)
    assert len(r.received()) == 1
    assert not hal.pins(P + "drive-info.*")             # not selected


def test_event_only_message(hal, rig):
    r = rig("--tx", "DriveCommand", "--period", "DriveCommand=0")
    r.step(0.01, 50)
    assert len(r.received()) == 1                       # once at connect
    hal.setp(P + "drive-command.enable-cmd", True)
    r.step(0.01, 50)
    assert r.received() == []                           # no --on-change


def test_transmitted_multiplexed_message(hal, rig):
    r = rig("--tx", "DriveInfo", "--period", "0.1")
    hal.setp(P + "drive-info.info-page", 1)
    hal.setp(P + "drive-info.run-hours", 99)
    r.step(0.1)
    values = decode(r.received()[-1])
    assert values == {"InfoPage": 1, "RunHours": 99}


# -- faults --------------------------------------------------------------------
def test_bus_failure_faults_and_reconnects(hal, rig, caplog, monkeypatch):
    r = rig("--node", "PLC")
    r.step()
    assert hal.getp(P + "connected")

    def broken(timeout=None):
        raise can.CanOperationError("network is down")
    r.driver.bus.recv = broken
    caplog.set_level(logging.ERROR, "halsdk.driverkit")
    r.step()
    assert hal.getp(P + "fault") and not hal.getp(P + "connected")
    assert hal.getp(P + "fault-code") == FAULT_READ
    assert hal.getp(P + "drive-status.timeout")         # no bus, no data
    assert "candbc.0: read failed: bus receive: network is down" in \
        caplog.messages
    r.step(0.05)
    assert not hal.getp(P + "connected")                # backing off
    real_bus = can.Bus

    def unplugged(**kwargs):
        raise OSError(19, "No such device")
    monkeypatch.setattr(can, "Bus", unplugged)
    r.step(0.06)                                        # reopen fails
    assert hal.getp(P + "fault-code") == FAULT_OPEN
    assert "candbc.0: open failed: cannot open virtual channel " \
        f"{r.channel}: [Errno 19] No such device" in caplog.messages
    monkeypatch.setattr(can, "Bus", real_bus)
    r.step(0.15)
    assert not hal.getp(P + "connected")                # delay doubled
    r.step(0.06)
    assert hal.getp(P + "connected") and not hal.getp(P + "fault")
    r.send("DriveStatus", STATUS)
    r.step()
    assert not hal.getp(P + "drive-status.timeout")
    assert hal.getp(P + "fault-count") == 2             # read, then open


# -- command line --------------------------------------------------------------
def run_program(args: list[str], cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "halsdk.drivers.candbc",
                           *args], cwd=str(cwd), capture_output=True,
                          text=True, timeout=30)


def test_bad_dbc_exits_with_file_and_line(tmp_path, hal):
    bad = tmp_path / "bad.dbc"
    bad.write_text(open(DEMO).read().replace("BO_ 512 DriveCommand:",
                                             "BO_ 512 DriveCommand"))
    proc = run_program(["--dbc", "bad.dbc", "--interface", "virtual"],
                       tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.startswith("can-dbc: bad.dbc:17:22: invalid syntax")
    assert "Traceback" not in proc.stderr
    overlap = tmp_path / "overlap.dbc"
    overlap.write_text(open(DEMO).read().replace("SG_ Mode : 17|2",
                                                 "SG_ Mode : 15|2"))
    proc = run_program(["--dbc", "overlap.dbc"], tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.startswith("can-dbc: overlap.dbc:17: ")
    assert "DriveCommand" in proc.stderr and "Traceback" not in proc.stderr
    for args, text in (
            (["--dbc", "nosuch.dbc"], "nosuch.dbc: cannot read"),
            (["--dbc", DEMO, "--tx", "Nope"], "no message named 'Nope'"),
            (["--dbc", DEMO, "--rx", "DriveInfo", "--tx", "drive-info"],
             "'DriveInfo' is both received and transmitted"),
            (["--dbc", DEMO, "--period", "x"], "--period 'x'"),
            (["--dbc", DEMO, "--interface", "nosuch"], "unknown interface")):
        proc = run_program(args, tmp_path)
        assert proc.returncode == 1 and text in proc.stderr, proc.stderr
        assert len(proc.stderr.splitlines()) == 1


def test_process_sends_and_stops_on_sigterm(tmp_path, hal):
    proc = subprocess.Popen(
        [sys.executable, "-m", "halsdk.drivers.candbc", "-n", "mycan",
         "--num", "3", "--interface", "virtual", "--channel", "own",
         "--dbc", "demo.dbc", "--node", "PLC"], cwd=str(tmp_path),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    with ended_at_exit(proc):
        assert wait_for(lambda: hal.pins("candbc.3.drive-command.count")
                        and hal.getp("candbc.3.drive-command.count") >= 3)
        assert hal.getp("candbc.3.connected")
        assert hal.getp("candbc.3.drive-status.timeout")   # nobody sends
        assert [c.name for c in hal.components("mycan")] == ["mycan"]
        out, err = sigterm(proc, 10)
    assert proc.returncode == 0, err
    assert "Traceback" not in err
    assert not hal.pins("candbc.3.*")


def test_example_hal_file_with_loadusr_w(tmp_path, python_tools_first):
    for name in ("machine.dbc", "candbc.hal"):
        shutil.copy(os.path.join(EXAMPLE, name), tmp_path / name)
    (tmp_path / "run.hal").write_text(
        "source candbc.hal\n"
        "loadusr -w sleep 0.3\n"
        "getp candbc.0.connected\n"
        "getp candbc.0.drive-status.timeout\n"
        "getp candbc.0.drive-command.count\n"
        "unloadusr can-dbc\n"
        "loadusr -w sleep 0.3\n"
        "show comp\n")
    env = dict(os.environ, HALSDK_INSTANCE=f"candbc{os.getpid()}")
    proc = subprocess.run([sys.executable, "-m", "halsdk.halcmd.cli",
                           "halrun", "-f", "run.hal"], cwd=str(tmp_path),
                          env=env, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[:2] == ["TRUE", "TRUE"]
    assert int(lines[2]) > 0                            # sent cyclically
    assert "can-dbc" not in "\n".join(lines[3:])         # unloaded


# -- bad input (review findings) -----------------------------------------------
class NoLoop:
    """Stands in for IOLoop: an accepted command line returns at once."""

    def __init__(self, driver, period: float) -> None:
        self.driver = driver

    def run(self) -> None:
        pass


def run_main(args: list[str], capsys) -> tuple[int, str]:
    from halsdk.drivers.candbc import __main__ as program
    mp = pytest.MonkeyPatch()
    mp.setattr(program, "IOLoop", NoLoop)
    try:
        code = program.main(args)
    finally:
        mp.undo()
    return code, capsys.readouterr().err


@pytest.mark.parametrize("args, text", [
    (["--loop-period", "1e300"], "--loop-period: '1e300': expected seconds"),
    (["--loop-period", "inf"], "--loop-period: 'inf'"),
    (["--loop-period", "nan"], "--loop-period: 'nan'"),
    (["--loop-period", "5"], "at most 1"),
    (["--timeout-factor", "inf"], "--timeout-factor: 'inf'"),
    (["--period", "1e300"], "--period '1e300': expected seconds from 0"),
    (["--timeout", "DriveStatus=1e9"], "--timeout '1e9'"),
    (["--num", "99999999999"], "--num: '99999999999': expected 0 to 999"),
    (["--num", "-1"], "--num: '-1'"),
    (["--bitrate", "-5"], "--bitrate: '-5': expected bit/s"),
    (["--bitrate", "0"], "--bitrate: '0'"),
    (["-n", ""], "-n/--name: the component name is empty"),
    (["--bogus"], "unrecognized arguments: --bogus"),
])
def test_bad_options_one_line_status_1(args, text, hal, capsys):
    code, err = run_main(["--dbc", DEMO, "--interface", "virtual", *args],
                         capsys)
    assert code == 1
    assert err.startswith("can-dbc: ") and text in err, err
    assert len(err.splitlines()) == 1


def test_unknown_option_named_before_missing_dbc(hal, capsys):
    code, err = run_main(["--bogus"], capsys)
    assert (code, err) == (1, "can-dbc: unrecognized arguments: --bogus\n")
    code, err = run_main([], capsys)
    assert code == 1 and "required: --dbc" in err


def test_truncated_empty_and_bad_cycle_dbc(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = open(DEMO, encoding="cp1252").read()
    cut = text.index(" SG_ InfoPage") + len(" SG_ InfoPag")
    (tmp_path / "cut.dbc").write_text(text[:cut])
    line = text[:cut].count("\n") + 1
    with pytest.raises(ConfigError) as info:
        parse_args(["--dbc", "cut.dbc"])
    assert str(info.value) == (f"cut.dbc:{line}: incomplete statement at "
                               "the end of the file (truncated?)")
    # cut inside a signal's numbers: the earlier signals must not pass
    cut = text.index("RunHours m1 : 8|24")
    (tmp_path / "cut2.dbc").write_text(text[:cut + 12])
    with pytest.raises(ConfigError, match=r"^cut2.dbc:\d+: incomplete"):
        parse_args(["--dbc", "cut2.dbc"])
    (tmp_path / "empty.dbc").write_text("\n  \n// nothing\n")
    with pytest.raises(ConfigError, match=r"^empty.dbc: empty DBC file$"):
        parse_args(["--dbc", "empty.dbc"])
    (tmp_path / "slow.dbc").write_text(text.replace(
        'BO_ 512 50;', 'BO_ 512 99999999999;'))
    with pytest.raises(ConfigError, match=r"^slow.dbc:17: message "
                       "DriveCommand: cycle time 99999999999 ms"):
        parse_args(["--dbc", "slow.dbc"])
    # sizes no frame can hold are refused at once, at their line
    line = text[:text.index("BO_ 512 DriveCommand")].count("\n") + 1
    (tmp_path / "huge.dbc").write_text(text.replace(
        "BO_ 512 DriveCommand: 4", "BO_ 512 DriveCommand: 2147483647"))
    with pytest.raises(ConfigError) as info:
        parse_args(["--dbc", "huge.dbc"])
    assert str(info.value) == (f"huge.dbc:{line}: message DriveCommand: "
                               "2147483647 bytes; a CAN frame has at most 64")
    (tmp_path / "wide.dbc").write_text(text.replace(
        "TargetSpeed : 0|16@", "TargetSpeed : 0|99999@"))
    with pytest.raises(ConfigError, match=r"^wide.dbc:\d+: signal "
                       "TargetSpeed: bit 0, 99999 bits; a CAN frame has 512"):
        parse_args(["--dbc", "wide.dbc"])
    # the whole file still loads, with every signal
    config = parse_args(["--dbc", DEMO])
    info_msg = config.db.get_message_by_name("DriveInfo")
    assert len(info_msg.signals) == 3


def test_errors_name_the_dbc_as_given(tmp_path, monkeypatch, hal, capsys):
    monkeypatch.chdir(tmp_path)                  # demo.dbc: the shipped one
    for args, text in (
            (["--node", "Nope"], "demo.dbc: no node named 'Nope' (--node)"),
            (["--tx", "Nope"], "demo.dbc: no message named 'Nope' (--tx)")):
        code, err = run_main(["--dbc", "demo.dbc", *args], capsys)
        assert (code, err) == (1, f"can-dbc: {text}\n")
