"""The Scope page's server side: the trigger finder and the triggering of
continuous samples (NumPy only, property tests), the recorder of the
public API, and the page's API and websocket through starlette's
TestClient against a real instance (threads stepped: the samples are
exact)."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from starlette.testclient import TestClient

from halsdk.errors import InvalidError, NotFoundError
from halsdk.web.app import create_app
from halsdk.web.scope import Acquisition, Config, find_trigger, parse_config

TOKEN = "scope-token-0123456789"
BASE = "http://127.0.0.1:8124"
ORIGIN = {"origin": BASE}
WS = "ws://127.0.0.1:8124/ws/scope"


# ---------------------------------------------------------------- triggers

@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-10, -0.5), min_size=1, max_size=50),
       st.lists(st.floats(0.5, 10), min_size=1, max_size=50),
       st.lists(st.floats(-10, 10), max_size=50),
       st.floats(-0.4, 0.4), st.booleans())
def test_the_first_level_crossing_is_found(low, high, rest, level, rising):
    """Data that stays on one side of the level, then crosses it: the
    crossing's index is found, whatever comes after."""
    first, second = (low, high) if rising else (high, low)
    values = np.array(first + second + rest)
    assert find_trigger(values, level, rising) == len(first)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1e6, 1e6), max_size=80), st.floats(-1e6, 1e6),
       st.booleans(), st.integers(0, 90))
def test_a_found_crossing_is_a_crossing(values, level, rising, start):
    v = np.array(values, dtype=float)
    hit = find_trigger(v, level, rising, start)
    pairs = [(i, v[i - 1], v[i]) for i in range(max(start, 1), len(v))]
    crossings = [i for i, a, b in pairs
                 if (a < level <= b if rising else a > level >= b)]
    assert hit == (crossings[0] if crossings else None)


def _square(n: int, half: int, phase: int = 0) -> np.ndarray:
    return np.where(((np.arange(n) + phase) // half) % 2 == 0, -1.0, 1.0)


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 40), st.integers(0, 79), st.integers(10, 120),
       st.floats(0, 100), st.lists(st.integers(1, 97), min_size=1,
                                   max_size=30))
def test_every_screen_has_the_edge_at_the_trigger(half, phase, length,
                                                  position, chunks):
    """A square wave fed in random chunks: each screen has ``length``
    samples and a rising edge exactly at its trigger index."""
    cfg = Config(["sq"], "t", length=length, trigger=0, level=0.0,
                 position=position)
    acq = Acquisition(cfg)
    wave = _square(sum(chunks), half, phase)
    at = 0
    screens = []
    for n in chunks:
        sampleno = np.arange(at, at + n)
        for msg in acq.feed(sampleno, wave[at:at + n, None]):
            screens.append(msg["frame"])
        at += n
    for s in screens:
        data = s["channels"][0]
        assert len(data) == length
        assert s["trigger"] == cfg.pre
        assert data[cfg.pre - 1] < 0 <= data[cfg.pre] if cfg.pre else True
        assert wave[s["start"] + cfg.pre] == 1.0
        assert wave[s["start"] + cfg.pre - 1] == -1.0
    assert acq.lost == 0


def test_the_multiplier_keeps_one_sample_in_mult_and_gaps_count():
    acq = Acquisition(Config(["a"], "t", mult=4, mode="roll", length=10))
    out = acq.feed(np.arange(0, 10), np.arange(0, 10, dtype=float)[:, None])
    assert out == [{"roll": {"start": 0, "channels": [[0.0, 4.0, 8.0]]}}]
    out = acq.feed(np.arange(13, 17), np.arange(13, 17, dtype=float)[:, None])
    assert out[0]["roll"] == {"start": 4, "channels": [[16.0]]}
    assert acq.lost == 3 and acq.samples == 4


def test_single_takes_one_screen_and_auto_runs_free():
    wave = _square(400, 20)
    single = Acquisition(Config(["a"], "t", length=30, mode="single",
                                trigger=0))
    assert len(single.feed(np.arange(400), wave[:, None])) == 1
    assert single.feed(np.arange(400, 800), wave[:, None]) == []
    assert single.state == "done"
    flat = np.zeros((100, 1))
    auto = Acquisition(Config(["a"], "t", length=30, mode="auto", trigger=0))
    screens = auto.feed(np.arange(100), flat)
    assert screens and screens[0]["frame"]["trigger"] is None
    normal = Acquisition(Config(["a"], "t", length=30, trigger=0))
    assert normal.feed(np.arange(100), flat) == []


