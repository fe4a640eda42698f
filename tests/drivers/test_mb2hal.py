"""mb2hal against a pymodbus server on loopback (TCP) and over a
pseudo-terminal pair (RTU)."""

from __future__ import annotations

import importlib.util
import logging
import os
import pty
import select
import socket
import subprocess
import sys
import threading
import time
import tty

import pytest
from helpers import REPO
from helpers.fixtures import factory
from helpers.polling import wait_for

from halsdk.drivers.mb2hal import ConfigError, Mb2hal, load_config
from halsdk.drivers.mb2hal.client import ModbusLink

ROOT = REPO
_spec = importlib.util.spec_from_file_location(
    "mb2hal_simulator", ROOT / "examples" / "modbus" / "simulator.py")
sim = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sim)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def client(port):
    from pymodbus.client import ModbusTcpClient
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=3, retries=3)
    assert c.connect()
    return c


INIT = "[MB2HAL_INIT]\nINIT_DEBUG=0\nVERSION=1.1\nTOTAL_TRANSACTIONS={n}\n"


def tcp_head(port, rate=50.0, timeout=300, debug=0):
    return (f"LINK_TYPE=tcp\nTCP_IP=127.0.0.1\nTCP_PORT={port}\n"
            f"MB_SLAVE_ID=1\nMAX_UPDATE_RATE={rate}\n"
            f"MB_RESPONSE_TIMEOUT_MS={timeout}\nDEBUG={debug}\n")


def write_ini(tmp_path, sections, init=INIT, name="t.ini"):
    text = init.format(n=len(sections))
    for i, body in enumerate(sections):
        text += f"[TRANSACTION_{i:02d}]\n{body}"
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.fixture
def server():
    srv = sim.ServerThread(context=sim.make_context(
        inputs=[7, 65535, 9], discrete=[True, False, True])).start()
    try:
        yield srv
    finally:
        srv.stop()


@pytest.fixture
def engine_of(hal):
    def start(path, **kw):
        eng = Mb2hal(load_config(path), **kw)
        eng.start()
        return eng
    with factory(start, Mb2hal.stop) as make:
        yield make


def test_all_eight_function_codes_both_ways(tmp_path, hal, server,
                                            engine_of):
    head = tcp_head(server.port)
    ini = write_ini(tmp_path, [
        head + "MB_TX_CODE=fnct_01_read_coils\nFIRST_ELEMENT=10\n"
        "NELEMENTS=3\nHAL_TX_NAME=coils\n",
        "MB_TX_CODE=fnct_02_read_discrete_inputs\nFIRST_ELEMENT=0\n"
        "PIN_NAMES=start,stop,hold\nHAL_TX_NAME=di\n",
        "MB_TX_CODE=fnct_03_read_holding_registers\nFIRST_ELEMENT=20\n"
        "NELEMENTS=2\n",
        "MB_TX_CODE=fnct_04_read_input_registers\nFIRST_ELEMENT=0\n"
        "NELEMENTS=3\nHAL_TX_NAME=ir\n",
        "MB_TX_CODE=fnct_05_write_single_coil\nFIRST_ELEMENT=30\n"
        "NELEMENTS=1\nHAL_TX_NAME=c5\n",
        "MB_TX_CODE=fnct_06_write_single_register\nFIRST_ELEMENT=40\n"
        "PIN_NAMES=speed\nHAL_TX_NAME=r6\n",
        "MB_TX_CODE=fnct_15_write_multiple_coils\nFIRST_ELEMENT=50\n"
        "NELEMENTS=3\nHAL_TX_NAME=c15\n",
        "MB_TX_CODE=fnct_16_write_multiple_registers\nFIRST_ELEMENT=60\n"
        "NELEMENTS=2\nHAL_TX_NAME=r16\n",
    ])
    c = client(server.port)
    try:
        c.write_coils(10, [True, False, True], device_id=1)
        c.write_registers(20, [1234, 65000], device_id=1)
        eng = engine_of(ini)
        hal.setp("mb2hal.c5.00.bit", True)
        hal.setp("mb2hal.r6.speed.float", 1000.7)
        hal.setp("mb2hal.r6.speed.int", 5)
        hal.setp("mb2hal.c15.01.bit", True)
        hal.setp("mb2hal.c15.02.bit", True)
        hal.setp("mb2hal.r16.00.int", 70000)      # clamped to 65535
        hal.setp("mb2hal.r16.01.float", -5.0)     # clamped to 0
        assert wait_for(lambda: hal.getp("mb2hal.ir.02.int") == 9
                        and hal.getp("mb2hal.02.01.int") == 65000)
        assert [hal.getp(f"mb2hal.coils.{i:02d}.bit") for i in range(3)] \
            == [True, False, True]
        assert hal.getp("mb2hal.coils.01.bit-inv") is True
        assert [hal.getp(f"mb2hal.di.{n}.bit") for n in
                ("start", "stop", "hold")] == [True, False, True]
        assert hal.getp("mb2hal.02.00.float") == 1234.0
        assert hal.getp("mb2hal.ir.01.float") == 65535.0

        def written():
            return (c.read_coils(30, count=1, device_id=1).bits[0]
                    and c.read_holding_registers(40, count=1, device_id=1)
                    .registers == [1005]
                    and c.read_coils(50, count=3, device_id=1).bits[:3]
                    == [False, True, True]
                    and c.read_holding_registers(60, count=2, device_id=1)
                    .registers == [65535, 0])
        assert wait_for(written)
        # a change of a HAL pin reaches the device, a device change HAL
        hal.setp("mb2hal.c5.00.bit", False)
        c.write_registers(21, [42], device_id=1)
        assert wait_for(lambda: not c.read_coils(30, count=1, device_id=1)
                        .bits[0] and hal.getp("mb2hal.02.01.int") == 42)
        assert all(hal.getp(f"mb2hal.{n}.num_errors") == 0 for n in
                   ("coils", "di", "02", "ir", "c5", "r6", "c15", "r16"))
        assert eng.transactions_done > 8
    finally:
        c.close()


