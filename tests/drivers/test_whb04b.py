"""The XHC WHB04B pendant driver (halsdk.drivers.whb04b) on the fake
pyusb backend that replays recorded reports."""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import data_path
from helpers.polling import wait_for
from helpers.processes import ended_at_exit, sigterm

from halsdk.driverkit import FAULT_NONE, FAULT_OPEN, FAULT_READ, IOLoop
from halsdk.drivers.whb04b import BUTTON_NAMES, FakeBackend, Whb04bDriver
from halsdk.drivers.whb04b.fake import ScriptError, load_script, parse_script
from halsdk.types import Direction, HalType

DATA = data_path("whb04b")
P = "whb04b.0."


class FakeClock:
    def __init__(self) -> None:
        self.now = 50.0

    def __call__(self) -> float:
        return self.now


class Rig:
    def __init__(self, hal, steps=()) -> None:
        self.hal = hal
        self.clock = FakeClock()
        self.usb = FakeBackend(steps, clock=self.clock)
        self.drv = Whb04bDriver(backend=self.usb, clock=self.clock)
        self.loop = IOLoop(self.drv, period=0.02, backoff=0.1,
                           backoff_max=0.4, clock=self.clock)
        self.loop.start()

    def step(self, n: int = 1, dt: float = 0.02) -> None:
        for _ in range(n):
            self.clock.now += dt
            self.loop.cycle()

    def feed(self, *reports: str) -> None:
        self.usb.feed(*reports)
        self.step()

    def get(self, pin: str):
        return self.hal.getp(P + pin)


@pytest.fixture
def rig(hal):
    r = Rig(hal)
    r.step()
    yield r
    r.drv.shutdown()


def pressed(rig: Rig) -> set[str]:
    return {n for n in BUTTON_NAMES if rig.get(f"button.{n}")}


def test_component_and_pin_types(hal, rig):
    assert "whb04b" in [c.name for c in hal.components()]
    pins = {p.name: p for p in hal.pins("whb04b.0.*")}
    expect = {
        "button.start-pause": (HalType.BIT, Direction.OUT),
        "button.macro-16": (HalType.BIT, Direction.OUT),
        "encoder.00.count": (HalType.S32, Direction.OUT),
        "encoder.00.reset": (HalType.BIT, Direction.IN),
        "axis.off": (HalType.BIT, Direction.OUT),
        "axis.number": (HalType.S32, Direction.OUT),
        "jog.increment": (HalType.FLOAT, Direction.OUT),
        "jog.percent": (HalType.FLOAT, Direction.OUT),
        "display.c": (HalType.FLOAT, Direction.IN),
        "display.work-coords": (HalType.BIT, Direction.IN),
        "bad-reports": (HalType.U32, Direction.OUT),
        "connected": (HalType.BIT, Direction.OUT),
        "fault": (HalType.BIT, Direction.OUT),
    }
    for name, kind in expect.items():
        pin = pins[P + name]
        assert (pin.type, pin.direction) == kind, name
    assert len([n for n in pins if ".button." in n]) == 31
    assert rig.get("connected") and not rig.get("fault")
    assert rig.get("axis.off") and rig.get("axis.number") == -1


def test_buttons_press_release_and_two_at_once(rig):
    rig.feed("04 10 02 00 0d 11 00 00")                 # Stop
    assert pressed(rig) == {"stop"}
    rig.feed("04 11 02 0b 0d 11 00 00")                 # Stop + S-ON/OFF
    assert pressed(rig) == {"stop", "s-on-off"}
    rig.feed("04 12 00 00 0d 11 00 00")
    assert pressed(rig) == set()
    rig.feed("04 13 0c 00 0d 11 00 00")                 # Fn alone
    assert pressed(rig) == {"fn"}
    rig.feed("04 14 0c 04 0d 11 00 00")                 # Fn + Feed+
    assert pressed(rig) == {"fn", "macro-1"}
    rig.feed("04 15 10 0c 0d 11 00 00")                 # Macro-10 + Fn
    assert pressed(rig) == {"fn", "macro-14"}
    rig.feed("04 16 10 00 0d 11 00 00")
    assert pressed(rig) == {"macro-10"}