@pytest.mark.parametrize("body, word", [
    ({"channels": [], "thread": "t"}, "channels"),
    ({"channels": ["a"] * 17, "thread": "t"}, "17 channels"),
    ({"channels": ["a"]}, "thread"),
    ({"channels": ["a"], "thread": "t", "mode": "x"}, "mode"),
    ({"channels": ["a"], "thread": "t", "mult": 0}, "mult"),
    ({"channels": ["a"], "thread": "t", "length": 5}, "length"),
    ({"channels": ["a"], "thread": "t", "trigger": 1}, "trigger"),
    ({"channels": ["a"], "thread": "t", "position": 101}, "position"),
    ({"channels": ["a"], "thread": "t", "edge": "up"}, "edge"),
])
def test_a_bad_config_names_what_is_wrong(body, word):
    with pytest.raises(ValueError, match=word):
        parse_config(body)


# ---------------------------------------------------------------- recorder

def _machine(hal) -> None:
    hal.newthread("servo", 1_000_000)
    hal.loadrt("siggen")
    hal.addf("siggen.0.update", "servo")
    hal.newsig("level", "float")


def _recorders(hal) -> list[str]:
    # a snapshot: the server may remove a recorder while we look
    return [c.name for c in hal.snapshot("component")
            if c.name.startswith(hal.RECORDER_PREFIX)]


def test_a_recorder_records_every_cycle_and_goes(hal):
    _machine(hal)
    hal.setp("siggen.0.frequency", 100.0)
    name = hal.recorder(["siggen.0.square", "level", "siggen.0.frequency"],
                        "servo", 64)
    assert name in hal.thread("servo").functions
    hal.sets("level", 2.5)
    hal.step(10)
    arr = hal.stream(name).read_many(-1, ["sq", "lv", "fr"])
    assert list(arr["sample"]) == list(range(10))
    assert set(arr["lv"]) == {2.5} and set(arr["fr"]) == {100.0}
    hal.step(100)                       # more than it holds: overruns
    assert hal.stream(name).overruns > 0
    hal.recorder_delete(name)
    assert _recorders(hal) == []
    assert hal.find("function", name) is None
    with pytest.raises(NotFoundError):
        hal.recorder_delete(name)
    with pytest.raises(NotFoundError, match="no.such"):
        hal.recorder(["no.such"], "servo", 64)
    with pytest.raises(InvalidError):
        hal.recorder(["level"], "servo", 1)
    with pytest.raises(InvalidError):
        hal.recorder_delete("siggen")
    assert _recorders(hal) == []


def test_a_pin_linked_later_is_recorded_from_its_signal(hal):
    _machine(hal)
    name = hal.recorder(["siggen.0.reset"], "servo", 64)
    hal.setp("siggen.0.reset", False)
    hal.step(2)
    hal.newsig("rst", "bit")
    hal.net("rst", "siggen.0.reset")
    hal.sets("rst", True)
    hal.step(2)
    arr = hal.stream(name).read_many(-1, ["r"])
    assert list(arr["r"]) == [0, 0, 1, 1]
    hal.recorder_delete(name)


def test_the_recorder_of_a_killed_process_is_swept(hal, tmp_path):
    """An attached process that records and is killed leaves its recorder;
    the next recorder made removes it."""
    _machine(hal)
    hal.start()
    try:
        code = ("import sys, time\nfrom halsdk.hal import Hal\n"
                "h = Hal(create=False)\n"
                "print(h.recorder(['level'], 'servo', 64), flush=True)\n"
                "time.sleep(60)\n")
        proc = subprocess.Popen([sys.executable, "-c", code],
                                stdout=subprocess.PIPE, text=True,
                                env=dict(os.environ), cwd=tmp_path)
        assert proc.stdout is not None
        orphan = proc.stdout.readline().strip()
        assert orphan in _recorders(hal)
        proc.kill()
        proc.wait()
        mine = hal.recorder(["level"], "servo", 64)
        assert _recorders(hal) == [mine]
        hal.recorder_delete(mine)
        assert _recorders(hal) == []
    finally:
        hal.stop()


# ---------------------------------------------------------------- the page

@pytest.fixture
def client(hal):
    _machine(hal)
    with TestClient(create_app(hal, token=TOKEN), base_url=BASE) as c:
        c.get("/?token=" + TOKEN)
        yield c


def _until(ws, key: str, limit: int = 400) -> dict:
    for _ in range(limit):
        msg = ws.receive_json()
        if key in msg:
            return msg
    raise AssertionError(f"no {key!r} message")


def _start(c, session: str, **config):
    return c.post("/api/scope/start", json={"session": session, **config},
                  headers=ORIGIN)


def test_the_sources_list_threads_and_names(client):
    data = client.get("/api/scope/sources").json()
    assert data["threads"] == [{"name": "servo", "period": 1_000_000}]
    assert "siggen.0.square" in data["pins"]
    assert "level" in data["signals"]
    assert data["max_channels"] == 16 and data["read_only"] is False


