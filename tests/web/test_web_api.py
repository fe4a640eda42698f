"""The web workbench's API (halsdk.web.app) against a real instance, through
starlette's TestClient: the token gate, read-only, the Show page's data,
its changes (halcmd's words on refusal) and the websocket of live values.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from importlib import resources

import pytest
from helpers import repo_path
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from starlette.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from halsdk.web.app import create_app

TOKEN = "test-token-0123456789"
BASE = "http://127.0.0.1:8123"
ORIGIN = {"origin": BASE}
#: the websocket (the test client takes the host of a relative URL from
#: no base_url: a full one)
WS = "ws://127.0.0.1:8123/ws"
#: every character a HAL name may have (the core refuses blanks, quotes,
#: #, $, [, ] and backslash; docs/concepts.rst)
NAME_CHARS = "".join(chr(c) for c in range(33, 127)
                     if chr(c) not in "\"'#\\$[]")


def _machine(hal) -> None:
    hal.newthread("servo", 1_000_000)
    hal.loadrt("and2", count=2)
    hal.addf("and2.0", "servo")
    hal.net("x-in", "and2.0.in0")


@pytest.fixture
def client(hal):
    _machine(hal)
    with TestClient(create_app(hal, token=TOKEN), base_url=BASE) as c:
        c.get("/?token=" + TOKEN)           # the first visit: the cookie
        yield c


@pytest.fixture
def read_only(hal):
    _machine(hal)
    app = create_app(hal, token=TOKEN, read_only=True)
    with TestClient(app, base_url=BASE) as c:
        c.get("/?token=" + TOKEN)
        yield c


def _signal(hal, pin: str):
    """The name of the signal a pin is linked to, or None."""
    sig = hal.pin(pin).signal
    return None if sig is None else sig.name


def post(c: TestClient, action: str, **body):
    return c.post(f"/api/{action}", json=body, headers=ORIGIN)


# ---------------------------------------------------------------- the token

@pytest.mark.parametrize("path", ["/", "/api/tree", "/api/info",
                                  "/static/show.js", "/api/item?kind=pin"
                                  "&name=and2.0.in0", "/nothing"])
def test_no_token_is_403(hal, path):
    _machine(hal)
    with TestClient(create_app(hal, token=TOKEN), base_url=BASE) as c:
        r = c.get(path)
        assert r.status_code == 403
        assert "token" in r.text
        assert c.get(path + ("&" if "?" in path else "?")
                     + "token=wrong").status_code == 403
        r = c.post("/api/setp", json={"name": "and2.0.in1", "value": "1"})
        assert r.status_code == 403
    assert hal.getp("and2.0.in1") is False


def test_the_first_visit_sets_a_strict_cookie(hal):
    _machine(hal)
    with TestClient(create_app(hal, token=TOKEN), base_url=BASE) as c:
        r = c.get("/?token=" + TOKEN, follow_redirects=False)
        assert r.status_code == 303
        assert r.headers["location"] == "/"          # out of the URL
        cookie = r.headers["set-cookie"]
        assert cookie.startswith(f"halsdk-web-8123={TOKEN};")
        assert "HttpOnly" in cookie and "SameSite=Strict" in cookie
        page = c.get("/")                           # by the cookie now
        assert page.status_code == 200
        assert "<title>HAL workbench</title>" in page.text
        assert page.headers["content-security-policy"].startswith(
            "default-src 'self'")
        assert c.get("/api/tree").status_code == 200
        assert c.get("/static/show.js").status_code == 200
        c.cookies.clear()
        assert c.get("/api/tree").status_code == 403


def test_a_token_in_the_query_of_an_api_request_works_once_and_sets_it(hal):
    _machine(hal)
    with TestClient(create_app(hal, token=TOKEN), base_url=BASE) as c:
        r = c.get("/api/info?token=" + TOKEN)
        assert r.status_code == 200 and r.json()["instance"] == hal.instance
        assert "HttpOnly" in r.headers["set-cookie"]
        assert c.get("/api/info").status_code == 200


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(bad=st.text(max_size=40).filter(lambda t: t != TOKEN))
def test_any_other_token_is_refused(hal, bad):
    if not hal.find("pin", "and2.0.in0"):
        _machine(hal)
    with TestClient(create_app(hal, token=TOKEN), base_url=BASE) as c:
        assert c.get("/api/info", params={"token": bad}).status_code == 403
        c.cookies.set("halsdk-web-8123", re.sub(r"[^!-~]", "", bad) or "x")
        assert c.get("/api/info").status_code == 403
        # the right token beside a wrong one is no token
        assert c.get("/api/info", params=[("token", TOKEN),
                                          ("token", bad)]).status_code == 403


# ---------------------------------------------------------------- read-only

def test_read_only_refuses_every_change(read_only, hal):
    for action, body in [("setp", {"name": "and2.0.in1", "value": "1"}),
                         ("sets", {"name": "x-in", "value": "1"}),
                         ("net", {"signal": "y", "pins": ["and2.1.in0"]}),
                         ("unlinkp", {"pin": "and2.0.in0"}),
                         ("addf", {"function": "and2.1", "thread": "servo"}),
                         ("delf", {"function": "and2.0", "thread": "servo"})]:
        r = post(read_only, action, **body)
        assert r.status_code == 403, action
        assert "read-only" in r.json()["error"]
    for line in ["setp and2.0.in1 1", "and2.0.in1 = 1", "net y and2.1.in0",
                 "show pin\nsetp and2.0.in1 1", "unlinkp and2.0.in0"]:
        r = read_only.post("/api/command", json={"line": line},
                           headers=ORIGIN)
        assert r.status_code == 403, line
        assert "read-only" in r.json()["error"]
    assert hal.getp("and2.0.in1") is False
    assert _signal(hal, "and2.0.in0") == "x-in"
    assert _signal(hal, "and2.1.in0") is None
    assert hal.thread("servo").functions == ["and2.0"]
    # what only reads still works
    r = read_only.post("/api/command", json={"line": "getp and2.0.in1"},
                       headers=ORIGIN)
    assert r.status_code == 200 and r.json()["output"] == "FALSE\n"
    assert read_only.get("/api/info").json()["read_only"] is True


# ---------------------------------------------------------------- data

def test_the_tree_lists_the_instance(client, hal):
    tree = client.get("/api/tree").json()
    assert tree["instance"] == hal.instance and tree["read_only"] is False
    pins = {p["name"]: p for p in tree["pins"]}
    assert set(pins) == {p.name for p in hal.pins()}
    assert pins["and2.0.in0"] == {"name": "and2.0.in0", "type": "bit",
                                  "dir": "IN", "owner": "and2",
                                  "signal": "x-in", "value": "FALSE"}
    assert pins["and2.0.out"]["dir"] == "OUT"
    assert [s["name"] for s in tree["signals"]] == ["x-in"]
    assert {"and2.0", "and2.1"} <= {f["name"] for f in tree["functions"]}
    assert tree["threads"] == [{"name": "servo", "period": 1_000_000,
                                "running": False, "functions": ["and2.0"]}]
    assert "and2" in {c["name"] for c in tree["components"]}
    assert {p["name"] for p in tree["params"]} == {
        p.name for p in hal.params()}
    assert client.get("/api/values", params=[
        ("key", "pin:and2.0.in0"), ("key", "signal:x-in"),
        ("key", "param:no.such")]).json() == {
        "pin:and2.0.in0": "FALSE", "signal:x-in": "FALSE",
        "param:no.such": None}


def test_the_detail_views(client, hal):
    hal.net("x-out", "and2.0.out", "and2.1.in0", "and2.1.in1")
    pin = client.get("/api/item", params={"kind": "pin",
                                          "name": "and2.1.in0"}).json()
    assert pin["exists"] and pin["type"] == "bit" and pin["dir"] == "IN"
    assert pin["owner"] == "and2" and pin["signal"] == "x-out"
    assert [w["name"] for w in pin["writers"]] == ["and2.0.out"]
    assert [r["name"] for r in pin["readers"]] == ["and2.1.in0",
                                                   "and2.1.in1"]
    sig = client.get("/api/item", params={"kind": "signal",
                                          "name": "x-out"}).json()
    assert sig["writers"] == [{"name": "and2.0.out", "dir": "OUT",
                               "owner": "and2"}]
    comp = client.get("/api/item", params={"kind": "component",
                                           "name": "and2"}).json()
    assert "and2.1.out" in comp["pins"] and "and2.0" in comp["functions"]
    funct = client.get("/api/item", params={"kind": "function",
                                            "name": "and2.0"}).json()
    assert funct["threads"] == ["servo"] and funct["owner"] == "and2"
    thread = client.get("/api/item", params={"kind": "thread",
                                             "name": "servo"}).json()
    assert thread["functions"] == ["and2.0"] and thread["period"] == 1000000
    gone = client.get("/api/item", params={"kind": "pin",
                                           "name": "no.such"}).json()
    assert gone == {"kind": "pin", "name": "no.such", "exists": False}
    assert client.get("/api/item", params={"kind": "nope",
                                           "name": "x"}).status_code == 400


def test_a_glob_character_in_a_name_names_that_item_only(client, hal):
    hal.newsig("a*", "bit")
    hal.newsig("ab", "float")
    d = client.get("/api/item", params={"kind": "signal",
                                        "name": "a*"}).json()
    assert d["exists"] and d["type"] == "bit"
    assert client.get("/api/item", params={"kind": "signal", "name": "a?"}
                      ).json()["exists"] is False


# ---------------------------------------------------------------- changes

def test_setp_reaches_the_pin(client, hal):
    r = post(client, "setp", name="and2.0.in1", value="1")
    assert r.status_code == 200 and r.json()["ok"] is True
    assert hal.getp("and2.0.in1") is True


def test_sets_net_unlinkp_addf_delf(client, hal):
    assert post(client, "sets", name="x-in", value="TRUE").json()["ok"]
    assert hal.gets("x-in") is True
    assert post(client, "net", signal="x-in",
                pins=["and2.1.in0"]).json()["ok"]
    assert _signal(hal, "and2.1.in0") == "x-in"
    assert post(client, "unlinkp", pin="and2.1.in0").json()["ok"]
    assert _signal(hal, "and2.1.in0") is None
    assert post(client, "addf", function="and2.1", thread="servo",
                position="1").json()["ok"]
    assert hal.thread("servo").functions == ["and2.1", "and2.0"]
    assert post(client, "delf", function="and2.1",
                thread="servo").json()["ok"]
    assert hal.thread("servo").functions == ["and2.0"]


def _halcmd(*words: str, tmp_path) -> str:
    """What the halcmd program says on stderr (attached to the test's
    instance: the fixture set HALSDK_INSTANCE)."""
    proc = subprocess.run([sys.executable, "-m", "halsdk.halcmd.cli",
                           "halcmd", *words], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1, proc
    return proc.stderr


@pytest.mark.parametrize("action, body, words", [
    ("addf", {"function": "no.such", "thread": "servo"},
     ["addf", "no.such", "servo"]),
    ("addf", {"function": "and2.0", "thread": "servo"},
     ["addf", "and2.0", "servo"]),              # already in the thread
    ("delf", {"function": "and2.1", "thread": "servo"},
     ["delf", "and2.1", "servo"]),
    ("setp", {"name": "and2.0.out", "value": "1"},
     ["setp", "and2.0.out", "1"]),              # an out pin
    ("setp", {"name": "and2.0.in1", "value": "maybe"},
     ["setp", "and2.0.in1", "maybe"]),
    ("sets", {"name": "no-sig", "value": "1"}, ["sets", "no-sig", "1"]),
    ("net", {"signal": "x-in", "pins": ["and2.0.out", "and2.1.out"]},
     ["net", "x-in", "and2.0.out", "and2.1.out"]),  # two writers
])
def test_a_refusal_is_in_halcmds_words(client, hal, tmp_path, action, body,
                                       words):
    expected = _halcmd(*words, tmp_path=tmp_path)
    r = post(client, action, **body)
    assert r.status_code == 409
    assert r.json() == {"ok": False, "output": "", "error": expected}


def test_the_lock_level_refuses_in_halcmds_words(client, hal, tmp_path):
    hal.lock()                                  # lock all
    try:
        expected = _halcmd("addf", "and2.1", "servo", tmp_path=tmp_path)
        assert "locked" in expected.lower()
        r = post(client, "addf", function="and2.1", thread="servo")
        assert (r.status_code, r.json()["error"]) == (409, expected)
        r = client.post("/api/command", json={"line": "net y and2.1.in0"},
                        headers=ORIGIN)
        assert r.json()["error"] == _halcmd("net", "y", "and2.1.in0",
                                            tmp_path=tmp_path)
    finally:
        hal.unlock()
    assert hal.thread("servo").functions == ["and2.0"]


def test_the_command_line_runs_halcmd(client, hal):
    r = client.post("/api/command", json={
        "line": "setp and2.1.in0 1\nshow pin and2.1.in0"}, headers=ORIGIN)
    assert r.status_code == 200
    assert r.json()["output"] == hal.command("show pin and2.1.in0")
    assert hal.getp("and2.1.in0") is True
    r = client.post("/api/command", json={"line": "frobnicate"},
                    headers=ORIGIN)
    assert (r.status_code, r.json()["error"]) == (
        409, "Unknown command 'frobnicate'\n")


def test_the_command_line_substitutes_nothing(client, monkeypatch):
    """The server's environment is not the page's: ``$NAME`` is a word
    as typed (halcmd would put the variable's value there)."""
    monkeypatch.setenv("HALSDK_WEB_TEST_SECRET", "hunter2")
    for line in ["help $HALSDK_WEB_TEST_SECRET", "getp $(HOME)",
                 "print $HALSDK_WEB_TEST_SECRET", "getp [EMC]MACHINE"]:
        r = client.post("/api/command", json={"line": line}, headers=ORIGIN)
        assert r.status_code in (200, 409), line
        text = r.json()["output"] + r.json()["error"]
        assert "hunter2" not in text and os.environ["HOME"] not in text
        assert line.split()[1] in text, (line, text)
    r = client.post("/api/command", json={"line": 'echo "open'},
                    headers=ORIGIN)
    assert (r.status_code, r.json()["error"]) == (
        409, "unterminated quoted string\n")


@pytest.mark.parametrize("line", ["loadusr -W sleep 100", "waitusr x",
                                  "source /etc/passwd",
                                  "save all /tmp/halsdk-web-save"])
def test_the_command_line_starts_no_program_and_touches_no_file(
        client, line):
    r = client.post("/api/command", json={"line": line}, headers=ORIGIN)
    assert r.status_code == 403
    assert "not from the web workbench" in r.json()["error"]


def test_a_change_must_be_json_from_this_origin(client, hal):
    r = client.post("/api/setp", data={"name": "and2.0.in1", "value": "1"},
                    headers=ORIGIN)                 # a form
    assert r.status_code == 400
    r = client.post("/api/setp", json={"name": "and2.0.in1", "value": "1"},
                    headers={"origin": "http://evil.example"})
    assert r.status_code == 403
    r = client.post("/api/setp", content=b"[1]", headers={
        **ORIGIN, "content-type": "application/json"})
    assert r.status_code == 400
    r = post(client, "setp", name=["and2.0.in1"], value="1")
    assert r.status_code == 400
    assert post(client, "frob", x="1").status_code == 404
    assert hal.getp("and2.0.in1") is False


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=st.text(alphabet=NAME_CHARS, min_size=1, max_size=40).filter(
    lambda n: not (n.startswith(".") or n.endswith(".") or ".." in n)))