def test_wheel_counts_accumulate_and_reset(hal, rig):
    rig.feed("04 01 00 00 0d 11 05 00")
    assert rig.get("encoder.00.count") == 5
    rig.feed("04 02 00 00 0d 11 03 00", "04 03 00 00 0d 11 fe 00")
    assert rig.get("encoder.00.count") == 6              # +3 -2 in a cycle
    rig.feed("04 04 00 00 0d 11 9c 00")                  # -100
    assert rig.get("encoder.00.count") == -94
    assert rig.get("encoder.00.velocity") == pytest.approx(-100 / 0.02)
    hal.setp(P + "encoder.00.position-scale", 4.0)
    rig.feed("04 05 00 00 0d 11 7f 00")                  # +127
    assert rig.get("encoder.00.count") == 33
    assert rig.get("encoder.00.position") == pytest.approx(8.25)
    hal.setp(P + "encoder.00.reset", True)
    rig.feed("04 06 00 00 0d 11 07 00")
    assert rig.get("encoder.00.count") == 0
    hal.setp(P + "encoder.00.reset", False)
    rig.feed("04 07 00 00 0d 11 02 00")
    assert rig.get("encoder.00.count") == 2
    rig.drv.count = 2**31 - 3                            # wraps, no error
    rig.feed("04 08 00 00 0d 11 05 00")
    assert rig.get("encoder.00.count") == -2**31 + 2
    assert not rig.get("fault")


def test_axis_and_step_selection(hal, rig):
    rig.feed("04 01 00 00 0f 12 00 00")                  # Y, position 3
    assert rig.get("axis.y") and not rig.get("axis.x")
    assert not rig.get("axis.off") and rig.get("axis.number") == 1
    assert rig.get("jog.position") == 3
    assert rig.get("jog.increment") == pytest.approx(0.1)
    assert rig.get("jog.percent") == pytest.approx(10.0)
    assert rig.get("jog.mode-continuous") and not rig.get("jog.mode-step")
    rig.feed("04 02 0f 00 1b 16 00 00")                  # Step key, C, pos 6
    assert rig.get("jog.mode-step") and not rig.get("jog.mode-continuous")
    assert rig.get("axis.c") and rig.get("axis.number") == 5
    assert rig.get("jog.increment") == pytest.approx(10.0)
    assert rig.get("jog.percent") == pytest.approx(100.0)
    hal.setp(P + "jog.increment-1", 0.0001)              # inch machine
    rig.feed("04 03 00 00 0d 06 00 00")                  # axis off, pos 1
    assert rig.get("axis.off") and rig.get("axis.number") == -1
    assert rig.get("jog.increment") == pytest.approx(0.0001)
    assert rig.get("jog.mode-step")                      # mode is kept
    rig.feed("04 04 00 00 1c 14 00 00")                  # A, Lead
    assert rig.get("jog.mode-lead") and not rig.get("jog.mode-step")
    assert rig.get("jog.position") == 7 and rig.get("jog.increment") == 0
    rig.feed("04 05 0e 00 10 13 00 00")                  # Continuous key
    assert rig.get("jog.mode-continuous") and rig.get("axis.z")
    assert rig.get("jog.increment") == pytest.approx(1.0)


def test_display_encoding_byte_exact(hal, rig):
    for pin, value in (("x", 1.2345), ("y", -0.5), ("z", 123.0),
                       ("a", -0.0001), ("b", 65536.0), ("c", 0.0),
                       ("feed-override", 1.2), ("spindle-override", 0.8),
                       ("feed", 1500.0), ("spindle-speed", 70000.0)):
        hal.setp(P + "display." + pin, value)
    rig.usb.control.clear()
    rig.step()
    assert rig.usb.control == [
        (0x21, 0x09, 0x0306, 0, bytes.fromhex(h)) for h in (
            "06 fe fd fe 00 01 00 29", "06 09 00 00 88 93 7b 00",
            "06 00 00 78 00 50 00 00")]
    rig.step()
    assert len(rig.usb.control) == 3                     # unchanged: no send
    hal.setp(P + "display.show-speeds", True)
    hal.setp(P + "display.work-coords", True)
    hal.setp(P + "display.reset", True)
    rig.feed("04 01 0f 00 0d 14 00 00")                  # Step key, axis A
    assert rig.usb.display_writes()[-3:] == [bytes.fromhex(h) for h in (
        "06 fe fd fe c1 00 00 01", "06 80 ff ff 0f 27 00 00",
        "06 00 00 dc 05 ff ff 00")]
    rig.step(n=60)                                       # 1.2 s: refreshed
    assert len(rig.usb.control) == 9


def test_malformed_reports_counted_logged_once(rig, caplog):
    rig.usb.add(*load_script(DATA / "malformed.txt"))
    with caplog.at_level(logging.WARNING, "halsdk.driverkit"):
        rig.step(n=3)
    assert rig.get("bad-reports") == 5
    assert rig.get("reports") == 7
    assert rig.get("encoder.00.count") == 3              # only good ones
    assert rig.get("axis.y") and rig.get("jog.position") == 2
    assert not rig.get("fault") and rig.get("connected")
    msgs = [r.getMessage() for r in caplog.records]
    assert len(msgs) == 1 and "6 bytes, expected 8" in msgs[0]
    assert all(r.exc_info is None for r in caplog.records)


