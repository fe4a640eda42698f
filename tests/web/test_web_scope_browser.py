"""The Scope page in a real browser (Debian's chromium under Playwright)
against ``halsdk web`` attached to the test's instance, whose threads
run: the scope triggers on a siggen square wave and shows the edge at
the trigger position; read-only refuses starting; nothing is left in
the instance after a stop, a closed page or a killed server.

Skipped without chromium or playwright, except in CI (see
helpers.web)."""

from __future__ import annotations

import os
import shutil
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from helpers.polling import wait_for
from helpers.web import serve, stop

pytestmark = pytest.mark.slow


def _recorders(hal) -> list[str]:
    # a snapshot: the server may remove a recorder while we look
    return [c.name for c in hal.snapshot("component")
            if c.name.startswith(hal.RECORDER_PREFIX)]


@pytest.fixture
def machine(hal):
    hal.newthread("servo", 1_000_000)
    hal.loadrt("siggen")
    hal.addf("siggen.0.update", "servo")
    hal.setp("siggen.0.frequency", 10.0)        # 100 samples a period
    hal.start()
    try:
        yield hal
    finally:
        hal.stop()


@pytest.fixture
def workbench(machine, tmp_path) -> Iterator[tuple[Any, str]]:
    proc, url = serve(tmp_path)
    try:
        yield proc, url
    finally:
        if proc.poll() is None:
            stop(proc)


def _open(browser, url: str):
    context = browser.new_context(viewport={"width": 1400, "height": 800})
    pg = context.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda exc: errors.append(str(exc)))
    pg.goto(url.replace("/?", "/scope?"))
    pg.locator("#link", has_text="live").wait_for(timeout=20_000)
    return context, pg, errors


def _channel(pg, index: int, name: str) -> None:
    box = pg.locator(f'#channels input.name[data-ch="{index}"]')
    box.fill(name)
    box.dispatch_event("change")


def test_the_scope_triggers_on_a_square_wave(browser, machine, workbench):
    _, url = workbench
    context, pg, errors = _open(browser, url)
    try:
        _channel(pg, 0, "siggen.0.square")
        _channel(pg, 1, "siggen.0.sine")
        pg.select_option("#trigger", "0")
        pg.fill("#length", "300")
        pg.fill("#position", "30")
        pg.fill("#level", "0")
        pg.locator("#channels input.scale").nth(0).fill("0.5")
        pg.click("#run")
        pg.wait_for_function(
            "() => window.scope.frame && window.scope.frame.trigger !== null",
            timeout=20_000)
        frame = pg.evaluate("window.scope.frame")
        square = frame["channels"][0]
        trig = frame["trigger"]
        assert len(square) == 300 and trig == round(0.3 * 299)
        # the edge at the trigger position, within one sample
        assert square[trig - 1] < 0 <= square[trig]
        assert frame["dt"] == pytest.approx(0.001)
        assert pg.get_attribute("#plot", "data-trigger") == str(trig)
        assert len(_recorders(machine)) == 1
        # cursors: delta time and value between two clicks
        box = pg.locator("#plot").bounding_box()
        assert box is not None
        pg.mouse.click(box["x"] + box["width"] * 0.2, box["y"] + 50)
        pg.keyboard.down("Shift")
        pg.mouse.click(box["x"] + box["width"] * 0.7, box["y"] + 50)
        pg.keyboard.up("Shift")
        text = pg.locator("#cursors").text_content() or ""
        assert "Δt 150 ms" in text and "Δ1" in text
        csv = pg.evaluate("window.scope.toCsv()").splitlines()
        assert csv[0] == '"time","siggen.0.square","siggen.0.sine"'
        assert len(csv) == 301
        assert float(csv[1 + trig].split(",")[0]) == 0.0
        status = pg.evaluate("window.scope.status")
        assert status["lost"] == 0 and status["overruns"] == 0
        picture = Path(os.environ.get("TMPDIR", "/tmp")) / \
            f"web-scope-{os.getpid()}.png"
        pg.screenshot(path=str(picture))
        assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        folder = os.environ.get("HALSDK_DOCS_SCREENSHOTS")
        if folder:
            shutil.copyfile(picture, Path(folder) / "web-scope.png")
        picture.unlink()
        pg.click("#stop")
        assert wait_for(lambda: _recorders(machine) == [], timeout=10)
    finally:
        context.close()
    assert errors == []


def test_roll_streams_every_sample(browser, machine, workbench):
    _, url = workbench
    context, pg, errors = _open(browser, url)
    try:
        _channel(pg, 0, "siggen.0.sawtooth")
        pg.select_option("#mode", "roll")
        pg.fill("#length", "500")
        pg.click("#run")
        pg.wait_for_function(
            "() => window.scope.frame && "
            "window.scope.frame.channels[0].length === 500", timeout=20_000)
        status = pg.evaluate("window.scope.status")
        assert status["state"] == "roll" and status["lost"] == 0
    finally:
        context.close()
    # the page closed: its websocket, and so its recorder, went
    assert wait_for(lambda: _recorders(machine) == [], timeout=10)
    assert errors == []


def test_a_killed_server_leaves_a_recorder_the_next_one_sweeps(
        browser, machine, workbench):
    proc, url = workbench
    context, pg, _ = _open(browser, url)
    try:
        _channel(pg, 0, "siggen.0.square")
        pg.click("#run")
        pg.wait_for_function("() => window.scope.status && "
                             "window.scope.status.running", timeout=20_000)
        orphan = _recorders(machine)
        assert len(orphan) == 1
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    finally:
        context.close()
    assert _recorders(machine) == orphan        # no one removed it yet
    mine = machine.recorder(["siggen.0.square"], "servo", 64)
    assert _recorders(machine) == [mine]
    machine.recorder_delete(mine)


def test_read_only_refuses_starting(browser, machine, tmp_path):
    proc, url = serve(tmp_path, "--read-only")
    try:
        context, pg, errors = _open(browser, url)
        pg.locator("#readonly").wait_for(state="visible", timeout=20_000)
        assert not pg.locator("#run").is_visible()
        answer = pg.evaluate("""async () => {
            const r = await fetch('/api/scope/start', {method: 'POST',
                headers: {'Content-Type': 'application/json'},
                body: JSON.stringify({session: window.scope.session,
                    channels: ['siggen.0.square'], thread: 'servo'})});
            return [r.status, (await r.json()).error];
        }""")
        assert answer[0] == 403 and "read-only" in answer[1]
        context.close()
        assert errors == []
    finally:
        stop(proc)
    assert _recorders(machine) == []
