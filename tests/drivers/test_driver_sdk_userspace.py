"""The userspace driver SDK (halsdk.driverkit) on a fake I/O board."""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from helpers import repo_path

from halsdk.driverkit import (
    FAULT_NONE,
    FAULT_OPEN,
    FAULT_READ,
    STAT_PINS,
    Backoff,
    Driver,
    DriverError,
    IOLoop,
)
from halsdk.types import Direction, HalType


class FakeBoard:
    """A device: 12 inputs, 2 outputs, one ADC, one DAC, one encoder."""

    def __init__(self) -> None:
        self.present = True
        self.broken_reads = False
        self.inputs = [False] * 12
        self.outputs = [False] * 2
        self.adc = 0.0
        self.dac = 0.0
        self.count = 0
        self.opens = 0

    def check(self) -> None:
        if not self.present:
            raise DriverError("board not found")


class FakeDriver(Driver):
    name = "fakedev"

    def __init__(self, board: FakeBoard, num: int = 0):
        super().__init__(num)
        self.board = board
        self.dt = 0.01

    def setup(self) -> None:
        self.ins = [self.digin(i) for i in range(12)]
        self.outs = [self.digout(i) for i in range(2)]
        self.adc = self.adcin(0)
        self.dac = self.dacout(0)
        self.enc = self.encoder(0)

    def open(self) -> None:
        self.board.check()
        self.board.opens += 1

    def read(self) -> None:
        self.board.check()
        if self.board.broken_reads:
            raise OSError("checksum error in reply")
        for ch, level in zip(self.ins, self.board.inputs):
            ch.update(level)
        self.adc.update(self.board.adc)
        self.enc.update(self.board.count, self.dt)

    def write(self) -> None:
        self.board.check()
        self.board.outputs = [ch.raw() for ch in self.outs]
        self.board.dac = self.dac.raw()


class FakeClock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def rig(hal):
    board = FakeBoard()
    clock = FakeClock()
    drv = FakeDriver(board)
    loop = IOLoop(drv, period=0.01, backoff=0.1, backoff_max=0.8,
                  clock=clock)
    loop.start()
    yield board, drv, loop, clock
    drv.shutdown()


def step(loop: IOLoop, clock: FakeClock, dt: float = 0.01, n: int = 1):
    for _ in range(n):
        clock.now += dt
        loop.cycle()


def test_canonical_names_types_directions(hal, rig):
    pins = {p.name: p for p in hal.pins("fakedev.0.*")}
    expect = {
        "fakedev.0.digin.03.in": (HalType.BIT, Direction.OUT),
        "fakedev.0.digin.11.in-not": (HalType.BIT, Direction.OUT),
        "fakedev.0.digout.01.out": (HalType.BIT, Direction.IN),
        "fakedev.0.adcin.00.value": (HalType.FLOAT, Direction.OUT),
        "fakedev.0.dacout.00.value": (HalType.FLOAT, Direction.IN),
        "fakedev.0.dacout.00.enable": (HalType.BIT, Direction.IN),
        "fakedev.0.encoder.00.count": (HalType.S32, Direction.OUT),
        "fakedev.0.encoder.00.position": (HalType.FLOAT, Direction.OUT),
        "fakedev.0.encoder.00.velocity": (HalType.FLOAT, Direction.OUT),
        "fakedev.0.encoder.00.reset": (HalType.BIT, Direction.IN),
        "fakedev.0.fault": (HalType.BIT, Direction.OUT),
        "fakedev.0.fault-code": (HalType.U32, Direction.OUT),
        "fakedev.0.fault-count": (HalType.U32, Direction.OUT),
        "fakedev.0.connected": (HalType.BIT, Direction.OUT),
    }
    for pin in STAT_PINS:
        expect[f"fakedev.0.{pin}"] = (HalType.FLOAT, Direction.OUT)
    for name, (type_, direction) in expect.items():
        assert name in pins, name
        assert (pins[name].type, pins[name].direction) == (type_, direction)
    assert len([n for n in pins if ".digin." in n]) == 24
    params = {p.name for p in hal.params("fakedev.0.*")}
    assert {"fakedev.0.digout.00.invert", "fakedev.0.adcin.00.scale",
            "fakedev.0.adcin.00.offset", "fakedev.0.dacout.00.high_limit",
            "fakedev.0.dacout.00.low_limit",
            "fakedev.0.encoder.00.position-scale"} <= params