def test_bad_header_alone(rig):
    rig.feed("84 01 02 00 0d 11 05 00")
    assert rig.get("bad-reports") == 1
    assert pressed(rig) == set() and rig.get("encoder.00.count") == 0


def test_absent_at_start_then_plugged(hal, caplog):
    with caplog.at_level(logging.ERROR, "halsdk.driverkit"):
        r = Rig(hal, load_script(DATA / "absent-then-plugged.txt"))
        try:
            r.step()
            assert not r.get("connected") and r.get("fault")
            assert r.get("fault-code") == FAULT_OPEN
            r.step(n=10)                                 # 0.2 s: still away
            assert not r.get("connected")
            r.step(n=40)                                 # back-off elapses
            assert r.get("connected") and not r.get("fault")
            assert r.get("fault-code") == FAULT_NONE
            assert pressed(r) == {"stop"} and r.get("axis.z")
            assert r.get("encoder.00.count") == 4
        finally:
            r.drv.shutdown()
    assert [m for m in caplog.messages] == [
        "whb04b.0: open failed: no WHB04B pendant (USB 10ce:eb93) found"]


def test_unplug_and_replug(hal, caplog):
    with caplog.at_level(logging.ERROR, "halsdk.driverkit"):
        r = Rig(hal, load_script(DATA / "unplug-replug.txt"))
        try:
            r.step()                       # reads both reports, then ENODEV
            assert r.get("fault") and r.get("fault-code") == FAULT_READ
            assert not r.get("connected")
            assert pressed(r) == set()     # held Reset released on unplug
            assert r.get("encoder.00.count") == 5
            assert not r.usb.claimed
            r.step(n=60)
            assert r.get("connected") and not r.get("fault")
            assert r.get("encoder.00.count") == 0
            assert r.get("fault-count") == 2               # read, open
            assert r.usb.opens == 2
        finally:
            r.drv.shutdown()
    assert "No such device" in caplog.messages[0]
    assert "read failed" in caplog.messages[0]


def test_replay_script_errors():
    with pytest.raises(ScriptError, match=r"bad-script.txt:2: 'pause'"):
        load_script(DATA / "bad-script.txt")
    with pytest.raises(ScriptError, match=r"x.txt:1: expected hex"):
        parse_script(["04 zz"], "x.txt")
    with pytest.raises(ScriptError, match=r"nosuch.txt: cannot read"):
        load_script(DATA / "nosuch.txt")
    steps = parse_script(["# c", "", "04 01  # tail", "pause 0", "plug"])
    assert [s.kind for s in steps] == ["report", "pause", "plug"]


# -------------------------------------------------------------- programs

def _replayers(marker: str) -> list[int]:
    """Driver processes whose command line names ``marker``."""
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            cmd = Path(f"/proc/{pid}/cmdline").read_bytes()
            state = Path(f"/proc/{pid}/stat").read_text().split()[2]
        except OSError:
            continue
        if marker.encode() in cmd and b"whb04b" in cmd and state != "Z":
            found.append(int(pid))
    return found


def _halcmd(tmp_path: Path, *lines: str) -> tuple[int, str]:
    """Run halcmd on ``lines``; output goes to a file, not a pipe, since
    the driver it starts keeps the inherited descriptors open."""
    (tmp_path / "cmd.hal").write_text("".join(f"{ln}\n" for ln in lines))
    log = tmp_path / "halcmd.log"
    with open(log, "w") as out:
        rc = subprocess.run(
            [sys.executable, "-m", "halsdk.halcmd.cli", "halcmd", "-f",
             "cmd.hal"], cwd=tmp_path, stdout=out, stderr=out,
            stdin=subprocess.DEVNULL, timeout=30).returncode
    return rc, log.read_text()


def test_loadusr_replay_and_unloadusr(hal, tmp_path, python_tools_first):
    script = tmp_path / "session.txt"
    script.write_text((DATA / "session.txt").read_text())
    try:
        rc, out = _halcmd(tmp_path, f"loadusr -W whb04b --replay {script}")
        assert rc == 0, out
        assert wait_for(lambda: hal.getp(P + "encoder.00.count") == 7)
        assert hal.getp(P + "button.stop") and hal.getp(P + "axis.b")
        assert hal.getp(P + "jog.increment") == pytest.approx(1.0)
        assert hal.getp(P + "connected") and not hal.getp(P + "fault")
        assert len(_replayers(str(tmp_path))) == 1
        rc, out = _halcmd(tmp_path, "unloadusr whb04b")
        assert rc == 0, out
        assert wait_for(lambda: not _replayers(str(tmp_path)))
        assert not hal.pins("whb04b.*")
    finally:
        for pid in _replayers(str(tmp_path)):
            os.kill(pid, signal.SIGKILL)


