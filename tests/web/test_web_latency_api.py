"""The Latency page's API (halsdk.web.latency) through starlette's
TestClient: start, live figures on /ws/latency, reset, stop; the
refusals (read-only, bad settings, the lock); and that the test is
removed by stop, when its last page goes away and when the server ends.
"""

from __future__ import annotations

import time

import pytest
from starlette.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from halsdk.web import latency as page
from halsdk.web.app import create_app

TOKEN = "test-token-latency-0123"
BASE = "http://127.0.0.1:8123"
ORIGIN = {"origin": BASE}
WS = "ws://127.0.0.1:8123/ws/latency"
#: a quick test: the servo thread only, few bins
QUICK = {"base": 0, "servo": 1_000_000, "bins": 20}


def names(hal) -> dict[str, list[str]]:
    # records taken under the instance lock: a test being removed
    # meanwhile (by the server) does not make a listing fail
    return {kind + "s": sorted(r.name for r in hal.snapshot(kind))
            for kind in ("component", "thread", "function")}


def _machine(hal) -> dict[str, list[str]]:
    hal.newthread("servo", 1_000_000)
    hal.loadrt("and2", count=1)
    hal.addf("and2.0", "servo")
    hal.start()
    return names(hal)


def _client(hal, read_only: bool = False) -> TestClient:
    c = TestClient(create_app(hal, token=TOKEN, read_only=read_only),
                   base_url=BASE)
    return c


def post(c: TestClient, action: str, **body):
    return c.post(f"/api/latency/{action}", json=body, headers=ORIGIN)


@pytest.fixture
def client(hal):
    before = _machine(hal)
    with _client(hal) as c:
        c.get("/?token=" + TOKEN)
        yield c
    assert names(hal) == before             # the server ended: all gone


def _live(ws, until, limit: int = 400) -> dict:
    """The first pushed state for which ``until(state)`` holds."""
    for _ in range(limit):
        state = ws.receive_json()["state"]
        if until(state):
            return state
    raise AssertionError(f"no state with the condition in {limit} pushes")


def test_the_idle_state(client):
    r = client.get("/api/latency/state")
    assert r.status_code == 200
    data = r.json()
    assert data["running"] is False and data["threads"] == []
    assert data["defaults"] == {"base": 25_000, "servo": 1_000_000,
                                "base_binsize": 100, "servo_binsize": 100,
                                "bins": 200}
    assert data["read_only"] is False


def test_start_live_figures_reset_and_stop(client, hal):
    before = names(hal)
    r = post(client, "start", base=50_000, servo=1_000_000, bins=30)
    assert r.status_code == 200, r.text
    state = r.json()["state"]
    assert state["running"] is True
    assert state["realtime"] in (True, False) and state["note"]
    assert {"latency-base", "latency-servo"} <= set(names(hal)["threads"])
    assert {"latency-base-td", "latency-base-bins", "latency-servo-td",
            "latency-servo-bins"} <= set(names(hal)["functions"])
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        live = _live(ws, lambda s: s["sweeps"] >= 2 and all(
            t["samples"] for t in s["threads"]))
        for t in live["threads"]:
            h = t["histogram"]
            assert t["samples"] == h["total"] > 0
            assert t["min"] <= t["avg"] <= t["max"]
            assert t["sdev"] >= 0 and t["jitter"] >= 0
            assert h["bins"] == 30
        cycles = live["threads"][1]["cycles"]
        later = _live(ws, lambda s: s["threads"][1]["cycles"] > cycles)
        assert later["running"]
        r = post(client, "reset")
        assert r.status_code == 200 and r.json()["ok"]
    r = post(client, "stop")
    assert r.status_code == 200 and r.json()["state"]["running"] is False
    assert names(hal) == before
    assert post(client, "stop").status_code == 200    # nothing to stop
    assert post(client, "reset").status_code == 409


def test_the_push_is_at_least_twice_a_second():
    assert page.PUSH_PERIOD <= 0.5