def test_semantics_applied(hal, rig):
    board, drv, loop, clock = rig
    board.inputs[3] = True
    board.adc = 2.0
    hal.setp("fakedev.0.adcin.00.scale", 10.0)
    hal.setp("fakedev.0.adcin.00.offset", 1.5)
    hal.setp("fakedev.0.digout.00.out", True)
    hal.setp("fakedev.0.digout.01.invert", True)
    hal.setp("fakedev.0.dacout.00.value", 4.0)
    hal.setp("fakedev.0.dacout.00.scale", 2.0)
    hal.setp("fakedev.0.dacout.00.offset", 1.0)
    hal.setp("fakedev.0.dacout.00.high_limit", 7.5)
    step(loop, clock)
    assert hal.getp("fakedev.0.digin.03.in")
    assert not hal.getp("fakedev.0.digin.03.in-not")
    assert hal.getp("fakedev.0.digin.02.in-not")
    assert hal.getp("fakedev.0.adcin.00.value") == pytest.approx(18.5)
    assert board.outputs == [True, True]          # out, and !out inverted
    assert board.dac == 0.0                       # not enabled
    hal.setp("fakedev.0.dacout.00.enable", True)
    step(loop, clock)
    assert board.dac == pytest.approx(7.5)        # 9 clamped to high_limit
    hal.setp("fakedev.0.dacout.00.value", -10.0)
    hal.setp("fakedev.0.dacout.00.low_limit", -3.0)
    step(loop, clock)
    assert board.dac == pytest.approx(-3.0)


def test_encoder_scale_velocity_reset(hal, rig):
    board, drv, loop, clock = rig
    hal.setp("fakedev.0.encoder.00.position-scale", 100.0)
    board.count = 1000
    step(loop, clock)
    board.count = 1050
    step(loop, clock)
    assert hal.getp("fakedev.0.encoder.00.count") == 1050
    assert hal.getp("fakedev.0.encoder.00.position") == pytest.approx(10.5)
    assert hal.getp("fakedev.0.encoder.00.velocity") == pytest.approx(50.0)
    hal.setp("fakedev.0.encoder.00.reset", True)
    step(loop, clock)
    assert hal.getp("fakedev.0.encoder.00.count") == 0
    # the counter stood still: a reset is no movement
    assert hal.getp("fakedev.0.encoder.00.velocity") == 0.0
    hal.setp("fakedev.0.encoder.00.reset", False)
    board.count = 1040
    step(loop, clock)
    assert hal.getp("fakedev.0.encoder.00.count") == -10
    assert hal.getp("fakedev.0.encoder.00.velocity") == pytest.approx(-10.0)


def test_timing_statistics(hal, rig):
    board, drv, loop, clock = rig
    step(loop, clock, 0.01)
    step(loop, clock, 0.03)
    step(loop, clock, 0.01)
    assert hal.getp("fakedev.0.period") == pytest.approx(0.01)
    assert hal.getp("fakedev.0.max-period") == pytest.approx(0.03)
    slow = board.check

    def slow_check() -> None:
        clock.now += 0.002
        slow()
    board.check = slow_check
    step(loop, clock)
    assert hal.getp("fakedev.0.read-time") == pytest.approx(0.002)
    assert hal.getp("fakedev.0.write-time") == pytest.approx(0.002)


def test_disappear_backoff_grows_then_resets(hal, rig, caplog):
    board, drv, loop, clock = rig
    step(loop, clock)
    assert hal.getp("fakedev.0.connected") and board.opens == 1
    board.present = False
    attempts = []
    real_open = drv.open

    def counting_open() -> None:
        attempts.append(clock.now)
        real_open()
    drv.open = counting_open
    with caplog.at_level(logging.INFO, "halsdk.driverkit"):
        for _ in range(400):                      # 4 s of cycles
            step(loop, clock)
    assert hal.getp("fakedev.0.fault")
    assert hal.getp("fakedev.0.fault-code") == FAULT_OPEN
    assert not hal.getp("fakedev.0.connected")
    gaps = [round(b - a, 2) for a, b in zip(attempts, attempts[1:])]
    assert gaps[:4] == [0.2, 0.4, 0.8, 0.8]       # doubles up to the cap
    errors = [r for r in caplog.records if r.levelno >= logging.ERROR]
    # read failed once, open failed once: no message per attempt
    assert [r.getMessage() for r in errors] == [
        "fakedev.0: read failed: board not found",
        "fakedev.0: open failed: board not found"]
    assert all(r.exc_info is None for r in caplog.records)
    board.present = True
    step(loop, clock, n=100)
    assert not hal.getp("fakedev.0.fault")
    assert hal.getp("fakedev.0.fault-code") == FAULT_NONE
    assert hal.getp("fakedev.0.connected")
    assert loop.retry.delay == pytest.approx(0.1)  # back-off reset
    assert hal.getp("fakedev.0.fault-count") == 2


def test_read_always_raising(hal, rig, caplog):
    board, drv, loop, clock = rig
    board.broken_reads = True
    with caplog.at_level(logging.ERROR, "halsdk.driverkit"):
        step(loop, clock, n=300)
    assert hal.getp("fakedev.0.fault")
    assert hal.getp("fakedev.0.fault-code") == FAULT_READ
    assert hal.getp("fakedev.0.fault-count") == 1
    assert [r.getMessage() for r in caplog.records] == [
        "fakedev.0: read failed: checksum error in reply"]
    assert drv.fault_text == "fakedev.0: read failed: checksum error in reply"
    assert 3 <= board.opens <= 8                   # retried, backed off