def test_program_demo_sigterm_and_bad_file(hal, tmp_path):
    proc = subprocess.Popen(
        [sys.executable, "-m", "halsdk.drivers.whb04b", "--replay", "demo",
         "-n", "pendant"], cwd=tmp_path, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)
    with ended_at_exit(proc):
        assert wait_for(lambda: bool(hal.pins(P + "connected"))
                     and hal.getp(P + "connected"))
        assert "pendant" in [c.name for c in hal.components()]
        assert wait_for(lambda: hal.getp(P + "jog.mode-lead"))   # last report
        assert hal.getp(P + "encoder.00.count") == 16
        assert hal.getp(P + "axis.z") and not hal.getp(P + "button.fn")
        out, err = sigterm(proc, 10)
    assert proc.returncode == 0, err
    assert "Traceback" not in err
    assert not hal.pins("whb04b.*")
    bad = subprocess.run(
        [sys.executable, "-m", "halsdk.drivers.whb04b", "--replay",
         str(DATA / "bad-script.txt")], cwd=tmp_path, capture_output=True,
        text=True, timeout=30)
    assert bad.returncode == 1
    assert bad.stderr.strip().startswith("whb04b: ")
    assert "bad-script.txt:2:" in bad.stderr and "Traceback" not in bad.stderr


def test_program_without_device_faults_and_stops(hal, tmp_path):
    """The real pyusb path: no receiver with this id -> one open fault
    message, fault pins set, still a clean SIGTERM exit."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "halsdk.drivers.whb04b", "--product-id",
         "fffe"], cwd=tmp_path, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)
    with ended_at_exit(proc):
        assert wait_for(lambda: bool(hal.pins(P + "fault-code"))
                     and hal.getp(P + "fault-code") == FAULT_OPEN)
        assert hal.getp(P + "fault") and not hal.getp(P + "connected")
        time.sleep(0.5)                      # several attempts, backed off
        out, err = sigterm(proc, 10)
    assert proc.returncode == 0, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "whb04b.0: open failed: " in lines[0], err
    assert "Traceback" not in err


# ------------------------------------------------- bad input (review findings)

@pytest.mark.parametrize("line, text", [
    ("pause 1e300", "1: 'pause' needs one number of seconds from 0 to 3600"),
    ("pause inf", "1: 'pause' needs"),
    ("pause nan", "1: 'pause' needs"),
    ("pause 3601", "1: 'pause' needs"),
    ("05 2", "1: hex bytes are two digits each, not '2'"),
    ("04 011", "1: hex bytes are two digits each, not '011'"),
    ("04 -1", "1: expected hex bytes"),
])
def test_replay_line_limits(line, text):
    with pytest.raises(ScriptError) as info:
        parse_script([line], "s.txt")
    assert str(info.value).startswith(f"s.txt:{text}")


def test_replay_limits_accept_the_edges():
    steps = parse_script(["pause 3600", "0A ff 00"])
    assert steps[0].seconds == 3600 and steps[1].data == b"\x0a\xff\x00"


def test_unreadable_replay_names_file_once(tmp_path):
    with pytest.raises(ScriptError) as info:
        load_script(tmp_path / "nosuch.txt")
    assert str(info.value) == (f"{tmp_path / 'nosuch.txt'}: cannot read: "
                               "No such file or directory")


@pytest.mark.parametrize("args, text", [
    (["--period", "1e300"], "argument --period: '1e300': expected seconds"),
    (["--period", "inf"], "argument --period: 'inf'"),
    (["--period", "-1"], "argument --period: '-1'"),
    (["--period", "2"], "at most 1"),
    (["--bogus"], "unrecognized arguments: --bogus"),
    (["--product-id", "zz"], "not a hex number"),
    (["-n", ""], "the component name is empty"),
    (["--replay", str(DATA / "long-pause.txt")], "long-pause.txt:2: 'pause'"),
])
def test_bad_command_line_one_line_status_1(args, text, hal, capsys,
                                            monkeypatch):
    from halsdk.drivers.whb04b import __main__ as program

    class NoLoop:                    # an accepted command line returns
        def __init__(self, driver, period: float) -> None:
            pass

        def run(self) -> None:
            pass
    monkeypatch.setattr(program, "IOLoop", NoLoop)
    assert program.main(args) == 1
    err = capsys.readouterr().err
    assert err.startswith("whb04b: ") and text in err, err
    assert len(err.splitlines()) == 1
