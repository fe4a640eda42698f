"""Hm2Sim: the simulated card on UDP, its Python API and its faults."""

from __future__ import annotations

import socket
import struct
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from halsdk.drivers.hm2sim import Hm2Sim, SimError, lbp16

COOKIE = lbp16.encode([lbp16.read(lbp16.SPACE_HM2, 0x0100)])
COOKIE_REPLY = struct.pack("<I", 0x55AACAFE)
#: how long a test waits for a reply that must not come
QUIET = 0.2


class Client:
    def __init__(self, port: int) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.connect(("127.0.0.1", port))

    def ask(self, packet: bytes = COOKIE, timeout: float = 2.0
            ) -> bytes | None:
        self.sock.send(packet)
        return self.recv(timeout)

    def recv(self, timeout: float = 2.0) -> bytes | None:
        self.sock.settimeout(timeout)
        try:
            return self.sock.recv(2000)
        except socket.timeout:
            return None

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def sim() -> Iterator[Hm2Sim]:
    with Hm2Sim("7i96s", port=0, realtime=False, seed=1) as s:
        yield s


@pytest.fixture
def client(sim: Hm2Sim) -> Iterator[Client]:
    c = Client(sim.port)
    yield c
    c.close()


def test_answers_and_stops(sim: Hm2Sim, client: Client) -> None:
    assert sim.running and sim.port > 0
    assert client.ask() == COOKIE_REPLY
    # writes are not answered
    assert client.ask(lbp16.encode([lbp16.write(0, 0x0200, [1])]),
                      QUIET) is None
    assert sim.leds == 1
    sim.stop()
    assert not sim.running
    sim.stop()                                  # twice is fine


def test_port_in_use() -> None:
    with Hm2Sim(port=0) as first:
        with pytest.raises(SimError, match=f"UDP 127.0.0.1:{first.port} "
                                           "is in use"):
            Hm2Sim(port=first.port).start()


def test_python_api(sim: Hm2Sim, client: Client) -> None:
    rate = round(2000 * 2**32 / 100e6)
    client.ask(lbp16.encode([lbp16.write(0, 0x2008, [rate])]), QUIET)
    sim.step(0.5)
    assert sim.axis_position(2) == pytest.approx(1000, abs=0.1)
    assert sim.stepgen(2)["steps_per_second"] == pytest.approx(2000, rel=1e-4)
    sim.set_input(5, False)
    (port0,) = struct.unpack("<I", client.ask(lbp16.encode(
        [lbp16.read(0, 0x1000)])))
    assert not port0 >> 5 & 1 and port0 >> 4 & 1
    client.ask(lbp16.encode([lbp16.write(0, 0x1100, [1 << 12]),
                             lbp16.write(0, 0x1000, [0])]), QUIET)
    assert sim.is_output(12) and not sim.pin(12) and sim.pin(13)
    sim.set_encoder(0, 1234)
    assert sim.encoder(0)["count"] == 1234
    sim.set_index_period(0, 1000)
    sim.set_encoder(0, 2500)                    # crosses 2000
    assert sim.encoder(0)["index_events"] == 1
    sim.set_encoder(0, -10)                     # 2000, 1000 and 0
    assert sim.encoder(0)["index_events"] == 4
    sim.pulse_index(0)
    assert sim.encoder(0)["index_events"] == 5
    sim.set_encoder(0, 2500)
    sim.set_encoder_velocity(0, 1000)
    sim.step(0.25)
    assert sim.encoder(0)["position"] == 2750
    assert sim.pwm_duty(0) == 0.0
    assert not sim.watchdog_bitten
    with pytest.raises(IndexError, match="stepgen 5: the 7i96s has 5"):
        sim.axis_position(5)
    with pytest.raises(IndexError, match="pins 0..50"):
        sim.set_input(51, True)


