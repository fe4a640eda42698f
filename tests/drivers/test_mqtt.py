"""The MQTT bridge (halsdk.drivers.mqtt) against a real Mosquitto broker
started on loopback by each test."""

from __future__ import annotations

import json
import logging
import os
import queue
import signal
import subprocess
import sys
import time
from types import SimpleNamespace
from typing import Any, Callable

import paho.mqtt.client as mqtt
import pytest
from helpers import repo_path
from helpers.fixtures import factory
from helpers.tools import need_program, unavailable
from paho.mqtt.enums import CallbackAPIVersion

import halsdk
from halsdk.drivers.mqtt import Bridge, BridgeConfig, ConfigError
from halsdk.drivers.mqtt.__main__ import main, publisher_main
from halsdk.drivers.mqtt.bridge import FAULT_CONNECT, FAULT_REFUSED
from halsdk.drivers.mqtt.broker import Mosquitto, find_mosquitto, free_port
from halsdk.drivers.mqtt.client import MAX_PENDING
from halsdk.drivers.mqtt.config import Subscription, parse_args
from halsdk.drivers.mqtt.payload import MAX_PAYLOAD, PayloadError, parse

PREFIX = "t/bridge"


def wait_until(cond: Callable[[], Any], timeout: float = 8.0,
               step: Callable[[], None] = lambda: None) -> Any:
    """Call step() and poll cond() until it is true or the time is up."""
    deadline = time.monotonic() + timeout
    while True:
        step()
        result = cond()
        if result or time.monotonic() > deadline:
            return result
        time.sleep(0.01)


@pytest.fixture
def broker(tmp_path):
    try:
        find_mosquitto()
    except RuntimeError as exc:
        unavailable(f"{exc} (apt-get install mosquitto)")
    made = []

    def make(extra: str = "", port: int = 0) -> Mosquitto:
        b = Mosquitto(str(tmp_path), port or None, extra)
        made.append(b)
        return b
    first = make()
    first.start()
    first.make = make
    yield first
    for b in made:
        b.stop()


