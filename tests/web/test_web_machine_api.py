"""The Machine page's API (halsdk.web.machine) through starlette's
TestClient, against the simulated mill run by ``halsdk run`` on a private
instance (quick homing): the status, the commands and their refusals,
read-only, the error channel, the program's preview and the websocket.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Iterator
from typing import Any

import pytest
from helpers import repo_path
from helpers.polling import wait_for
from helpers.running_machine import running_machine
from hypothesis import given, settings
from hypothesis import strategies as st
from starlette.testclient import TestClient

from halsdk.hal import Hal
from halsdk.web import machine as page
from halsdk.web.app import create_app

TOKEN = "machine-token-0123456789"
BASE = "http://127.0.0.1:8124"
ORIGIN = {"origin": BASE}
WS = "ws://127.0.0.1:8124/ws/machine"

@pytest.fixture(scope="module")
def mill(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    folder = tmp_path_factory.mktemp("mill")
    shutil.copy(repo_path("examples", "mill", "demo.ngc"), folder)
    with running_machine(folder) as m:
        yield m


def _client(instance: str, read_only: bool = False
            ) -> Iterator[TestClient]:
    hal = Hal(instance, create=False)
    try:
        app = create_app(hal, token=TOKEN, read_only=read_only)
        with TestClient(app, base_url=BASE) as c:
            c.get("/?token=" + TOKEN)
            yield c
    finally:
        hal.close()


@pytest.fixture(scope="module")
def client(mill) -> Iterator[TestClient]:
    yield from _client(mill.instance)


def status(client: TestClient) -> dict[str, Any]:
    return client.get("/api/machine/status").json()


def connected(client: TestClient) -> dict[str, Any]:
    assert wait_for(lambda: status(client)["connected"], 20), status(client)
    return status(client)


def post(client: TestClient, action: str, **body: Any) -> Any:
    return client.post(f"/api/machine/{action}", json=body, headers=ORIGIN)


def ready(client: TestClient) -> dict[str, Any]:
    """The machine on and homed."""
    st = connected(client)
    if st["estop"]:
        assert post(client, "estop-reset").status_code == 200
    if not status(client)["enabled"]:
        assert post(client, "on").status_code == 200
    if not status(client)["all_homed"]:
        assert post(client, "home", joint=-1).status_code == 200
        assert wait_for(lambda: status(client)["all_homed"], 30)
    return status(client)


def idle(client: TestClient) -> bool:
    st = status(client)
    return st["interp"] == "IDLE" and st["velocity"] == 0


@pytest.mark.slow
def test_the_status_of_the_mill(client):
    st = connected(client)
    assert st["axes"] == "XYZ"
    assert len(st["machine"]) == len(st["work"]) == 3
    assert len(st["joints"]) == 3
    assert st["state"] in ("ESTOP", "ESTOP_RESET", "ON")
    assert st["mode"] in ("MANUAL", "AUTO", "MDI")
    assert st["task_pid"] > 0


@pytest.mark.slow
def test_a_command_in_estop_is_refused_with_the_reason(client):
    connected(client)
    assert post(client, "estop").status_code == 200
    assert wait_for(lambda: status(client)["estop"], 10)
    r = post(client, "mdi", line="G0 X1")
    assert r.status_code == 409
    assert r.json()["ok"] is False
    assert "estop" in r.json()["error"].lower().replace("-", "")
    # the refusal is on the error channel too
    assert wait_for(lambda: any(
        m["kind"] == "error" for m in
        client.get("/api/machine/messages").json()["messages"]), 10)


@pytest.mark.slow
def test_home_and_mdi_move_and_the_dro_follows(client):
    ready(client)
    assert all(j["homed"] for j in status(client)["joints"])
    r = post(client, "mdi", line="G0 X10 Y5 Z-1")
    assert r.status_code == 200, r.text
    assert wait_for(lambda: status(client)["machine"] == [10, 5, -1], 30)
    st = status(client)
    assert st["mode"] == "MDI" and st["mdi"] == "G0 X10 Y5 Z-1"
    # a work offset: the work coordinates move, the machine ones do not
    assert wait_for(lambda: idle(client), 30)
    assert post(client, "mdi", line="G10 L2 P1 X4 Y-2 Z0").status_code \
        == 200
    assert wait_for(lambda: status(client)["work"] == [6, 7, -1], 30)
    assert status(client)["machine"] == [10, 5, -1]
    assert wait_for(lambda: idle(client), 30)
    assert post(client, "mdi", line="G10 L2 P1 X0 Y0 Z0").status_code \
        == 200
    assert wait_for(lambda: status(client)["work"] == [10, 5, -1], 30)


@pytest.mark.slow
def test_jog_by_an_increment(client):
    ready(client)
    assert wait_for(lambda: idle(client), 30)
    before = status(client)["machine"][0]
    r = post(client, "jog", axis="x", velocity=20, distance=2)
    assert r.status_code == 200, r.text
    assert status(client)["mode"] == "MANUAL"
    assert wait_for(lambda: abs(status(client)["machine"][0] - before - 2)
                    < 1e-6, 30)
    r = post(client, "jog", axis="Y", velocity=-20)     # continuous
    assert r.status_code == 200, r.text
    assert wait_for(lambda: status(client)["velocity"] > 0, 10)
    assert post(client, "jog-stop", axis="Y").status_code == 200
    assert wait_for(lambda: idle(client), 10)


@pytest.mark.slow
def test_a_page_going_away_stops_its_continuous_jog(client):
    ready(client)
    assert wait_for(lambda: idle(client), 30)
    # far from the limits: X -1 to 201 (examples/mill/mill.ini)
    assert post(client, "mdi", line="G53 G0 X100").status_code == 200
    assert wait_for(lambda: status(client)["machine"][0] == 100, 30)
    assert wait_for(lambda: idle(client), 30)
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        ws.receive_json()
        r = post(client, "jog", axis="X", velocity=-2)
        assert r.status_code == 200, r.text
        assert wait_for(lambda: status(client)["velocity"] > 0, 10)
    # the page closed without its jog-stop: the workbench stops the jog
    assert wait_for(lambda: idle(client), 10)
    assert client.app.state.workbench.pages["machine"].jogging == set()
    assert status(client)["machine"][0] > 80    # stopped, not at a limit


@pytest.mark.slow
def test_bad_requests(client):
    connected(client)
    assert post(client, "mdi").status_code == 400
    assert "'line'" in post(client, "mdi").json()["error"]
    assert post(client, "mdi", line="G0\nM2").status_code == 400
    assert post(client, "feed", scale=7).status_code == 400
    assert post(client, "jog", axis="Q", velocity=1).status_code == 400
    assert post(client, "home", joint="all").status_code == 400
    r = post(client, "open", path="/no/such/program.ngc")
    assert r.status_code == 400 and "no such file" in r.json()["error"]
    assert post(client, "reboot").status_code == 404
    # another site's page cannot send a command
    r = client.post("/api/machine/estop", json={},
                    headers={"origin": "http://evil.example"})
    assert r.status_code == 403


@pytest.mark.slow
def test_overrides(client):
    connected(client)
    assert post(client, "feed", scale=0.5).status_code == 200
    assert wait_for(lambda: status(client)["feedrate"] == 0.5, 10)
    assert post(client, "spindle-override", scale=1.5).status_code == 200
    assert wait_for(
        lambda: status(client)["spindle"]["override"] == 1.5, 10)
    assert post(client, "feed", scale=1).status_code == 200
    assert post(client, "spindle-override", scale=1).status_code == 200


@pytest.mark.slow
def test_open_run_pause_resume_abort_a_program(client, mill):
    ready(client)
    assert wait_for(lambda: idle(client), 30)
    path = str(mill.ini.parent / "demo.ngc")
    r = post(client, "open", path=path)
    assert r.status_code == 200, r.text
    assert wait_for(lambda: status(client)["file"] == path, 10)
    preview = client.get("/api/machine/preview").json()
    assert preview["file"] == path and preview["error"] == ""
    kinds = {p["kind"] for p in preview["paths"]}
    assert kinds == {"rapid", "feed"}
    xs = [x for p in preview["paths"] for x in p["points"][0::2]]
    ys = [y for p in preview["paths"] for y in p["points"][1::2]]
    # the outline: work X0..60 Y0..60 at the work origin X50 Y40
    assert min(xs) <= 50 and max(xs) >= 110 - 1e-6
    assert max(ys) >= 100 - 1e-6
    assert post(client, "run").status_code == 200
    assert wait_for(lambda: status(client)["interp"] != "IDLE", 10)
    assert post(client, "pause").status_code == 200
    assert wait_for(lambda: status(client)["paused"], 10)
    assert post(client, "resume").status_code == 200
    assert wait_for(lambda: not status(client)["paused"], 10)
    assert post(client, "abort").status_code == 200
    assert wait_for(lambda: status(client)["interp"] == "IDLE", 10)


@pytest.mark.slow
def test_the_websocket_pushes_the_status_and_messages(client):
    connected(client)
    assert page.PUSH_PERIOD <= 0.1        # 10 a second at least
    with client.websocket_connect(WS, headers=ORIGIN) as ws:
        beats = [ws.receive_json()["status"]["heartbeat"]
                 for _ in range(10)]
        assert beats == sorted(beats) and beats[-1] > beats[0]
        post(client, "estop")
        post(client, "mdi", line="G0 X0")           # refused: a message
        for _ in range(200):
            message = ws.receive_json()
            if any("refused" in m["text"]
                   for m in message.get("messages", [])):
                break
        else:
            pytest.fail("no message of the error channel came")


@pytest.mark.slow
def test_read_only_refuses_every_command(mill):
    for c in _client(mill.instance, read_only=True):
        before = connected(c)
        for action in page.ACTIONS:
            r = post(c, action, line="G0 X1", joint=0, axis="X",
                     velocity=1, scale=1, path="/tmp/x.ngc")
            assert r.status_code == 403, action
            assert "read-only" in r.json()["error"]
        after = status(c)
        assert (after["state"], after["mode"], after["machine"]) == \
            (before["state"], before["mode"], before["machine"])


# ----------------------------------------------------------- the preview


@settings(max_examples=200, deadline=None)
@given(cx=st.floats(-100, 100), cy=st.floats(-100, 100),
       r=st.floats(0.1, 100), a0=st.floats(-math.pi, math.pi),
       a1=st.floats(-math.pi, math.pi), turn=st.sampled_from([-2, -1, 1, 2]))
def test_arc_points_are_on_the_arc_in_its_direction(cx, cy, r, a0, a1,
                                                     turn):
    start = (cx + r * math.cos(a0), cy + r * math.sin(a0))
    end = (cx + r * math.cos(a1), cy + r * math.sin(a1))
    pts = page._arc_points(start, end, (cx, cy), turn)
    assert (pts[-2], pts[-1]) == end
    angles = [math.atan2(start[1] - cy, start[0] - cx)]
    for x, y in zip(pts[0::2], pts[1::2]):
        assert math.isclose(math.hypot(x - cx, y - cy), r, rel_tol=1e-6,
                            abs_tol=1e-6)
        angles.append(math.atan2(y - cy, x - cx))
    # every step turns the way the arc goes, less than half a turn
    for before, after in zip(angles, angles[1:]):
        step = (after - before + math.pi) % (2 * math.pi) - math.pi
        assert step * turn >= -1e-9
    # the sweep: at least (|turn| - 1) full turns
    total = sum(abs((b - a + math.pi) % (2 * math.pi) - math.pi)
                for a, b in zip(angles, angles[1:]))
    assert total >= 2 * math.pi * (abs(turn) - 1) - 1e-6


def test_preview_paths_join_moves_of_one_kind():
    from halsdk.gcode import canon as C
    z = (0.0,) * 7
    moves = [C.StraightTraverse((1.0, 0.0, *z)),
             C.StraightTraverse((1.0, 1.0, *z)),
             C.StraightFeed((2.0, 1.0, *z), 100.0),
             C.Dwell(1.0),
             C.ArcFeed((2.0, 3.0, *z), (2.0, 2.0), 17, 1, 100.0)]
    paths = page.preview_paths(moves, (0.0, 0.0))
    assert [p["kind"] for p in paths] == ["rapid", "feed"]
    assert paths[0]["points"] == [0, 0, 1, 0, 1, 1]
    assert paths[1]["points"][:4] == [1, 1, 2, 1]
    assert paths[1]["points"][-2:] == [2, 3]
    # a counter-clockwise half circle from (2, 1) around (2, 2): x > 2
    assert max(paths[1]["points"][4::2]) > 2.9


def test_the_preview_reads_programs_as_the_machine_does(tmp_path):
    """The preview uses the machine's [RS274NGC] settings: subroutines on
    SUBROUTINE_PATH, REMAPped codes and #<_ini[...]> values."""
    from types import SimpleNamespace
    (tmp_path / "subs").mkdir()
    (tmp_path / "subs" / "square.ngc").write_text(
        "o<square> sub\nG1 X#1 F100\nG1 Y#1\no<square> endsub\nM2\n")
    (tmp_path / "subs" / "m400.ngc").write_text(
        "o<m400> sub\nG0 X-#<p>\no<m400> endsub\nM2\n")
    ini = tmp_path / "m.ini"
    ini.write_text("[TRAJ]\nLINEAR_UNITS = mm\n[RS274NGC]\n"
                   "SUBROUTINE_PATH = subs\n"
                   "REMAP = M400 modalgroup=10 argspec=P ngc=m400\n"
                   "[PART]\nSIZE = 12\n")
    prog = tmp_path / "p.ngc"
    prog.write_text("G21 G90\no<square> call [#<_ini[part]size>]\n"
                    "M400 P3\nM2\n")
    st = SimpleNamespace(position=(0.0,) * 9, ini_filename=str(ini),
                         g5x_index=1, g5x_offset=(0.0,) * 9,
                         g92_offset=(0.0,) * 9)
    preview = page.make_preview(str(prog), st)
    assert preview["error"] == ""
    points = [(x, y) for p in preview["paths"]
              for x, y in zip(p["points"][0::2], p["points"][1::2])]
    assert (12, 0) in points and (12, 12) in points and (-3, 12) in points
    # without the machine's INI file the same program is an error
    st.ini_filename = ""
    assert "square" in page.make_preview(str(prog), st)["error"]