def test_encoder_coupled_to_a_stepgen(sim: Hm2Sim, client: Client) -> None:
    sim.couple(encoder=0, stepgen=1, counts_per_step=4)
    rate = round(-500 * 2**32 / 100e6) & 0xFFFFFFFF
    client.ask(lbp16.encode([lbp16.write(0, 0x2004, [rate])]), QUIET)
    sim.step(1.0)
    assert sim.encoder(0)["position"] == round(sim.axis_position(1) * 4)
    assert sim.encoder(0)["position"] == pytest.approx(-2000, abs=1)


def test_realtime_clock_moves_the_axis() -> None:
    with Hm2Sim(port=0) as sim:
        c = Client(sim.port)
        rate = round(10_000 * 2**32 / 100e6)
        c.ask(lbp16.encode([lbp16.write(0, 0x2000, [rate])]), 0.05)
        deadline = time.monotonic() + 5
        while sim.axis_position(0) < 100 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert sim.axis_position(0) >= 100
        c.close()


def test_drop_next(sim: Hm2Sim, client: Client) -> None:
    sim.faults.drop(next=2)
    assert client.ask(timeout=QUIET) is None
    assert client.ask(timeout=QUIET) is None
    assert client.ask() == COOKIE_REPLY
    assert sim.stats.dropped == 2 and sim.stats.replies == 1


def test_drop_probability(sim: Hm2Sim, client: Client) -> None:
    sim.faults.drop(probability=1.0)
    assert client.ask(timeout=QUIET) is None
    sim.faults.drop(probability=0.5)
    answered = sum(client.ask(timeout=QUIET) is not None for _ in range(20))
    assert 0 < answered < 20                    # seed 1: not all, not none
    sim.faults.clear()
    assert client.ask() == COOKIE_REPLY


def test_duplicate(sim: Hm2Sim, client: Client) -> None:
    sim.faults.duplicate(next=1)
    assert client.ask() == COOKIE_REPLY
    assert client.recv() == COOKIE_REPLY        # the copy
    assert client.recv(QUIET) is None
    assert sim.stats.duplicated == 1


def test_truncate(sim: Hm2Sim, client: Client) -> None:
    sim.faults.truncate(next=1)
    assert client.ask() == COOKIE_REPLY[:2]
    sim.faults.truncate(next=1, keep=1)
    assert client.ask() == COOKIE_REPLY[:1]
    assert client.ask() == COOKIE_REPLY


def test_delay(sim: Hm2Sim, client: Client) -> None:
    sim.faults.delay(0.3, next=1)
    start = time.monotonic()
    assert client.ask(timeout=0.1) is None      # not yet
    assert client.recv(5.0) == COOKIE_REPLY     # late
    assert time.monotonic() - start >= 0.3
    assert client.ask() == COOKIE_REPLY         # the next one on time


def test_card_goes_away_and_comes_back(sim: Hm2Sim, client: Client) -> None:
    rate = round(1000 * 2**32 / 100e6)
    client.ask(lbp16.encode([lbp16.write(0, 0x2000, [rate])]), QUIET)
    sim.step(1.0)
    assert sim.axis_position(0) > 0
    sim.go_away()
    assert client.ask(timeout=QUIET) is None
    assert sim.stats.ignored == 1
    axis = sim.axis_position(0)
    sim.set_input(2, False)
    sim.come_back()
    assert client.ask() == COOKIE_REPLY
    # it was powered off: its registers start again, the machine stays
    (acc,) = struct.unpack("<I", client.ask(lbp16.encode(
        [lbp16.read(0, 0x2100)])))
    assert acc == 0 and sim.stepgen(0)["rate"] == 0
    assert sim.axis_position(0) == axis
    assert not sim.pin(2)


def test_away_without_reset_keeps_the_state(sim: Hm2Sim,
                                            client: Client) -> None:
    sim.set_encoder(0, 77)
    sim.go_away(reset=False)
    assert client.ask(timeout=QUIET) is None
    sim.come_back()
    assert client.ask() == COOKIE_REPLY
    assert sim.encoder(0)["count"] == 77