def test_any_name_is_data(client, hal, name):
    """A signal of any name the core accepts is listed, shown and set by
    its name as it is: never parsed as HAL language, a glob or HTML."""
    if hal.find("signal", name) is None:
        hal.newsig(name, "s32")
    value = len(name)
    r = post(client, "sets", name=name, value=str(value))
    assert r.json() == {"ok": True, "output": "", "error": ""}
    assert hal.gets(name) == value
    assert name in [s["name"] for s in client.get("/api/tree").json()[
        "signals"]]
    d = client.get("/api/item", params={"kind": "signal",
                                        "name": name}).json()
    assert (d["name"], d["value"]) == (name, str(value))
    hal.delsig(name)


def test_the_page_puts_no_data_into_html():
    """The page writes names with textContent and attributes only."""
    script = (resources.files("halsdk.web") / "static" / "show.js"
              ).read_text(encoding="utf-8")
    for sink in ("innerHTML", "outerHTML", "insertAdjacentHTML",
                 "document.write", "eval(", "new Function"):
        assert sink not in script, sink


def test_the_static_files_are_package_data():
    """A wheel (not only the checkout) carries every file of the page."""
    # (read as text: tomllib is Python 3.11+, halsdk supports 3.9)
    text = repo_path("pyproject.toml").read_text(encoding="utf-8")
    [line] = [t for t in text.splitlines()
              if t.startswith('"halsdk.web" = [')]
    globs = json.loads(line.partition("=")[2])
    folder = resources.files("halsdk.web") / "static"
    names = sorted(p.name for p in folder.iterdir())
    assert {"index.html", "show.js", "style.css"} <= set(names)
    suffixes = {g.rpartition(".")[2] for g in globs}
    assert all(n.rpartition(".")[2] in suffixes for n in names), names


