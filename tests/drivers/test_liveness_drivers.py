"""Drivers go to their safe state and end when the HAL host dies.

``halrun -f x.hal`` starts the driver with ``loadusr``, as a user's HAL
file does; halrun is SIGKILLed; the driver must end within a bound, say
why on stderr, and leave its device safe: mb2hal writes its coils OFF and
writes nothing more, the MQTT bridge publishes "offline".
"""

from __future__ import annotations

import importlib.util
import queue
import time
from collections.abc import Iterator
from pathlib import Path

import paho.mqtt.client as mqtt
import pytest
from helpers import REPO
from helpers.liveness import BOUND, Hosts, hosts_fixture, tag, wait_ended
from helpers.polling import wait_for
from helpers.tools import unavailable
from paho.mqtt.enums import CallbackAPIVersion

from halsdk.drivers.mqtt.broker import Mosquitto, find_mosquitto

_spec = importlib.util.spec_from_file_location(
    "mb2hal_simulator_live", REPO / "examples" / "modbus" / "simulator.py")
assert _spec is not None and _spec.loader is not None
sim = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sim)


@pytest.fixture
def hosts(tmp_path: Path) -> Iterator[Hosts]:
    yield from hosts_fixture(tmp_path)


# ------------------------------------------------------------ mb2hal


@pytest.fixture
def server():
    srv = sim.ServerThread(context=sim.make_context()).start()
    try:
        yield srv
    finally:
        srv.stop()


def coils(port: int, first: int, n: int) -> list[bool]:
    from pymodbus.client import ModbusTcpClient
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=3, retries=3)
    assert c.connect()
    try:
        return list(c.read_coils(first, count=n, device_id=1).bits[:n])
    finally:
        c.close()


def set_coils(port: int, first: int, values: list[bool]) -> None:
    from pymodbus.client import ModbusTcpClient
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=3, retries=3)
    assert c.connect()
    try:
        c.write_coils(first, values, device_id=1)
    finally:
        c.close()


def test_mb2hal_writes_coils_off_and_ends_when_host_is_sigkilled(
        tmp_path, hosts, server):
    head = (f"LINK_TYPE=tcp\nTCP_IP=127.0.0.1\nTCP_PORT={server.port}\n"
            "MB_SLAVE_ID=1\nMAX_UPDATE_RATE=50\nMB_RESPONSE_TIMEOUT_MS=300\n"
            "DEBUG=0\n")
    (tmp_path / "plc.ini").write_text(
        "[MB2HAL_INIT]\nHAL_MODULE_NAME=plc\nINIT_DEBUG=0\nVERSION=1.1\n"
        "TOTAL_TRANSACTIONS=2\n"
        f"[TRANSACTION_00]\n{head}MB_TX_CODE=fnct_05_write_single_coil\n"
        "FIRST_ELEMENT=30\nNELEMENTS=1\nHAL_TX_NAME=c5\n"
        "[TRANSACTION_01]\nMB_TX_CODE=fnct_15_write_multiple_coils\n"
        "FIRST_ELEMENT=50\nNELEMENTS=3\nHAL_TX_NAME=c15\n")
    host = hosts.make("mb", "loadusr -Wn plc mb2hal config=plc.ini\n"
                      "setp plc.c5.00.bit 1\nsetp plc.c15.00.bit 1\n"
                      "setp plc.c15.02.bit 1\n")
    port = server.port
    assert wait_for(lambda: coils(port, 30, 1) == [True]
                    and coils(port, 50, 3) == [True, False, True], 20), \
        host.stderr()
    pid = host.comp_pid("plc")
    hosts.pids.append(pid)
    host_pid = host.proc.pid
    host.kill()
    assert wait_ended(pid, 10) < BOUND
    assert coils(port, 30, 1) == [False]
    assert coils(port, 50, 3) == [False, False, False]
    # and nothing writes them any more
    set_coils(port, 30, [True])
    time.sleep(0.3)
    assert coils(port, 30, 1) == [True]
    text = host.stderr()
    assert (f"mb2hal: HAL instance '{tag('mb')}': its host (pid {host_pid})"
            " is gone; ending") in text, text
    assert "Traceback" not in text


# ------------------------------------------------------------ MQTT


@pytest.fixture
def broker(tmp_path: Path) -> Iterator[Mosquitto]:
    try:
        find_mosquitto()
    except RuntimeError as exc:
        unavailable(f"{exc} (apt-get install mosquitto)")
    b = Mosquitto(str(tmp_path))
    b.start()
    try:
        yield b
    finally:
        b.stop()


class Status:
    """The messages of one topic, as a paho client receives them."""

    def __init__(self, port: int, topic: str):
        self.messages: queue.Queue[str] = queue.Queue()
        self.client = mqtt.Client(CallbackAPIVersion.VERSION2)
        self.client.on_message = lambda c, u, m: self.messages.put(
            m.payload.decode())
        self.client.connect("127.0.0.1", port, 30)
        self.client.subscribe(topic, 1)
        self.client.loop_start()

    def wait(self, payload: str, timeout: float = 10.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                if self.messages.get(timeout=0.05) == payload:
                    return True
            except queue.Empty:
                pass
        return False

    def close(self) -> None:
        self.client.disconnect()
        self.client.loop_stop()


def test_mqtt_bridge_publishes_offline_and_ends_when_host_is_sigkilled(
        tmp_path, hosts, broker):
    status = Status(broker.port, "cell/status")
    try:
        host = hosts.make("mq", f"loadusr -Wn cell mqtt-bridge -n cell "
                          f"--mqtt-port={broker.port} --prefix=cell "
                          "--subscribe=feed:float\n")
        assert status.wait("online", 20), host.stderr()
        pid = host.comp_pid("cell")
        hosts.pids.append(pid)
        host_pid = host.proc.pid
        host.kill()
        assert status.wait("offline", 10), host.stderr()
        assert wait_ended(pid, 10) < 2 * BOUND      # disconnects first
    finally:
        status.close()
    text = host.stderr()
    assert (f"HAL instance '{tag('mq')}': its host (pid {host_pid}) is "
            "gone; ending") in text, text
    assert "Traceback" not in text