def test_malformed_datagram_is_not_answered(sim: Hm2Sim,
                                            client: Client) -> None:
    assert client.ask(b"\x81\x42\x00", QUIET) is None
    assert sim.stats.malformed == 1
    assert client.ask() == COOKIE_REPLY


@pytest.mark.parametrize("call, message", [
    (lambda f: f.drop(next=-1), "next=-1"),
    (lambda f: f.drop(probability=2), "probability=2"),
    (lambda f: f.delay(100), "0..60 s"),
    (lambda f: f.truncate(next=1, keep=-1), "keep=-1"),
])
def test_bad_fault_settings(sim: Hm2Sim, call, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call(sim.faults)


def test_packet_log(tmp_path: Path) -> None:
    log = tmp_path / "packets.txt"
    with Hm2Sim(port=0, log=log) as sim:
        c = Client(sim.port)
        assert c.ask() == COOKIE_REPLY
        c.close()
    text = log.read_text()
    assert "<- 81420001" in text
    assert "read hm2 0x0100 32bit x1 inc" in text
    assert "-> fecaaa55" in text


def test_wait_requests(sim: Hm2Sim, client: Client) -> None:
    assert sim.requests == 0
    assert not sim.wait_requests(1, timeout=0.05)
    client.sock.send(lbp16.encode([lbp16.write(0, 0x0200, [7])]))
    assert sim.wait_requests(1, timeout=5.0)
    assert sim.requests == 1
    assert sim.leds == 7                        # executed when counted


def test_a_model_error_does_not_stop_the_card(sim: Hm2Sim, client: Client,
                                              monkeypatch) -> None:
    def broken(commands):
        raise RuntimeError("model bug")
    monkeypatch.setattr(sim.card, "execute", broken)
    assert client.ask(timeout=QUIET) is None
    monkeypatch.undo()
    assert client.ask() == COOKIE_REPLY
    assert isinstance(sim.error, RuntimeError) and sim.running


def test_lose_datagrams_to_the_card(sim: Hm2Sim, client: Client) -> None:
    sim.faults.lose(next=2)
    # a lost write never reaches the card
    assert client.ask(lbp16.encode([lbp16.write(0, 0x0200, [5])]),
                      QUIET) is None
    assert client.ask(timeout=QUIET) is None       # a lost read
    assert sim.leds == 0
    assert client.ask(lbp16.encode([lbp16.write(0, 0x0200, [6]),
                                    lbp16.read(0, 0x0200)])) == b"\6\0\0\0"
    assert sim.stats.lost == 2
    # the card counts only what reached it
    reply = client.ask(bytes.fromhex("01590800"))
    assert reply == b"\2\0"


def test_switches_on_an_axis(sim: Hm2Sim, client: Client) -> None:
    sim.add_switch(0, stepgen=1, at=100)                    # home, NO
    sim.add_switch(1, stepgen=1, at=-50, above=False, on_level=False)
    rate = round(1000 * 2**32 / 100e6)
    client.ask(lbp16.encode([lbp16.write(0, 0x2004, [rate])]), QUIET)
    sim.step(0.05)                                          # 50 steps
    assert not sim.pin(0) and sim.pin(1)
    sim.step(0.06)                                          # 110 steps
    assert sim.pin(0) and sim.pin(1)
    (port0,) = struct.unpack("<I", client.ask(lbp16.encode(
        [lbp16.read(0, 0x1000)])))
    assert port0 & 3 == 3
    client.ask(lbp16.encode([lbp16.write(0, 0x2004, [-rate & 0xFFFFFFFF])]),
               QUIET)
    sim.step(0.2)                                           # -90 steps
    assert not sim.pin(0) and not sim.pin(1)                # limit: NC open
    with pytest.raises(IndexError, match="stepgen 7"):
        sim.add_switch(0, 7, 1.0)