def test_exception_response_counts_and_others_continue(tmp_path, hal,
                                                       server, engine_of):
    ini = write_ini(tmp_path, [
        tcp_head(server.port) + "MB_TX_CODE=fnct_03_read_holding_registers"
        "\nFIRST_ELEMENT=500\nNELEMENTS=2\nHAL_TX_NAME=bad\n",
        "MB_TX_CODE=fnct_03_read_holding_registers\nFIRST_ELEMENT=0\n"
        "NELEMENTS=1\nHAL_TX_NAME=good\n"])
    engine_of(ini)
    c = client(server.port)
    try:
        c.write_registers(0, [77], device_id=1)
        assert wait_for(lambda: hal.getp("mb2hal.bad.num_errors") >= 3
                        and hal.getp("mb2hal.good.00.int") == 77)
        c.write_registers(0, [78], device_id=1)
        assert wait_for(lambda: hal.getp("mb2hal.good.00.int") == 78)
        assert hal.getp("mb2hal.good.num_errors") == 0
    finally:
        c.close()


@pytest.fixture
def silent_server():
    """Accepts connections and reads requests but never answers."""
    lsock = socket.socket()
    lsock.bind(("127.0.0.1", 0))
    lsock.listen(8)
    stop = threading.Event()
    conns = []

    def serve():
        while not stop.is_set():
            ready, _, _ = select.select([lsock, *conns], [], [], 0.05)
            for s in ready:
                if s is lsock:
                    conns.append(lsock.accept()[0])
                elif not s.recv(256):
                    conns.remove(s)
                    s.close()
    t = threading.Thread(target=serve, daemon=True)
    t.start()
    try:
        yield lsock.getsockname()[1]
    finally:
        stop.set()
        t.join(5)
        for s in conns:
            s.close()
        lsock.close()


def test_timeout_is_counted_and_other_link_continues(tmp_path, hal, server,
                                                     silent_server,
                                                     engine_of):
    ini = write_ini(tmp_path, [
        tcp_head(silent_server, timeout=80) + "MB_TX_CODE="
        "fnct_04_read_input_registers\nFIRST_ELEMENT=0\nNELEMENTS=1\n"
        "HAL_TX_NAME=mute\n",
        tcp_head(server.port) + "MB_TX_CODE=fnct_03_read_holding_registers"
        "\nFIRST_ELEMENT=5\nNELEMENTS=1\nHAL_TX_NAME=live\n"])
    eng = engine_of(ini, backoff=0.02, backoff_max=0.05)
    c = client(server.port)
    try:
        for value in (5, 6, 7):
            c.write_registers(5, [value], device_id=1)
            assert wait_for(lambda v=value: hal.getp("mb2hal.live.00.int")
                            == v)
        assert wait_for(lambda: hal.getp("mb2hal.mute.num_errors") >= 3)
        assert hal.getp("mb2hal.live.num_errors") == 0
    finally:
        c.close()
    t0 = time.monotonic()
    eng.stop()                      # not blocked by the silent device
    assert time.monotonic() - t0 < 3.0


def messages(caplog, text):
    return [r.getMessage() for r in caplog.records
            if r.name == "halsdk.mb2hal" and text in r.getMessage()]


def test_server_restart_errors_then_recovery(tmp_path, hal, engine_of,
                                             caplog):
    caplog.set_level(logging.INFO, logger="halsdk.mb2hal")
    port = free_port()
    srv = sim.ServerThread(port=port).start()
    ini = write_ini(tmp_path, [tcp_head(port, timeout=200, debug=1) +
                               "MB_TX_CODE=fnct_03_read_holding_registers\n"
                               "FIRST_ELEMENT=3\nNELEMENTS=1\n"])
    engine_of(ini, backoff=0.02, backoff_max=0.1)
    try:
        c = client(port)
        c.write_registers(3, [11], device_id=1)
        c.close()
        assert wait_for(lambda: hal.getp("mb2hal.00.00.int") == 11)
        assert hal.getp("mb2hal.00.num_errors") == 0
        srv.stop()
        assert wait_for(lambda: hal.getp("mb2hal.00.num_errors") >= 2)
        assert not messages(caplog, "connected again")
        srv = sim.ServerThread(port=port).start()
        c = client(port)
        c.write_registers(3, [12], device_id=1)
        c.close()
        assert wait_for(lambda: hal.getp("mb2hal.00.00.int") == 12)
        errors = hal.getp("mb2hal.00.num_errors")
        time.sleep(0.1)
        assert hal.getp("mb2hal.00.num_errors") == errors   # healthy again
        assert len(messages(caplog, "connected again")) == 1
    finally:
        srv.stop()


@pytest.fixture
def closing_server():
    """Accepts every connection and closes it at once."""
    lsock = socket.socket()
    lsock.bind(("127.0.0.1", 0))
    lsock.listen(8)
    lsock.settimeout(0.05)
    stop = threading.Event()

    def serve():
        while not stop.is_set():
            try:
                lsock.accept()[0].close()
            except OSError:
                pass
    t = threading.Thread(target=serve, daemon=True)
    t.start()
    try:
        yield lsock.getsockname()[1]
    finally:
        stop.set()
        t.join(5)
        lsock.close()