class Listener:
    """A paho client that collects messages of the topics it is given."""

    def __init__(self, port: int, *topics: str, **tls: Any):
        self.messages: queue.Queue = queue.Queue()
        self.client = mqtt.Client(CallbackAPIVersion.VERSION2)
        self.client.on_message = lambda c, u, m: self.messages.put(
            (m.topic, m.payload))
        subscribed = []
        self.client.on_subscribe = lambda *a: subscribed.append(1)
        self.client.connect("127.0.0.1", port, 30)
        self.client.loop_start()
        if topics:
            self.client.subscribe([(t, 0) for t in topics])
            assert wait_until(lambda: subscribed, 5)

    def next(self, topic: str, timeout: float = 5.0,
             step: Callable[[], None] = lambda: None) -> Any:
        """The next JSON payload on topic (others are dropped)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            step()
            try:
                got, raw = self.messages.get(timeout=0.01)
            except queue.Empty:
                continue
            if got == topic or topic.endswith("#") and \
                    got.startswith(topic[:-1]):
                return json.loads(raw) if raw[:1] in b'{["-0123456789tfn' \
                    else raw.decode()
        raise AssertionError(f"no message on {topic} within {timeout} s")

    def send(self, topic: str, payload: Any) -> None:
        if not isinstance(payload, (bytes, str)):
            payload = json.dumps(payload)
        self.client.publish(topic, payload, qos=1).wait_for_publish(5)

    def close(self) -> None:
        self.client.disconnect()
        self.client.loop_stop()


@pytest.fixture
def listeners():
    with factory(Listener, Listener.close) as make:
        yield make


@pytest.fixture
def source(hal):
    """Pins, a param and a signal to publish."""
    comp = halsdk.component("src")
    comp.newpin("x", "float", "out")
    comp.newpin("on", "bit", "out")
    comp.newpin("n", "s32", "out")
    comp.newparam("gain", "float", "rw")
    comp.ready()
    comp["gain"] = 2.5
    hal.newsig("speed", "float")
    hal.sets("speed", 100.0)
    yield comp
    comp.exit()


@pytest.fixture
def bridges():
    def start(port: int, **kw: Any) -> Bridge:
        kw.setdefault("prefix", PREFIX)
        kw.setdefault("backoff", 0.05)
        kw.setdefault("backoff_max", 0.2)
        b = Bridge(BridgeConfig(broker="127.0.0.1", port=port, **kw))
        b.start()
        return b
    with factory(start, Bridge.shutdown) as make:
        yield make


def connected(bridge: Bridge, timeout: float = 8.0) -> bool:
    return wait_until(lambda: bridge.comp["connected"], timeout,
                      bridge.cycle)


ITEMS = [("", "src.x"), ("", "src.on"), ("", "src.n"), ("", "src.gain"),
         ("signal", "speed")]


def test_publish_on_change(hal, source, broker, bridges, listeners):
    lst = listeners(broker.port, f"{PREFIX}/#")
    bridge = bridges(broker.port, publish=ITEMS)
    assert connected(bridge)
    first = {}
    while len(first) < len(ITEMS):
        topic, raw = lst.messages.get(timeout=5)
        if topic != f"{PREFIX}/status":
            first[topic] = json.loads(raw)
    # everything once on connect, with value, type and time
    assert first[f"{PREFIX}/src.gain"]["value"] == 2.5
    assert first[f"{PREFIX}/src.on"] == {
        "name": "src.on", "value": False, "type": "bit",
        "timestamp": first[f"{PREFIX}/src.on"]["timestamp"]}
    assert first[f"{PREFIX}/speed"]["type"] == "float"
    assert abs(first[f"{PREFIX}/src.n"]["timestamp"] - time.time()) < 60
    source["x"] = 1.25
    msg = lst.next(f"{PREFIX}/src.x", step=bridge.cycle)
    assert (msg["value"], msg["type"]) == (1.25, "float")
    hal.sets("speed", 7.0)
    source["n"] = -3
    got = {}
    while len(got) < 2:
        msg = lst.next(f"{PREFIX}/#", step=bridge.cycle)
        got[msg["name"]] = msg["value"]
    assert got == {"speed": 7.0, "src.n": -3}
    for _ in range(5):                  # no change: nothing more is sent
        bridge.cycle()
    time.sleep(0.1)
    assert lst.messages.empty()
    assert bridge.comp["published"] == len(ITEMS) + 3
    hal.setp(f"{bridge.cfg.name}.enable", False)
    source["x"] = 9.0
    for _ in range(5):
        bridge.cycle()
    time.sleep(0.1)
    assert lst.messages.empty()          # disabled
    hal.setp(f"{bridge.cfg.name}.enable", True)
    assert lst.next(f"{PREFIX}/src.x", step=bridge.cycle)["value"] == 9.0
    source.exit()                       # its items go, the signal stays
    hal.sets("speed", 8.0)
    while lst.next(f"{PREFIX}/speed", step=bridge.cycle)["value"] != 8.0:
        pass                            # (re-enable sent 7.0 first)
    assert [item.name for item in bridge.items] == ["speed"]


def test_periodic_batch(hal, source, broker, bridges, listeners):
    lst = listeners(broker.port, PREFIX)
    bridge = bridges(broker.port, publish=ITEMS, on_change=False,
                     period=0.1)
    assert connected(bridge)
    first = lst.next(PREFIX, step=bridge.cycle)
    assert set(first) == {"timestamp", "values"}
    assert first["values"] == {"src.x": 0.0, "src.on": False, "src.n": 0,
                               "src.gain": 2.5, "speed": 100.0}
    source["on"] = True
    second = lst.next(PREFIX, step=bridge.cycle)
    while not second["values"]["src.on"]:
        second = lst.next(PREFIX, step=bridge.cycle)
    assert second["timestamp"] >= first["timestamp"] + 0.09
    assert bridge.comp["lastpublish"] >= int(first["timestamp"])
    # period 0 stops the batches
    hal.setp(f"{bridge.cfg.name}.period", 0.0)
    count = bridge.comp["published"]
    wait_until(lambda: False, 0.3, bridge.cycle)
    assert bridge.comp["published"] == count


def subscribe_cfg() -> list[Subscription]:
    return [Subscription("feed", "float"), Subscription("run", "bit"),
            Subscription("tool", "s32", "cell/tool/number"),
            Subscription("count", "u32")]


def test_subscribe_drives_pins(hal, broker, bridges, listeners):
    bridge = bridges(broker.port, subscribe=subscribe_cfg())
    assert connected(bridge)
    hal.newsig("feed-cmd", "float")
    hal.net("feed-cmd", "mqtt-bridge.feed")
    lst = listeners(broker.port)
    wait_until(lambda: False, 0.2, bridge.cycle)   # subscriptions settle
    lst.send(f"{PREFIX}/feed/set", 0.75)
    lst.send(f"{PREFIX}/run/set", {"value": True, "type": "bit"})
    lst.send("cell/tool/number", {"value": 12, "timestamp": 1.0})
    lst.send(f"{PREFIX}/set", {"count": 4000000000, "run": 0})
    assert wait_until(lambda: hal.getp("mqtt-bridge.count") == 4000000000,
                      step=bridge.cycle)
    assert hal.gets("feed-cmd") == 0.75
    assert hal.getp("mqtt-bridge.tool") == 12
    assert hal.getp("mqtt-bridge.run") is False
    assert bridge.comp["received"] == 4
    assert bridge.comp["bad-payloads"] == 0
    pins = {p.name: p for p in hal.pins("mqtt-bridge.*")}
    assert pins["mqtt-bridge.feed"].direction == halsdk.Direction.OUT


BAD = [("feed/set", b"\xff\xfe not json"), ("feed/set", b"{'value': 1}"),
       ("feed/set", b'"fast"'), ("feed/set", b"NaN"),
       ("feed/set", b'{"value": 1, "unit": "mm"}'),
       ("feed/set", b'{"type": "s32", "value": 1}'),
       ("run/set", b"2"), ("count/set", b"-1"), ("count/set", b"1.5"),
       ("count/set", b"4294967296"), ("set", b'{"nosuch": 1}'),
       ("set", b"[1, 2]"), ("feed/set", b"1e999"),
       ("set", b"[" * 1100),                       # nested too deeply
       ("feed/set", b" " * MAX_PAYLOAD + b"0.5")]  # valid, but too long


def test_a_flood_is_dropped_counted_and_logged_once(hal, broker, bridges,
                                                   caplog):
    bridge = bridges(broker.port, subscribe=subscribe_cfg())
    assert connected(bridge)
    topic = f"{PREFIX}/count/set"

    def flood(n: int) -> None:      # as paho's thread delivers them
        for i in range(n):
            bridge.link._on_message(None, None, SimpleNamespace(
                topic=topic, payload=str(i).encode()))
    with caplog.at_level(logging.WARNING, "halsdk.driverkit.mqtt"):
        flood(MAX_PENDING + 5)
        assert len(bridge.link.events) == MAX_PENDING     # bounded
        bridge.cycle()
        bridge.cycle()              # a scan with no new drops: re-armed
        flood(MAX_PENDING + 3)
        bridge.cycle()
    assert bridge.comp["dropped"] == 8
    assert bridge.comp["received"] == 2 * MAX_PENDING
    assert hal.getp("mqtt-bridge.count") == MAX_PENDING - 1
    dropped = [r for r in caplog.records if "dropping" in r.getMessage()]
    assert len(dropped) == 2           # once per burst, not per message


def test_bad_payloads_counted_logged_once(hal, broker, bridges, listeners,
                                          caplog):
    bridge = bridges(broker.port, subscribe=subscribe_cfg())
    assert connected(bridge)
    lst = listeners(broker.port)
    wait_until(lambda: False, 0.2, bridge.cycle)
    lst.send(f"{PREFIX}/feed/set", 2.0)
    lst.send(f"{PREFIX}/count/set", 7)
    assert wait_until(lambda: bridge.comp["received"] == 2,
                      step=bridge.cycle)
    with caplog.at_level(logging.WARNING, "halsdk.driverkit.mqtt"):
        for topic, raw in BAD:
            lst.send(f"{PREFIX}/{topic}", raw)
        assert wait_until(lambda: bridge.comp["received"] == 2 + len(BAD),
                          step=bridge.cycle)
    assert bridge.comp["bad-payloads"] == len(BAD)
    assert hal.getp("mqtt-bridge.feed") == 2.0       # kept
    assert hal.getp("mqtt-bridge.count") == 7
    assert hal.getp("mqtt-bridge.run") is False
    warned = [r.getMessage() for r in caplog.records]
    assert len(warned) == 4                # once per topic
    assert all(r.exc_info is None for r in caplog.records)
    text = "\n".join(warned)
    assert "t/bridge/feed/set': not JSON" in text
    assert "t/bridge/run/set': 2 is not a bit" in text
    assert "t/bridge/count/set': -1 is out of range for u32" in text
    assert "t/bridge/set': unknown key 'nosuch'" in text
    assert not bridge.comp["fault"]


def test_payload_depth_and_size_limits():
    for raw, words in [(b"[" * 1100, "nested too deeply"),
                       (b'{"value": ' + b"[" * 5000, "nested too deeply"),
                       (b" " * MAX_PAYLOAD + b"1", f"limit of {MAX_PAYLOAD}")]:
        with pytest.raises(PayloadError, match=words):
            parse(raw)
    assert parse(b" " * (MAX_PAYLOAD - 1) + b"1") == 1


def test_broker_restart(hal, source, broker, bridges, listeners, caplog):
    bridge = bridges(broker.port, publish=[("", "src.x")])
    assert connected(bridge)
    with caplog.at_level(logging.WARNING, "halsdk.driverkit.mqtt"):
        broker.stop()
        assert wait_until(lambda: not bridge.comp["connected"],
                          step=bridge.cycle)
        assert wait_until(lambda: bridge.comp["fault-code"] == FAULT_CONNECT,
                          step=bridge.cycle)   # lost, then refused retries
        assert bridge.comp["fault"]
        wait_until(lambda: False, 0.5, bridge.cycle)     # several retries
        source["x"] = 3.5                                # while offline
        bridge.cycle()
        again = broker.make(port=broker.port)
        again.start()
        assert connected(bridge)
    assert not bridge.comp["fault"]
    assert bridge.comp["reconnects"] == 1
    lst = listeners(broker.port, f"{PREFIX}/#")
    source["x"] = 4.5
    # the value set while offline may still arrive first (published on
    # reconnection, or retained); then the new one, and nothing else
    value = lst.next(f"{PREFIX}/src.x", step=bridge.cycle)["value"]
    if value == 3.5:
        value = lst.next(f"{PREFIX}/src.x", step=bridge.cycle)["value"]
    assert value == 4.5
    errors = [r.getMessage() for r in caplog.records
              if r.levelno >= logging.ERROR]
    assert len(errors) == 2, errors       # lost once, refused once
    assert f"connection to 127.0.0.1:{broker.port} lost" in errors[0]
    assert "Connection refused" in errors[1]
    assert "connected to 127.0.0.1" in caplog.messages[-1]


def test_unreachable_broker_does_not_block(hal, source, bridges):
    port = free_port()
    bridge = bridges(port, publish=[("", "src.x")])
    assert wait_until(lambda: bridge.comp["fault"], step=bridge.cycle)
    assert bridge.comp["fault-code"] == FAULT_CONNECT
    assert not bridge.comp["connected"]
    source["x"] = 1.0
    for _ in range(50):
        bridge.cycle()                  # returns although nobody listens
    assert bridge.comp["published"] == 0


def test_wrong_credentials(hal, source, broker, bridges, caplog):
    secure = broker.make("allow_anonymous false\n"
                         f"password_file {broker.folder}/passwd")
    broker.stop()
    secure.add_user("cnc", "s3cret")
    secure.start()
    with caplog.at_level(logging.ERROR, "halsdk.driverkit.mqtt"):
        bad = bridges(secure.port, publish=[("", "src.x")], user="cnc",
                      password="wrong", name="bad-login")
        assert wait_until(lambda: bad.comp["fault"], step=bad.cycle)
        wait_until(lambda: False, 0.5, bad.cycle)      # retries, quietly
    assert bad.comp["fault-code"] == FAULT_REFUSED
    assert not bad.comp["connected"]
    assert caplog.messages == [
        f"bad-login: broker 127.0.0.1:{secure.port} refused the connection:"
        " Not authorized (retrying)"]
    good = bridges(secure.port, publish=[("", "src.x")], user="cnc",
                   password="s3cret", name="good-login")
    assert connected(good)
    assert not good.comp["fault"]


def make_certs(folder: str) -> dict[str, str]:
    """A throwaway CA, a server certificate for 127.0.0.1 and a client
    certificate, made with the openssl command."""
    need_program("openssl", "openssl", "the TLS tests make their "
                 "certificates with it")
    paths = {k: os.path.join(folder, k) for k in (
        "ca.key", "ca.crt", "server.key", "server.crt", "client.key",
        "client.crt", "ext.cnf")}
    with open(paths["ext.cnf"], "w") as f:
        f.write("subjectAltName=IP:127.0.0.1\n")

    def run(*args: str) -> None:
        subprocess.run(["openssl", *args], check=True, timeout=30,
                       cwd=folder, capture_output=True)
    run("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2",
        "-subj", "/CN=halsdk test CA", "-keyout", "ca.key", "-out", "ca.crt")
    for who in ("server", "client"):
        run("req", "-newkey", "rsa:2048", "-nodes", "-subj",
            f"/CN={'127.0.0.1' if who == 'server' else 'cnc'}",
            "-keyout", f"{who}.key", "-out", f"{who}.csr")
        run("x509", "-req", "-in", f"{who}.csr", "-CA", "ca.crt",
            "-CAkey", "ca.key", "-CAcreateserial", "-days", "2",
            "-extfile", "ext.cnf", "-out", f"{who}.crt")
    return paths


def test_tls_with_client_certificate(hal, source, broker, bridges,
                                     tmp_path):
    certs = make_certs(str(tmp_path))
    broker.stop()
    tls = broker.make(
        f"allow_anonymous true\ncafile {certs['ca.crt']}\n"
        f"certfile {certs['server.crt']}\nkeyfile {certs['server.key']}\n"
        "require_certificate true\n")
    tls.start()
    good = bridges(tls.port, publish=[("", "src.x")], name="tls-good",
                   tls_ca=certs["ca.crt"], tls_cert=certs["client.crt"],
                   tls_key=certs["client.key"])
    assert connected(good)
    # the value once per connection (a loaded machine may see the TLS
    # link drop and come back, which sends everything again)
    assert good.comp["published"] == 1 + good.comp["reconnects"]
    # no client certificate: the broker drops the handshake
    nocert = bridges(tls.port, publish=[("", "src.x")], name="tls-nocert",
                     tls_ca=certs["ca.crt"])
    # the broker is not signed by a system CA: verification fails
    unknown = bridges(tls.port, publish=[("", "src.x")], name="tls-unknown",
                      tls=True, tls_cert=certs["client.crt"],
                      tls_key=certs["client.key"])
    for b in (nocert, unknown):
        assert wait_until(lambda b=b: b.comp["fault"], step=b.cycle)
        assert b.comp["fault-code"] == FAULT_CONNECT
        assert not b.comp["connected"]
    assert "CERTIFICATE_VERIFY_FAILED" in unknown.fault_text
    insecure = bridges(tls.port, publish=[("", "src.x")], name="tls-any",
                       tls_insecure=True, tls_cert=certs["client.crt"],
                       tls_key=certs["client.key"])
    assert connected(insecure)


def test_bad_tls_file_is_a_config_error(hal, tmp_path):
    bad = tmp_path / "ca.crt"
    bad.write_text("not a certificate\n")
    cfg = BridgeConfig(tls_ca=str(bad), subscribe=[Subscription("y", "bit")])
    with pytest.raises(ConfigError, match="TLS files"):
        Bridge(cfg).start()
    assert not hal.components("mqtt-bridge")


def test_unknown_key_is_a_config_error(hal):
    cfg = BridgeConfig(publish=[("", "no.such.pin")])
    with pytest.raises(ConfigError, match="key 'no.such.pin': no pin, "
                       "param or signal"):
        Bridge(cfg).start()
    assert not hal.components("mqtt-bridge")


def test_options_and_config_file(tmp_path):
    conf = tmp_path / "bridge.conf"
    conf.write_text("[mqtt]\nbroker = 127.0.0.2\nqos = 1\nperiod = 2.5\n"
                    "[publish]\nsrc.x\nsignal:speed\n"
                    "[subscribe]\nfeed = float\ntool = s32 cell/tool\n")
    cfg, _ = parse_args(["-c", str(conf), "--qos", "2", "-n", "b1",
                         "keys=src.n,src.on"])
    assert (cfg.broker, cfg.qos, cfg.period, cfg.name) == (
        "127.0.0.2", 2, 2.5, "b1")
    assert cfg.publish == [("", "src.x"), ("signal", "speed"),
                           ("", "src.n"), ("", "src.on")]
    assert [cfg.sub_topic(s) for s in cfg.subscribe] == [
        "halsdk/b1/feed/set", "cell/tool"]
    pub, _ = parse_args(["--mqtt-broker=h", "--mqtt-port=1884",
                         "--mqtt-user=u", "--mqtt-password=p",
                         "--mqtt-prefix=a/b", "--dryrun", "keys=x,y"],
                        publisher=True)
    assert (pub.broker, pub.port, pub.user, pub.password, pub.prefix,
            pub.dryrun, pub.flat, pub.on_change, pub.period) == (
        "h", 1884, "u", "p", "a/b", True, True, False, 10.0)
    assert BridgeConfig().broker == "127.0.0.1"
    assert BridgeConfig(tls=True).broker_port == 8883
    for text, message in [
            ("[mqtt]\nqos = 5\n", "bad.conf:2: qos: 5 is not in 0..2"),
            ("[mqtt]\nspeed = 1\n", "bad.conf:2: unknown key 'speed'"),
            ("[subscribe]\nx = double\n", "bad.conf:2: type 'double'"),
            ("\n[wrong]\n", "bad.conf:2: unknown section [wrong]"),
            ("x\n", "bad.conf:1: line outside a section"),
            ("[subscribe]\na = bit\na = bit\n",
             "bad.conf:3: pin 'a' subscribed twice (first at "),
            ("[mqtt]\nport = 15885\nport = 1\n",
             "bad.conf:3: key 'port' given twice (first at "),
            ("[mqtt]\npassword = a\npassword-file = bad.conf\n",
             "bad.conf:3: key 'password-file' sets the same as 'password'"),
            ("[mqtt]\nqos = 1\n[publish]\nsrc.x\n[mqtt]\nqos = 2\n",
             "bad.conf:5: section [mqtt] given twice (first at "),
            ("[publish]\nsrc.x\n[publish]\n",
             "bad.conf:3: section [publish] given twice"),
            ("[publish]\nsrc.x\nsignal:src.x\n",
             "bad.conf:3: item 'src.x' published twice (first at "),
            ("[mqtt]\npoll = 1e300\n",
             "bad.conf:2: poll: 1e300 must be > 0 and at most 3600 s")]:
        bad = tmp_path / "bad.conf"
        bad.write_text(text)
        with pytest.raises(ConfigError) as info:
            parse_args(["-c", str(bad), "keys=x"])
        assert str(info.value).startswith(f"{bad.parent}/{message}"), \
            str(info.value)


def test_numeric_options_are_bounded():
    for args, message in [
            (["--poll", "1e300"], "--poll: 1e300 must be > 0 and at most 3600"),
            (["--poll=inf"], "--poll: inf is not a finite number"),
            (["--poll", "nan"], "--poll: nan is not a finite number"),
            (["--poll", "0"], "--poll: 0 must be > 0"),
            (["--poll", "3600.5"], "--poll: 3600.5 must be > 0"),
            (["--backoff", "inf"], "--backoff: inf is not a finite"),
            (["--backoff-max", "1e300"], "--backoff-max: 1e300 must be"),
            (["--period", "nan"], "--period: nan is not a finite number"),
            (["--period", "-1"], "--period: -1 must be in 0..4294967295 s"),
            (["--period", "1e300"], "--period: 1e300 must be in 0..")]:
        with pytest.raises(ConfigError) as info:
            parse_args([*args, "keys=x"])
        assert str(info.value).startswith(f"mqtt-bridge: {message}"), \
            str(info.value)
    for period, message in [
            ("5000000000", "5000000000 must be in 0..4294967295 s"),
            ("1e300", "1e300 must be in 0..4294967295 s"),
            ("2.5", "2.5 is not a whole number of seconds")]:
        with pytest.raises(ConfigError, match=f"^mqtt-publisher: --period: "
                           f"{message}"):
            parse_args(["--period", period, "keys=x"], publisher=True)
    cfg, _ = parse_args(["--period", "4294967295", "--poll", "3600",
                         "--backoff", "3600", "--backoff-max", "3600",
                         "keys=x"], publisher=True)
    assert (cfg.period, cfg.poll, cfg.backoff_max) == (4294967295, 3600,
                                                       3600)


def test_errors_name_the_option_typed():
    for option in ("--mqtt-port", "--port"):
        for args in ([option, "70000"], [f"{option}=70000"]):
            with pytest.raises(ConfigError) as info:
                parse_args([*args, "keys=x"])
            assert str(info.value) == \
                f"mqtt-bridge: {option}: 70000 is not in 1..65535"
    with pytest.raises(ConfigError, match="^mqtt-bridge: --keepalive: 0 "
                       "is not in 1..65535"):
        parse_args(["--keepalive", "0", "keys=x"])


def test_api_config_is_checked(hal):
    for field, value, words in [
            ("poll", float("inf"), "poll: inf is not a finite number"),
            ("poll", 1e300, r"poll: 1e\+300 must be > 0 and at most 3600 s"),
            ("poll", 10 ** 400, r"poll: 10{36}\.\.\. is too large"),
            ("backoff", float("nan"), "backoff: nan is not a finite"),
            ("period", -1.0, "period: -1.0 must be in 0..4294967295 s"),
            ("keepalive", 0, "keepalive: 0 is not an integer in 1..65535"),
            ("port", 70000, "port: 70000 is not an integer in 1..65535")]:
        cfg = BridgeConfig(publish=[("", "x")], **{field: value})
        with pytest.raises(ConfigError, match=f"^mqtt-bridge: {words}"):
            Bridge(cfg).start()
    assert not hal.components("mqtt-bridge")


def test_program_errors_start_with_its_name(tmp_path, capsys):
    missing = tmp_path / "nonexist.ini"
    assert main(["-c", str(missing)]) == 1
    assert capsys.readouterr().err == (
        f"mqtt-bridge: {missing}: cannot read: No such file or directory\n")
    conf = tmp_path / "q1.ini"
    conf.write_text("[mqtt]\nqos = 1\nfoo = 2\n")
    assert publisher_main(["-c", str(conf), "keys=x"]) == 1
    assert capsys.readouterr().err == (
        f"mqtt-publisher: {conf}:3: unknown key 'foo'\n")
    assert main(["--mqtt-port", "70000", "keys=x"]) == 1
    assert capsys.readouterr().err == (
        "mqtt-bridge: --mqtt-port: 70000 is not in 1..65535\n")


def test_example_config_parses():
    here = str(repo_path("examples", "mqtt"))
    cfg, _ = parse_args(["-c", os.path.join(here, "bridge.conf")])
    assert cfg.publish == [("", "siggen.0.clock"), ("", "siggen.0.amplitude"),
                           ("signal", "wave")]
    assert [(s.pin, s.type) for s in cfg.subscribe] == [
        ("offset", "float"), ("reset", "bit")]
    assert (cfg.period, cfg.qos, cfg.topic_prefix) == (5.0, 1, "halsdk/demo")


def _halcmd(tmp_path, text: str) -> subprocess.CompletedProcess:
    hal_file = tmp_path / "bridge.hal"
    hal_file.write_text(text)
    # a file, not a pipe: the loaded programs keep their stdout open
    with open(tmp_path / "halcmd.out", "w+") as out:
        proc = subprocess.run(
            [sys.executable, "-m", "halsdk.halcmd.cli", "halcmd", "-f",
             str(hal_file)], cwd=tmp_path, stdout=out,
            stderr=subprocess.STDOUT, text=True, timeout=30)
        out.seek(0)
        proc.stdout = out.read()
    return proc


def _kill_comp(hal, name: str) -> None:
    comps = hal.components(name)
    if comps and comps[0].alive:
        try:
            hal.unload(name)
        except Exception:
            os.kill(comps[0].pid, signal.SIGKILL)


def test_programs_through_loadusr(hal, source, broker, listeners, tmp_path,
                                  python_tools_first):
    lst = listeners(broker.port, "#")
    port = broker.port
    try:
        proc = _halcmd(tmp_path, (
            f"loadusr -W mqtt-publisher --mqtt-broker=127.0.0.1 "
            f"--mqtt-port={port} --mqtt-prefix=shop/mill "
            "keys=src.x,src.gain,speed\n"
            "setp mqtt-publisher.period 1\n"
            f"loadusr -Wn cell mqtt-bridge -n cell --mqtt-port={port} "
            "--prefix=cell --publish=src.n --subscribe=feed:float\n"
            "net feed-cmd cell.feed\n"))
        assert proc.returncode == 0, proc.stdout
        pub = hal.components("mqtt-publisher")[0]
        assert pub.pid != os.getpid() and pub.alive
        msg = lst.next("shop/mill", timeout=8)
        assert msg == {"src.x": 0.0, "src.gain": 2.5, "speed": 100.0}
        assert hal.ptype("mqtt-publisher.period") == "u32"
        assert hal.getp("mqtt-publisher.lastpublish") > 0
        assert lst.next("cell/status") == "online"
        assert lst.next("cell/src.n")["value"] == 0
        lst.send("cell/feed/set", 0.5)
        assert wait_until(lambda: hal.gets("feed-cmd") == 0.5)
        assert hal.getp("cell.received") == 1
        assert hal.getp("cell.connected") and hal.getp("mqtt-publisher"
                                                       ".connected")
        hal.unload("cell")
        assert lst.next("cell/status") == "offline"
        hal.unload("mqtt-publisher")
        assert not hal.components("mqtt-publisher") + hal.components("cell")
    finally:
        _kill_comp(hal, "cell")
        _kill_comp(hal, "mqtt-publisher")


def test_program_dryrun_and_bad_options(hal, source, tmp_path,
                                        python_tools_first):
    proc = subprocess.Popen(
        ["mqtt-publisher", "--dryrun", "keys=src.x,src.on"], cwd=tmp_path,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)
    topic, text = line.split(" ", 1)
    assert topic == "devices/linuxcnc/machine"
    assert json.loads(text) == {"src.x": 0.0, "src.on": False}
    assert proc.returncode == 0 and "Traceback" not in err
    for args, message in [
            (["keys=no.such.pin"], "key 'no.such.pin': no pin, param or "
             "signal of that name"),
            (["--mqtt-port=x", "keys=src.x"], "port: not a number: 'x'"),
            (["-c", "missing.conf"], "mqtt-bridge: missing.conf: cannot "
             "read"),
            (["--poll", "1e300", "keys=src.x"], "mqtt-bridge: --poll: 1e300"),
            (["src.x"], "unexpected argument 'src.x'")]:
        bad = subprocess.run(["mqtt-bridge", *args], cwd=tmp_path,
                             capture_output=True, text=True, timeout=20)
        assert bad.returncode == 1
        assert message in bad.stderr and "Traceback" not in bad.stderr, \
            bad.stderr
    assert not hal.components("mqtt-bridge")