def test_the_scope_triggers_on_a_square_wave(client, hal):
    hal.setp("siggen.0.frequency", 50.0)        # 20 cycles a period
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        session = _until(ws, "hello")["hello"]["session"]
        r = _start(client, session, channels=["siggen.0.square", "level"],
                   thread="servo", length=40, position=25, trigger=0)
        assert r.status_code == 200, r.text
        assert r.json()["dt"] == pytest.approx(0.001)
        assert len(_recorders(hal)) == 1
        hal.step(200)
        frame = _until(ws, "frame")
        data = frame["frame"]["channels"][0]
        pre = frame["frame"]["trigger"]
        assert pre == round(0.25 * 39) and len(data) == 40
        assert data[pre - 1] < 0 <= data[pre]
        assert frame["status"]["lost"] == 0
        assert frame["status"]["state"] == "triggered"
        # a change of mode keeps the recorder; stop removes it
        first = _recorders(hal)
        assert _start(client, session, channels=["siggen.0.square", "level"],
                      thread="servo", mode="roll").status_code == 200
        assert _recorders(hal) == first
        hal.step(30)
        got = 0
        while got < 30:
            got += len(_until(ws, "roll")["roll"]["channels"][0])
        assert got == 30
        r = client.post("/api/scope/stop", json={"session": session},
                        headers=ORIGIN)
        assert r.status_code == 200
        assert _recorders(hal) == []
        assert _until(ws, "status")["status"]["running"] is False


def test_closing_the_websocket_removes_the_recorder(client, hal):
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        session = _until(ws, "hello")["hello"]["session"]
        assert _start(client, session, channels=["level"],
                      thread="servo").status_code == 200
        assert len(_recorders(hal)) == 1
    deadline = time.monotonic() + 10
    while _recorders(hal) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert _recorders(hal) == []
    assert hal.find("function", "siggen.0.update") is not None


def test_the_server_end_removes_the_recorders(client, hal):
    """What the server's end runs (the workbench's close) removes the
    recorders of the websockets still open."""
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        session = _until(ws, "hello")["hello"]["session"]
        assert _start(client, session, channels=["level"],
                      thread="servo").status_code == 200
        assert len(_recorders(hal)) == 1
        client.app.state.workbench.pages["scope"].close()
        assert _recorders(hal) == []


@pytest.mark.parametrize("body, status, word", [
    ({"session": "nope", "channels": ["level"], "thread": "servo"}, 404,
     "session"),
    ({"channels": ["level"], "thread": "servo"}, 404, "session"),
])
def test_a_start_without_a_session_is_404(client, body, status, word):
    r = client.post("/api/scope/start", json=body, headers=ORIGIN)
    assert r.status_code == status and word in r.json()["error"]


def test_bad_starts_are_refused_with_the_reason(client, hal):
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        session = _until(ws, "hello")["hello"]["session"]
        r = _start(client, session, channels=["no.such.pin"], thread="servo")
        assert r.status_code == 409 and "no.such.pin" in r.json()["error"]
        r = _start(client, session, channels=["level"], thread="nothread")
        assert r.status_code == 409 and "nothread" in r.json()["error"]
        r = _start(client, session, channels=["level"], thread="servo",
                   mult=0)
        assert r.status_code == 400 and "mult" in r.json()["error"]
        r = client.post("/api/scope/start", json={"session": session,
                        "channels": ["level"], "thread": "servo"},
                        headers={"origin": "http://evil.example"})
        assert r.status_code == 403
        assert _recorders(hal) == []


def test_a_channel_that_goes_stops_the_scope(client, hal):
    hal.newsig("tmp", "float")
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        session = _until(ws, "hello")["hello"]["session"]
        assert _start(client, session, channels=["tmp"],
                      thread="servo").status_code == 200
        hal.delsig("tmp")
        for _ in range(400):
            status = _until(ws, "status")["status"]
            if status["error"]:
                break
        assert "tmp" in status["error"] and status["running"] is False
        assert _recorders(hal) == []


def test_read_only_refuses_starting(hal):
    _machine(hal)
    app = create_app(hal, token=TOKEN, read_only=True)
    with TestClient(app, base_url=BASE) as c:
        c.get("/?token=" + TOKEN)
        assert c.get("/api/scope/sources").json()["read_only"] is True
        with c.websocket_connect(WS, headers=ORIGIN) as ws:
            session = _until(ws, "hello")["hello"]["session"]
            r = _start(c, session, channels=["level"], thread="servo")
            assert r.status_code == 403
            assert "read-only" in r.json()["error"]
            assert c.post("/api/scope/stop", json={"session": session},
                          headers=ORIGIN).status_code == 403
        assert _recorders(hal) == []