@pytest.mark.parametrize("kind", ["closing", "silent"])
def test_accepting_but_broken_server_is_logged_once(
        tmp_path, hal, engine_of, caplog, closing_server, silent_server,
        kind):
    caplog.set_level(logging.INFO, logger="halsdk.mb2hal")
    port = closing_server if kind == "closing" else silent_server
    ini = write_ini(tmp_path, [
        tcp_head(port, rate=0.0, timeout=30, debug=1) + "MB_TX_CODE="
        "fnct_03_read_holding_registers\nFIRST_ELEMENT=0\nNELEMENTS=1\n"])
    eng = engine_of(ini, backoff=0.005, backoff_max=0.01)
    assert wait_for(lambda: hal.getp("mb2hal.00.num_errors") >= 20)
    logged = [r.getMessage() for r in caplog.records
              if r.name == "halsdk.mb2hal"]
    # a TCP connect alone is no recovery; each distinct problem once
    assert not messages(caplog, "connected")
    assert 1 <= len(logged) <= 6, logged
    assert not [m for m in logged if "Modbus" in m or "seconds" in m]
    assert eng.transactions_done == 0


def test_unexpected_error_in_transaction_keeps_link_alive(
        tmp_path, hal, server, engine_of, caplog, monkeypatch):
    real = ModbusLink.execute
    broken = threading.Event()
    broken.set()

    def execute(self, tx, values=None):
        if broken.is_set():
            raise RuntimeError("boom")
        return real(self, tx, values)
    monkeypatch.setattr(ModbusLink, "execute", execute)
    ini = write_ini(tmp_path, [tcp_head(server.port, debug=1) + "MB_TX_CODE="
                               "fnct_04_read_input_registers\n"
                               "FIRST_ELEMENT=0\nNELEMENTS=1\n"])
    eng = engine_of(ini, backoff=0.005, backoff_max=0.01)
    assert wait_for(lambda: hal.getp("mb2hal.00.num_errors") >= 5)
    assert eng.workers[0].thread.is_alive()
    assert len(messages(caplog, "RuntimeError: boom")) == 1
    assert len(messages(caplog, "")) == 1
    broken.clear()
    assert wait_for(lambda: hal.getp("mb2hal.00.00.int") == 7)
    errors = hal.getp("mb2hal.00.num_errors")
    time.sleep(0.05)
    assert hal.getp("mb2hal.00.num_errors") == errors


def test_unexpected_error_between_transactions_is_counted_once_logged(
        tmp_path, hal, server, caplog):
    ini = write_ini(tmp_path, [tcp_head(server.port, debug=1) + "MB_TX_CODE="
                               "fnct_04_read_input_registers\n"
                               "FIRST_ELEMENT=0\nNELEMENTS=1\n"])
    config = load_config(ini)
    config.slowdown = 1e300         # what the config check now refuses
    eng = Mb2hal(config, backoff=0.005, backoff_max=0.01)
    eng.start()
    try:
        assert wait_for(lambda: hal.getp("mb2hal.00.num_errors") >= 5)
        assert eng.workers[0].thread.is_alive()
        assert hal.getp("mb2hal.00.00.int") == 7
        assert len(messages(caplog, "OverflowError")) == 1
        assert len(messages(caplog, "")) == 1       # nothing else
    finally:
        eng.stop()


def test_no_device_counts_on_every_transaction_of_the_link(tmp_path, hal,
                                                          engine_of):
    ini = write_ini(tmp_path, [
        tcp_head(free_port(), rate=0.0) + "MB_TX_CODE="
        "fnct_03_read_holding_registers\nFIRST_ELEMENT=0\nNELEMENTS=1\n",
        "MB_TX_CODE=fnct_16_write_multiple_registers\nFIRST_ELEMENT=0\n"
        "NELEMENTS=1\n"])
    eng = engine_of(ini, backoff=0.01, backoff_max=0.02)
    assert wait_for(lambda: hal.getp("mb2hal.00.num_errors") >= 3
                    and hal.getp("mb2hal.01.num_errors") >= 3)
    assert eng.transactions_done == 0


def test_version_1_0_pin_names(tmp_path, hal, engine_of):
    ini = write_ini(tmp_path, [
        tcp_head(free_port()) + "MB_TX_CODE=fnct_02_read_discrete_inputs\n"
        "FIRST_ELEMENT=0\nNELEMENTS=1\n",
        "MB_TX_CODE=fnct_16_write_multiple_registers\nFIRST_ELEMENT=0\n"
        "PIN_NAMES=a\nHAL_TX_NAME=wr\n",
        "MB_TX_CODE=fnct_03_read_holding_registers\nFIRST_ELEMENT=0\n"
        "NELEMENTS=1\n",
        "MB_TX_CODE=fnct_15_write_multiple_coils\nFIRST_ELEMENT=0\n"
        "NELEMENTS=1\n"], init=INIT.replace("VERSION=1.1\n", ""))
    engine_of(ini, name="plc")
    names = {(p.name, p.type, p.direction) for p in hal.pins("plc.*")}
    got = sorted(n for n, _, _ in names)
    assert got == ["plc.00.00", "plc.00.num_errors", "plc.02.00.float",
                   "plc.02.00.int", "plc.02.num_errors", "plc.03.00",
                   "plc.03.num_errors", "plc.wr.a", "plc.wr.num_errors"]


TX = ("[TRANSACTION_00]\nLINK_TYPE=tcp\nTCP_IP=h\nMB_SLAVE_ID=1\n"
      "FIRST_ELEMENT=0\nNELEMENTS=1\n"
      "MB_TX_CODE=fnct_03_read_holding_registers\n")