def test_a_start_without_realtime_scheduling(hal):
    """The test starts a stopped instance: without realtime scheduling
    when asked, and the state says so."""
    with _client(hal) as c:
        c.get("/?token=" + TOKEN)
        r = post(c, "start", realtime=False, **QUICK)
        assert r.status_code == 200, r.text
        state = r.json()["state"]
        assert state["realtime"] is False
        assert "non-realtime" in state["note"]
        assert post(c, "stop").status_code == 200
    assert not hal.info()["threads_running"]
    assert names(hal)["threads"] == []


def test_a_second_start_is_refused(client, hal):
    assert post(client, "start", **QUICK).status_code == 200
    r = post(client, "start", **QUICK)
    assert r.status_code == 409
    assert "already running" in r.json()["error"]
    assert post(client, "stop").status_code == 200


@pytest.mark.parametrize("body, word", [
    ({"servo": "fast"}, "'servo' is not an integer"),
    ({"bins": 5000}, "'bins' 5000 is not from 1 to 1000"),
    ({"servo_binsize": 0}, "'servo_binsize' 0"),
    ({"servo": True}, "'servo' is not an integer"),
    ({"realtime": "yes"}, "'realtime' is not true or false"),
])
def test_bad_settings_are_refused(client, hal, body, word):
    before = names(hal)
    r = post(client, "start", **body)
    assert r.status_code == 400
    assert word in r.json()["error"]
    assert names(hal) == before


def test_a_base_period_below_the_least_is_refused(client, hal):
    before = names(hal)
    r = post(client, "start", base=1000)
    assert r.status_code == 409
    assert "latency-base" in r.json()["error"]
    assert names(hal) == before


def test_the_lock_refuses_a_start(client, hal):
    before = names(hal)
    hal.lock(hal.LOCK_LOAD)
    try:
        r = post(client, "start", **QUICK)
    finally:
        hal.unlock()
    assert r.status_code == 409
    assert "cannot start" in r.json()["error"]
    assert "lock" in r.json()["error"]
    assert names(hal) == before


def test_unknown_action_and_no_json(client):
    assert post(client, "launch").status_code == 404
    r = client.post("/api/latency/start", content=b"x", headers=ORIGIN)
    assert r.status_code == 400


def test_another_origin_is_refused(client, hal):
    before = names(hal)
    r = client.post("/api/latency/start", json=QUICK,
                    headers={"origin": "http://evil.example"})
    assert r.status_code == 403
    assert names(hal) == before


def test_read_only_refuses_every_change(hal):
    before = _machine(hal)
    with _client(hal, read_only=True) as c:
        c.get("/?token=" + TOKEN)
        for action in ("start", "reset", "stop"):
            r = post(c, action, **QUICK)
            assert r.status_code == 403
            assert "read-only" in r.json()["error"]
        assert c.get("/api/latency/state").json()["read_only"] is True
        with c.websocket_connect(WS, headers=ORIGIN) as ws:
            assert ws.receive_json()["state"]["running"] is False
    assert names(hal) == before


def test_no_token_is_refused(hal):
    _machine(hal)
    with _client(hal) as c:
        assert c.get("/api/latency/state").status_code == 403
        assert c.post("/api/latency/start", json=QUICK,
                      headers=ORIGIN).status_code == 403
        with pytest.raises(WebSocketDisconnect):
            with c.websocket_connect(WS, headers=ORIGIN) as ws:
                ws.receive_json()
        assert "latency-servo" not in names(hal)["threads"]


def test_the_test_ends_when_its_last_page_goes(client, hal, monkeypatch):
    monkeypatch.setattr(page, "IDLE_GRACE", 0.2)
    before = names(hal)
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        ws.receive_json()
        assert post(client, "start", **QUICK).status_code == 200
        _live(ws, lambda s: s["running"])
    deadline = time.monotonic() + 30
    while names(hal) != before and time.monotonic() < deadline:
        time.sleep(0.05)
    assert names(hal) == before
    assert client.get("/api/latency/state").json()["running"] is False


def test_the_test_ends_with_the_server(hal):
    before = _machine(hal)
    with _client(hal) as c:
        c.get("/?token=" + TOKEN)
        assert post(c, "start", **QUICK).status_code == 200
        assert "latency-servo" in names(hal)["threads"]
    assert names(hal) == before