# ---------------------------------------------------------------- live values

def _receive(ws, timeout: float = 10.0):
    """The next message of a websocket session, or a failure after
    ``timeout`` s (the test client's receive has no time limit)."""
    with ThreadPoolExecutor(1) as pool:
        return pool.submit(ws.receive_json).result(timeout=timeout)


def test_the_websocket_pushes_a_changed_value(client, hal):
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        ws.send_text(json.dumps({"watch": ["pin:and2.0.in1", "signal:x-in",
                                           "pin:no.such", "bogus"]}))
        first = _receive(ws)["values"]
        assert first == {"pin:and2.0.in1": "FALSE", "signal:x-in": "FALSE",
                         "pin:no.such": None, "bogus": None}
        hal.setp("and2.0.in1", True)
        assert _receive(ws) == {"values": {"pin:and2.0.in1": "TRUE"}}
        hal.sets("x-in", True)
        assert _receive(ws) == {"values": {"signal:x-in": "TRUE"}}
        ws.send_text("not json")                # ignored
        hal.newsig("late", "float")             # the tree changed
        assert _receive(ws)["tree"]["counts"]["signal"] == 2


@pytest.mark.parametrize("headers", [
    {"origin": "http://evil.example"},
    {"origin": "http://127.0.0.1:9999"},
    {"origin": "null"},
    {},
])
def test_a_websocket_from_another_origin_is_refused(client, headers):
    with pytest.raises(WebSocketDisconnect) as exc:
        with client.websocket_connect(WS, headers=headers) as ws:
            ws.receive_json()
    assert exc.value.code == 1008


def test_a_websocket_without_the_token_is_refused(hal):
    _machine(hal)
    with TestClient(create_app(hal, token=TOKEN), base_url=BASE) as c:
        with pytest.raises(WebSocketDisconnect):
            with c.websocket_connect(WS, headers=ORIGIN) as ws:
                ws.receive_json()
        with c.websocket_connect(WS + "?token=" + TOKEN, headers=ORIGIN) as ws:
            ws.send_text(json.dumps({"watch": ["pin:and2.0.in0"]}))
            assert _receive(ws) == {"values": {"pin:and2.0.in0": "FALSE"}}