#: what LinuxCNC's mb2hal refuses too: (body after [MB2HAL_INIT], key,
#: line of the key counted from the line after the header, text)
BAD = [
    ("", "[MB2HAL_INIT]", None, "TOTAL_TRANSACTIONS is required"),
    ("TOTAL_TRANSACTIONS=x\n", "TOTAL_TRANSACTIONS", 1, "not an integer"),
    ("TOTAL_TRANSACTIONS=0\n", "TOTAL_TRANSACTIONS", 1, "out of range"),
    ("TOTAL_TRANSACTIONS=2\n" + TX, "TOTAL_TRANSACTIONS", 1,
     "[TRANSACTION_01] is missing"),
    ("TOTAL_TRANSACTIONS=1\n[transaction_00]\n", "TOTAL_TRANSACTIONS", 1,
     "section names are case sensitive"),
    ("TOTAL_TRANSACTIONS=1\n[TRANSACTION_00]\nLINK_TYPE=udp\n", "LINK_TYPE",
     3, "'udp' is not one of tcp, serial"),
    ("TOTAL_TRANSACTIONS=1\n" + TX.replace("fnct_03_read_holding_registers",
                                           "fnct_99_x"),
     "MB_TX_CODE", 8, "'fnct_99_x' is not one of"),
    ("TOTAL_TRANSACTIONS=1\n" + TX.replace("fnct_03_read_holding_registers",
                                           "fnct_03"),
     "MB_TX_CODE", 8, "'fnct_03' is not one of"),
    ("TOTAL_TRANSACTIONS=1\n[TRANSACTION_00]\nLINK_TYPE=serial\n"
     "SERIAL_PORT=/dev/x\nSERIAL_BAUD=9600\nSERIAL_BITS=9\n", "SERIAL_BITS",
     6, "out of range 5..8"),
    ("TOTAL_TRANSACTIONS=1\n[TRANSACTION_00]\nLINK_TYPE=serial\n"
     "SERIAL_PORT=/dev/x\nSERIAL_BAUD=9600\nSERIAL_BITS=8\n"
     "SERIAL_PARITY=mark\n", "SERIAL_PARITY", 7, "'mark' is not one of"),
    ("TOTAL_TRANSACTIONS=1\n" + TX + "HAL_TX_NAME=" + "n" * 29 + "\n",
     "HAL_TX_NAME", 9, "longer than 28"),
    ("TOTAL_TRANSACTIONS=1\n" + TX + "HAL_TX_NAME=a b\n", "HAL_TX_NAME", 9,
     "a name with spaces"),
    ("TOTAL_TRANSACTIONS=1\n" + TX.replace("NELEMENTS=1", "NELEMENTS=0"),
     "NELEMENTS", 7, "out of range"),
    ("TOTAL_TRANSACTIONS=1\n" + TX.replace("NELEMENTS=1", "PIN_NAMES=a,a"),
     "PIN_NAMES", 7, "a name is repeated"),
    ("TOTAL_TRANSACTIONS=1\n" + TX.replace("FIRST_ELEMENT=0",
                                           "FIRST_ELEMENT=-1"),
     "FIRST_ELEMENT", 6, "out of range"),
    ("TOTAL_TRANSACTIONS=1\n" + TX.replace("NELEMENTS=1",
                                           "NELEMENTS=2 # two"),
     "[TRANSACTION_00]", 2, "NELEMENTS (or PIN_NAMES) is required"),
    ("TOTAL_TRANSACTIONS=1\n" + TX.replace("MB_SLAVE_ID=1",
                                           "mb_slave_id=1"),
     "[TRANSACTION_00]", 2, "MB_SLAVE_ID is required"),
]


@pytest.mark.parametrize("body,key,line,text", BAD)
def test_bad_ini_names_file_line_and_key(tmp_path, body, key, line, text):
    path = tmp_path / "bad.ini"
    path.write_text("[MB2HAL_INIT]\n" + body)
    with pytest.raises(ConfigError) as err:
        load_config(str(path))
    msg = str(err.value)
    assert msg.startswith(f"{path}:{line + 1}: " if line else f"{path}:1: ")
    assert key in msg and text in msg


def test_error_comes_with_the_warnings_that_explain_it(tmp_path):
    path = tmp_path / "bad.ini"
    path.write_text("[MB2HAL_INIT]\nTOTAL_TRANSACTIONS=1\n" +
                    TX.replace("MB_SLAVE_ID=1", "mb_slave_id=1"))
    with pytest.raises(ConfigError) as err:
        load_config(str(path))
    assert err.value.warnings == [
        f"{path}:6: [TRANSACTION_00]mb_slave_id: unknown key, ignored "
        "(keys are case sensitive: MB_SLAVE_ID?)"]