def test_threaded_loop_clean_stop(hal):
    board = FakeBoard()
    drv = FakeDriver(board, num=1)
    loop = IOLoop(drv, period=0.005)
    thread = loop.start_thread()
    deadline = time.monotonic() + 5
    while board.opens == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    board.inputs[0] = True
    time.sleep(0.05)
    assert hal.getp("fakedev.1.digin.00.in")
    loop.stop()
    assert not thread.is_alive()
    assert not hal.pins("fakedev.1.*")


@pytest.mark.parametrize("kw", [
    {"period": 0}, {"period": -1}, {"period": float("nan")},
    {"period": float("inf")}, {"period": 1e300},
    {"backoff": 0}, {"backoff": float("nan")}, {"backoff_max": 1e300},
    {"backoff": 2.0, "backoff_max": 1.0}])
def test_bad_loop_arguments(kw):
    # a bad number is refused here, not an OverflowError in the loop
    with pytest.raises(ValueError):
        IOLoop(Driver(), **kw)


def test_backoff_doubles_to_the_maximum_and_resets():
    retry = Backoff(0.5, 2.0)
    assert retry.ready(0.0)
    assert [retry.failed(10.0) for _ in range(4)] == [0.5, 1.0, 2.0, 2.0]
    assert not retry.ready(11.9) and retry.ready(12.0)
    retry.succeeded()
    assert retry.ready(0.0) and retry.failed(20.0) == 0.5


def test_sigterm_stops_loadusr_process(tmp_path, hal):
    script = tmp_path / "drv.py"
    script.write_text(textwrap.dedent("""
        import sys
        from halsdk.driverkit import Driver, IOLoop

        class Tiny(Driver):
            name = "tiny"
            def setup(self):
                self.ch = self.digout(0)
            def open(self):
                print("open", flush=True)
            def close(self):
                print("closed", flush=True)

        IOLoop(Tiny(), period=0.01).run()
        print("done", flush=True)
    """))
    env = dict(os.environ)
    proc = subprocess.Popen([sys.executable, str(script)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline().strip() == "open"
        assert [p.name for p in hal.pins("tiny.0.*")] == [
            "tiny.0.connected", "tiny.0.digout.00.out", "tiny.0.fault",
            "tiny.0.fault-code", "tiny.0.fault-count", "tiny.0.max-period",
            "tiny.0.period", "tiny.0.read-time", "tiny.0.write-time"]
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert out.split() == ["closed", "done"]
    assert "Traceback" not in err
    assert not hal.pins("tiny.*")


def docs_example() -> str:
    """The code block captioned iobox.py in docs/drivers.rst."""
    with open(repo_path("docs", "drivers.rst"),
              encoding="utf-8") as f:
        text = f.read()
    start = text.index("   :caption: iobox.py\n")
    body = []
    for line in text[start:].splitlines()[2:]:
        if line.strip() and not line.startswith("   "):
            break
        body.append(line)
    return textwrap.dedent("\n".join(body))


def test_docs_example_runs_and_recovers(tmp_path, hal):
    script = tmp_path / "iobox.py"
    script.write_text(docs_example())
    proc = subprocess.Popen([sys.executable, str(script), "--flaky"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            if hal.pins("iobox.0.fault-count") and \
                    hal.getp("iobox.0.fault-count") >= 1 and \
                    not hal.getp("iobox.0.fault"):
                break
            time.sleep(0.02)
        assert hal.getp("iobox.0.fault-count") >= 1   # dropped out ...
        assert hal.getp("iobox.0.connected")           # ... and came back
        assert hal.pins("iobox.0.digin.03.in-not")
        hal.setp("iobox.0.adcin.00.scale", 0.0)
        time.sleep(0.05)
        assert hal.getp("iobox.0.adcin.00.value") == 0.0
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "no reply from the box" in err and "Traceback" not in err
    assert not hal.pins("iobox.0.*")


def test_threaded_loop_ends_when_component_removed(hal, caplog):
    board = FakeBoard()
    drv = FakeDriver(board, num=2)
    loop = IOLoop(drv, period=0.005)
    with caplog.at_level(logging.WARNING, "halsdk.driverkit"):
        thread = loop.start_thread()
        hal.unload("fakedev.2")       # as unloadusr does
        thread.join(5)
    assert not thread.is_alive()
    assert "fakedev.2: component removed, stopping" in caplog.messages
    assert board.opens <= 1


def test_duplicate_device_exits_with_message(hal):
    board = FakeBoard()
    first = FakeDriver(board)
    first.start()
    try:
        with pytest.raises(SystemExit) as info:
            IOLoop(FakeDriver(board)).run(handle_signals=False)
        assert info.value.code == 1
    finally:
        first.shutdown()