OK_HEAD = "[MB2HAL_INIT]\nTOTAL_TRANSACTIONS=1\n"
#: what LinuxCNC's mb2hal runs but looks like a mistake: accepted with a
#: warning, refused with strict. (text after OK_HEAD, file line, key and
#: text of the warning, a check of what is used)
SUSPICIOUS = [
    (TX + "MB_SLAVEID=3\n", 10, "[TRANSACTION_00]MB_SLAVEID",
     "unknown key, ignored (did you mean MB_SLAVE_ID?)", None),
    (TX + "DATA_TYPE=float\n", 10, "[TRANSACTION_00]DATA_TYPE",
     "unknown key, ignored", None),
    (TX.replace("NELEMENTS=1", "NELEMENTS=1\nNELEMENTS=3"), 9,
     "[TRANSACTION_00]NELEMENTS", "is given again (first at line 8)",
     lambda c: c.transactions[0].count == 1),
    (TX + TX.replace("FIRST_ELEMENT=0", "FIRST_ELEMENT=7") +
     "HAL_TX_NAME=x\n", 10, "[TRANSACTION_00]",
     "is given again (first at line 3), ignored: only the first copy",
     lambda c: (c.transactions[0].first_element, c.transactions[0].name)
     == (0, "00")),
    (TX + "[MB2HAL_INIT]\nSLOWDOWN=1\n", 10, "[MB2HAL_INIT]",
     "is given again (first at line 1)", lambda c: c.slowdown == 0.0),
    (TX + "[TRANSACTION_01]\n" + TX[17:], 10, "[TRANSACTION_01]",
     "section not read: TOTAL_TRANSACTIONS=1",
     lambda c: len(c.transactions) == 1),
    ("VERSION=2.0\n" + TX, 3, "[MB2HAL_INIT]VERSION",
     "'2.0' is not 1.0 or 1.1, read as 2.0 (1.1 used)",
     lambda c: c.version == 1001),
    ("VERSION=1\n" + TX, 3, "[MB2HAL_INIT]VERSION",
     "'1' is not a version N.N, 1.0 used", lambda c: c.version == 1000),
    ("INIT_DEBUG=9\n" + TX, 3, "[MB2HAL_INIT]INIT_DEBUG",
     "9 is out of range 0..4, 4 used", lambda c: c.init_debug == 4),
    ("SLOWDOWN=1e300\n" + TX, 3, "[MB2HAL_INIT]SLOWDOWN",
     "1e+300 s is more than 60 s, 60 used", lambda c: c.slowdown == 60.0),
    ("SLOWDOWN=nan\n" + TX, 3, "[MB2HAL_INIT]SLOWDOWN",
     "'nan' is not a number, ignored", lambda c: c.slowdown == 0.0),
    ("SLOWDOWN=-1\n" + TX, 3, "[MB2HAL_INIT]SLOWDOWN",
     "-1 is negative, 0 used", lambda c: c.slowdown == 0.0),
    (TX + "MAX_UPDATE_RATE=inf\n", 10, "MAX_UPDATE_RATE",
     "'inf' is not a number, ignored",
     lambda c: c.transactions[0].max_update_rate == 0.0),
    (TX + "MAX_UPDATE_RATE=1e-9\n", 10, "MAX_UPDATE_RATE",
     "1e-09 Hz is outside 1/3600",
     lambda c: c.transactions[0].max_update_rate == 1e-9),
    (TX + "MAX_UPDATE_RATE=10 # Hz\n", 10, "MAX_UPDATE_RATE",
     "'10 # Hz' is not a number, ignored",
     lambda c: c.transactions[0].max_update_rate == 0.0),
    (TX + "MB_RESPONSE_TIMEOUT_MS=60001\n", 10, "MB_RESPONSE_TIMEOUT_MS",
     "60001 is out of range 1..60000, 60000 used",
     lambda c: c.transactions[0].response_timeout_ms == 60000),
    (TX + "MB_RESPONSE_TIMEOUT_MS=0\n", 10, "MB_RESPONSE_TIMEOUT_MS",
     "0 is out of range 1..60000, 500 used",
     lambda c: c.transactions[0].response_timeout_ms == 500),
    (TX + "MB_BYTE_TIMEOUT_MS=abc\n", 10, "MB_BYTE_TIMEOUT_MS",
     "'abc' is not an integer, ignored",
     lambda c: c.transactions[0].byte_timeout_ms == 500),
    (TX + "DEBUG=-1\n", 10, "[TRANSACTION_00]DEBUG",
     "-1 is out of range 0..4, 0 used",
     lambda c: c.transactions[0].debug == 0),
    (TX + "HAL_TX_NAME=\n", 10, "HAL_TX_NAME", "empty value, ignored",
     lambda c: c.transactions[0].name == "00"),
    (TX.replace("NELEMENTS=1", "NELEMENTS=2\nPIN_NAMES=a,b"), 9,
     "PIN_NAMES", "NELEMENTS is given too",
     lambda c: c.transactions[0].pin_names == ["a", "b"]),
    (TX.replace("NELEMENTS=1", "NELEMENTS=3\nPIN_NAMES=a,b"), 9,
     "PIN_NAMES", "the elements without a name are numbered",
     lambda c: c.transactions[0].pin_names == ["a", "b", "02"]),
    (TX.replace("NELEMENTS=1", "PIN_NAMES=a,,b,"), 8, "PIN_NAMES",
     "empty names are skipped",
     lambda c: c.transactions[0].pin_names == ["a", "b"]),
    (TX.replace("NELEMENTS=1", "PIN_NAMES=a, b"), 8, "PIN_NAMES",
     "spaces around the names are removed",
     lambda c: c.transactions[0].pin_names == ["a", "b"]),
    (TX.replace("NELEMENTS=1\nMB_TX_CODE=fnct_03_read_holding_registers",
                "NELEMENTS=3\nMB_TX_CODE=fnct_06_write_single_register"), 8,
     "[TRANSACTION_00]NELEMENTS", "fnct_06_write_single_register sends at "
     "most 1 element(s), not 3: nothing is sent",
     lambda c: c.transactions[0].unusable != ""),
    (TX.replace("NELEMENTS=1", "NELEMENTS=126"), 8, "NELEMENTS",
     "at most 125 element(s), not 126",
     lambda c: c.transactions[0].unusable != ""),
    (TX.replace("MB_SLAVE_ID=1", "MB_SLAVE_ID=256"), 6, "MB_SLAVE_ID",
     "256 is not a device id (0..247 or 255)",
     lambda c: c.transactions[0].unusable != ""),
    (TX.replace("FIRST_ELEMENT=0", "FIRST_ELEMENT=65537"), 7,
     "FIRST_ELEMENT", "address 1 is sent",
     lambda c: c.transactions[0].first_element == 1),
    (TX.replace("TCP_IP=h", "TCP_IP=h\nTCP_PORT=70000"), 6, "TCP_PORT",
     "70000 is out of range 1..65535: the link cannot connect", None),
    (TX.replace("LINK_TYPE=tcp\nTCP_IP=h", "LINK_TYPE=serial\n"
                "SERIAL_PORT=/dev/x\nSERIAL_BAUD=9600\nSERIAL_BITS=8\n"
                "SERIAL_PARITY=none\nSERIAL_STOP=1") +
     TX.replace("_00", "_01").replace("LINK_TYPE=tcp\nTCP_IP=h",
                                      "LINK_TYPE=serial\nSERIAL_BAUD=19200"),
     15, "[TRANSACTION_01]LINK_TYPE", "serial port /dev/x is already "
     "configured as serial /dev/x 9600 8N1: those settings are used",
     lambda c: len(c.links) == 1),
]


@pytest.mark.parametrize("body,line,key,text,check", SUSPICIOUS)
def test_suspicious_is_a_warning_and_refused_when_strict(
        tmp_path, body, line, key, text, check):
    path = tmp_path / "odd.ini"
    total = 2 if "SERIAL_BAUD=19200" in body else 1
    path.write_text(OK_HEAD.replace("=1", f"={total}") + body)
    cfg = load_config(str(path))
    first = cfg.warnings[0]
    assert first.startswith(f"{path}:{line}: "), cfg.warnings
    assert key in first and text in first, first
    if check is not None:
        assert check(cfg)
    with pytest.raises(ConfigError) as err:
        load_config(str(path), strict=True)
    lines = str(err.value).splitlines()
    assert lines == [w + " (refused by --strict)" for w in cfg.warnings]


@pytest.mark.parametrize("body", [
    TX.replace("LINK_TYPE=tcp", "LINK_TYPE=TCP").replace(
        "fnct_03_read_holding_registers", "FNCT_03_READ_HOLDING_REGISTERS"),
    TX.replace("MB_SLAVE_ID=1", "MB_SLAVE_ID = 1").replace(
        "NELEMENTS=1", "\tNELEMENTS\t=\t1   ").replace("\n", "\r\n"),
    TX.replace("NELEMENTS=1", "; a comment\n# another\nNELEMENTS=1"),
    TX + "SERIAL_PORT=/dev/ttyS0\nSERIAL_BAUD=x\n[OTHER]\nANY=1\nANY=2\n",
    TX + "MB_BYTE_TIMEOUT_MS=0\nHAL_TX_NAME=plc-in.a_B\n"
    "[TRANSACTION_01]\nLINK_TYPE=tcp\nMB_TX_CODE=fnct_04_read_input_registers"
    "\nFIRST_ELEMENT=1\nNELEMENTS=1\n",
    TX.replace("MB_SLAVE_ID=1", "MB_SLAVE_ID=255"),
])
def test_what_the_reference_reads_silently_gives_no_warning(tmp_path,
                                                           body):
    path = tmp_path / "ok.ini"
    total = 2 if "TRANSACTION_01" in body else 1
    path.write_text(OK_HEAD.replace("=1", f"={total}") + body)
    cfg = load_config(str(path), strict=True)
    assert cfg.warnings == []
    tx = cfg.transactions
    assert tx[0].function == 3 and tx[0].slave_id in (1, 255)
    assert tx[-1].link == tx[0].link


def test_every_key_of_the_reference_example_is_known(tmp_path):
    """The reference's example file sets serial keys in a tcp transaction
    and every optional key; all of them must be accepted."""
    path = tmp_path / "full.ini"
    path.write_text(
        "# comment\n[MB2HAL_INIT]\nINIT_DEBUG=3\nVERSION=1.1\n"
        "HAL_MODULE_NAME=mb2hal\nSLOWDOWN=0.0\nTOTAL_TRANSACTIONS=2\n"
        "[TRANSACTION_00]\nLINK_TYPE=tcp\nTCP_IP=10.0.0.2\nTCP_PORT=502\n"
        "SERIAL_PORT=/dev/ttyS0\nSERIAL_BAUD=19200\nSERIAL_BITS=8\n"
        "SERIAL_PARITY=none\nSERIAL_STOP=2\nSERIAL_DELAY_MS=10\n"
        "MB_SLAVE_ID=1\nFIRST_ELEMENT=0\n#NELEMENTS=4\nPIN_NAMES=a,b\n"
        "MB_TX_CODE=fnct_03_read_holding_registers\n"
        "MB_RESPONSE_TIMEOUT_MS=500\nMB_BYTE_TIMEOUT_MS=500\n"
        "HAL_TX_NAME=io\nMAX_UPDATE_RATE=0.0\nDEBUG=2\n"
        "[TRANSACTION_01]\nMB_TX_CODE=fnct_01_read_coils\n"
        "FIRST_ELEMENT=8\nNELEMENTS=3\nMAX_UPDATE_RATE=10.0\nDEBUG=1\n"
        "[OTHER]\nANYTHING=1\nANYTHING=2\n")
    cfg = load_config(str(path))
    assert [t.name for t in cfg.transactions] == ["io", "01"]
    assert cfg.transactions[0].link.describe() == "tcp 10.0.0.2:502"


def test_fnct_01_needs_version_1_1(tmp_path):
    path = write_ini(tmp_path, [tcp_head(502) + "MB_TX_CODE="
                                "fnct_01_read_coils\nFIRST_ELEMENT=0\n"
                                "NELEMENTS=1\n"],
                     init=INIT.replace("VERSION=1.1\n", ""))
    with pytest.raises(ConfigError, match=r"t\.ini:12: .*VERSION=1\.1"):
        load_config(path)


def test_same_link_and_optional_keys_follow_previous(tmp_path):
    cfg = load_config(write_ini(tmp_path, [
        tcp_head(1502, rate=5.0, timeout=120) + "MB_TX_CODE="
        "fnct_03_read_holding_registers\nFIRST_ELEMENT=0\nNELEMENTS=1\n",
        "MB_TX_CODE=fnct_04_read_input_registers\nFIRST_ELEMENT=1\n"
        "NELEMENTS=1\n",
        "LINK_TYPE=serial\nSERIAL_PORT=/dev/ttyX\nSERIAL_BAUD=9600\n"
        "SERIAL_BITS=8\nSERIAL_PARITY=even\nSERIAL_STOP=2\nMB_SLAVE_ID=3\n"
        "MB_TX_CODE=fnct_04_read_input_registers\nFIRST_ELEMENT=1\n"
        "NELEMENTS=1\n"]))
    t0, t1, t2 = cfg.transactions
    assert t1.link == t0.link and t1.slave_id == 1
    assert (t1.max_update_rate, t1.response_timeout_ms) == (5.0, 120)
    assert t1.name == "01" and t1.byte_timeout_ms == 500
    assert t2.link.describe() == "serial /dev/ttyX 9600 8E2"
    assert t2.slave_id == 3 and len(cfg.links) == 2


def _halrun(tmp_path, hal_text, timeout=30):
    (tmp_path / "m.hal").write_text(hal_text)
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "halsdk.halcmd.cli",
                           "halrun", "-f", "m.hal"], cwd=tmp_path, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=timeout)


def test_loadusr_process_reads_device(tmp_path, server, python_tools_first,
                                      monkeypatch):
    monkeypatch.setenv("HALSDK_INSTANCE", f"mb2hal-{os.getpid()}")
    c = client(server.port)
    c.write_registers(8, [4321], device_id=1)
    c.close()
    init = INIT.replace("INIT_DEBUG=0", "HAL_MODULE_NAME=plc\nINIT_DEBUG=0")
    write_ini(tmp_path, [tcp_head(server.port) + "MB_TX_CODE="
                         "fnct_03_read_holding_registers\nFIRST_ELEMENT=8\n"
                         "NELEMENTS=1\nHAL_TX_NAME=rd\n"], init=init,
              name="plc.ini")
    proc = _halrun(tmp_path, "loadusr -Wn plc mb2hal config=plc.ini\n"
                   "loadusr -w sleep 0.5\ngetp plc.rd.00.int\n"
                   "getp plc.rd.num_errors\nunloadusr plc\n")
    assert proc.stdout.splitlines()[-2:] == ["4321", "0"], proc.stdout
    assert proc.returncode == 0
    assert not [n for n in os.listdir("/dev/shm") if f"mb2hal-{os.getpid()}"
                in n]


def test_program_bad_config_exits_1_with_file_line(tmp_path):
    path = tmp_path / "bad.ini"
    path.write_text("[MB2HAL_INIT]\nTOTAL_TRANSACTIONS=0\n")
    proc = subprocess.run([sys.executable, "-m", "halsdk.drivers.mb2hal",
                           f"config={path}"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=30)
    assert proc.returncode == 1
    assert proc.stderr.strip() == (f"mb2hal: {path}:2: [MB2HAL_INIT]"
                                   "TOTAL_TRANSACTIONS: 0 is out of range "
                                   "(1 or more)")


@pytest.mark.parametrize("args,text", [
    (["file.ini"], "unknown argument 'file.ini'"),
    (["--bogus", "config=x.ini"], "unrecognized arguments: --bogus"),
    ([], "missing config=FILE.ini"),
    (["-n", "", "config=x.ini"], "-n/--name: '' is not a HAL name"),
])
def test_program_usage_error_exits_1_with_one_line(tmp_path, args, text):
    proc = subprocess.run([sys.executable, "-m", "halsdk.drivers.mb2hal",
                           *args], cwd=tmp_path, capture_output=True,
                          text=True, timeout=30)
    assert proc.returncode == 1
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("mb2hal: ")
    assert text in lines[0]


@pytest.fixture
def pty_bridge():
    """Two pseudo-terminals joined back to back: what is written on one
    slave is read on the other (a null-modem cable)."""
    a_master, a_slave = pty.openpty()
    b_master, b_slave = pty.openpty()
    for fd in (a_slave, b_slave):
        tty.setraw(fd)
    stop = threading.Event()

    def pump():
        while not stop.is_set():
            ready, _, _ = select.select([a_master, b_master], [], [], 0.05)
            for fd in ready:
                try:
                    data = os.read(fd, 512)
                except OSError:
                    continue
                os.write(b_master if fd == a_master else a_master, data)
    t = threading.Thread(target=pump, daemon=True)
    t.start()
    try:
        yield os.ttyname(a_slave), os.ttyname(b_slave)
    finally:
        stop.set()
        t.join(5)
        for fd in (a_master, a_slave, b_master, b_slave):
            os.close(fd)


def test_rtu_over_pseudo_terminals(tmp_path, hal, pty_bridge, engine_of):
    ours, device = pty_bridge
    srv = sim.ServerThread(serial=device, context=sim.make_context(
        inputs=[31, 32])).start()
    try:
        ini = write_ini(tmp_path, [
            f"LINK_TYPE=serial\nSERIAL_PORT={ours}\nSERIAL_BAUD=115200\n"
            "SERIAL_BITS=8\nSERIAL_PARITY=none\nSERIAL_STOP=1\n"
            "SERIAL_DELAY_MS=5\nMB_SLAVE_ID=1\nDEBUG=0\n"
            "MB_TX_CODE=fnct_04_read_input_registers\nFIRST_ELEMENT=0\n"
            "NELEMENTS=2\nHAL_TX_NAME=ir\nMAX_UPDATE_RATE=20\n",
            "MB_TX_CODE=fnct_06_write_single_register\nFIRST_ELEMENT=4\n"
            "NELEMENTS=1\nHAL_TX_NAME=out\n",
            "MB_TX_CODE=fnct_03_read_holding_registers\nFIRST_ELEMENT=4\n"
            "NELEMENTS=1\nHAL_TX_NAME=back\n"])
        engine_of(ini)
        hal.setp("mb2hal.out.00.int", 555)
        assert wait_for(lambda: hal.getp("mb2hal.ir.01.int") == 32
                        and hal.getp("mb2hal.back.00.int") == 555)
        assert hal.getp("mb2hal.ir.00.float") == 31.0
    finally:
        srv.stop()


SINGLE_WRITES = INIT.replace("INIT_DEBUG=0", "INIT_DEBUG=1") + (
    "[TRANSACTION_00]\n{head}MB_TX_CODE=fnct_06_write_single_register\n"
    "FIRST_ELEMENT=20\nNELEMENTS=2\nHAL_TX_NAME=w6\n"
    "[TRANSACTION_01]\nMB_TX_CODE=fnct_05_write_single_coil\n"
    "FIRST_ELEMENT=30\nPIN_NAMES=a,b\nHAL_TX_NAME=w5\n"
    "[TRANSACTION_02]\nMB_TX_CODE=fnct_06_write_single_register\n"
    "FIRST_ELEMENT=40\nNELEMENTS=1\nHAL_TX_NAME=one\n"
    "[TRANSACTION_03]\nMB_TX_CODE=fnct_03_read_holding_registers\n"
    "FIRST_ELEMENT=40\nNELEMENTS=1\nHAL_TX_NAME=back\n")


def test_halrun_single_write_of_several_elements_sends_nothing(
        tmp_path, python_tools_first, monkeypatch):
    """LinuxCNC's mb2hal runs fnct_05/06 with NELEMENTS>1 but never sends
    them: each repetition counts an error, the link goes on."""
    monkeypatch.setenv("HALSDK_INSTANCE", f"i18mb-sw-{os.getpid()}")
    srv = sim.ServerThread(record=True).start()
    try:
        (tmp_path / "plc.ini").write_text(SINGLE_WRITES.format(
            n=4, head=tcp_head(srv.port, rate=20.0, debug=1)))
        proc = _halrun(tmp_path, "loadusr -W mb2hal config=plc.ini\n"
                       "setp mb2hal.w6.00.int 11\nsetp mb2hal.w6.01.int 22\n"
                       "setp mb2hal.w5.a.bit 1\nsetp mb2hal.one.00.int 33\n"
                       "loadusr -w sleep 2\n"
                       "getp mb2hal.w6.num_errors\n"
                       "getp mb2hal.w5.num_errors\n"
                       "getp mb2hal.one.num_errors\n"
                       "getp mb2hal.back.00.int\nunloadusr mb2hal\n")
    finally:
        srv.stop()
    out = proc.stdout.splitlines()
    assert proc.returncode == 0, proc.stdout
    w6, w5, one, back = out[-4:]
    assert int(w6) >= 3 and int(w5) >= 3 and one == "0" and back == "33"
    assert {(code, addr) for code, addr, _ in srv.requests} == {
        (6, 40), (3, 40)}
    assert (6, 40, [33]) in srv.requests
    # one warning per transaction at start, naming file, line and key
    assert ("mb2hal: warning: plc.ini:15: [TRANSACTION_00]"
            "NELEMENTS: fnct_06_write_single_register sends at most 1 "
            "element(s), not 2: nothing is sent and each repetition counts "
            "an error") in out
    assert any(line.startswith("mb2hal: warning: plc.ini:20: "
                               "[TRANSACTION_01]PIN_NAMES: fnct_05")
               for line in out)
    # and the failure of each such transaction is logged once
    assert len([line for line in out if "transaction w6: not sent" in line
                ]) == 1


def test_halrun_strict_refuses_what_warns(tmp_path, python_tools_first,
                                         monkeypatch):
    monkeypatch.setenv("HALSDK_INSTANCE", f"i18mb-st-{os.getpid()}")
    (tmp_path / "plc.ini").write_text(SINGLE_WRITES.format(
        n=4, head=tcp_head(free_port())))
    proc = _halrun(tmp_path, "loadusr -W mb2hal --strict config=plc.ini\n")
    assert proc.returncode != 0
    lines = [line for line in proc.stdout.splitlines()
             if line.startswith("mb2hal: ")]
    assert lines[0] == (
        "mb2hal: plc.ini:15: [TRANSACTION_00]NELEMENTS: "
        "fnct_06_write_single_register sends at most 1 element(s), not 2: "
        "nothing is sent and each repetition counts an error (refused by "
        "--strict)")
    assert len(lines) == 2 and "[TRANSACTION_01]PIN_NAMES" in lines[1]
    assert "Traceback" not in proc.stdout


def test_program_help_shows_strict(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "halsdk.drivers.mb2hal",
                           "--help"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=30)
    assert proc.returncode == 0
    assert "--strict" in proc.stdout and "config=FILE.ini" in proc.stdout


def test_program_warnings_follow_init_debug(tmp_path):
    """INIT_DEBUG=0 (silent) hides the warnings; --strict still refuses."""
    path = tmp_path / "odd.ini"
    path.write_text("[MB2HAL_INIT]\nINIT_DEBUG=0\nTOTAL_TRANSACTIONS=0x\n")
    proc = subprocess.run([sys.executable, "-m", "halsdk.drivers.mb2hal",
                           f"config={path}"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=30)
    assert proc.returncode == 1
    assert proc.stderr == (f"mb2hal: {path}:3: [MB2HAL_INIT]"
                           "TOTAL_TRANSACTIONS: '0x' is not an integer\n")
    path.write_text("[MB2HAL_INIT]\nINIT_DEBUG=0\nTOTAL_TRANSACTIONS=1\n"
                    + TX + "FOO=1\n")
    cfg = load_config(str(path))
    assert cfg.warnings and cfg.init_debug == 0
    proc = subprocess.run([sys.executable, "-m", "halsdk.drivers.mb2hal",
                           "--strict", f"config={path}"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=30)
    assert proc.returncode == 1
    assert proc.stderr == (f"mb2hal: {path}:11: [TRANSACTION_00]FOO: "
                           "unknown key, ignored (refused by --strict)\n")
