"""The Latency page in a real browser (Debian's chromium under
Playwright), against ``halsdk web`` attached to the test's instance: the
server is an attached process, so the test's threads and components are
made by the host over the request channel."""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from helpers.polling import wait_for
from helpers.web import serve, stop


def names(hal) -> dict[str, list[str]]:
    # records taken under the instance lock: a test being removed
    # meanwhile (by the server) does not make a listing fail
    return {kind + "s": sorted(r.name for r in hal.snapshot(kind))
            for kind in ("component", "thread", "function")}


@pytest.fixture
def machine(hal):
    """A user's running machine, which the latency test leaves alone."""
    hal.newthread("servo", 1_000_000)
    hal.loadrt("and2", count=1)
    hal.addf("and2.0", "servo")
    hal.start()
    return hal


@pytest.fixture
def workbench(machine, tmp_path) -> Iterator[str]:
    proc, url = serve(tmp_path)
    try:
        yield url
    finally:
        stop(proc)


def _open(browser, url: str) -> tuple[Any, Any, list[str]]:
    context = browser.new_context()
    pg = context.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda exc: errors.append(str(exc)))
    pg.goto(url)                            # the token: into the cookie
    pg.goto(url.partition("/?")[0] + "/latency")
    pg.locator("#link", has_text="live").wait_for(timeout=20_000)
    return context, pg, errors


def _numbers_are_live(pg) -> None:
    """Every thread has samples and a histogram that is not empty."""
    pg.wait_for_function("""() => {
        const rows = document.querySelectorAll('#figures tbody tr');
        const hists = document.querySelectorAll('#histograms canvas');
        return rows.length === 2 && hists.length === 2 &&
          [...rows].every((r) => Number(r.querySelector('.samples')
                                        .textContent) > 0) &&
          [...hists].every((c) => Number(c.dataset.total) > 0);
    }""", timeout=30_000)


def test_a_latency_test_runs_live_and_leaves_nothing(browser, workbench,
                                                     machine, tmp_path):
    before = names(machine)
    context, pg, errors = _open(browser, workbench)
    try:
        pg.set_viewport_size({"width": 1200, "height": 760})
        assert pg.locator("#status").text_content() == \
            "No latency test is running."
        pg.click("#start")
        _numbers_are_live(pg)
        assert {"latency-base", "latency-servo"} <= \
            set(names(machine)["threads"])
        assert "scheduling" in pg.locator("#sched").text_content()
        # live: the samples of the servo thread grow while we look
        cell = pg.locator('#figures tr[data-thread="latency-servo"] '
                          '.samples')
        first = int(cell.text_content())
        pg.wait_for_function(
            "(n) => Number(document.querySelector('#figures "
            "tr[data-thread=\"latency-servo\"] .samples').textContent) > n",
            arg=first, timeout=20_000)
        for row in pg.locator("#figures tbody tr").all():
            for cls in ("jitter", "min", "max", "avg", "sdev"):
                assert row.locator("." + cls).text_content() != "–"
        picture = tmp_path / "web-latency.png"
        pg.screenshot(path=str(picture))
        assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        folder = os.environ.get("HALSDK_DOCS_SCREENSHOTS")
        if folder:
            shutil.copyfile(picture, Path(folder) / "web-latency.png")
        pg.click("#stop")
        pg.locator("#status", has_text="No latency test").wait_for(
            timeout=20_000)
        assert pg.locator("#figures tbody tr").count() == 0
    finally:
        context.close()
    assert errors == []
    assert names(machine) == before
    assert machine.info()["threads_running"]    # the user's thread runs


@pytest.mark.slow                           # the server waits 5 s for a reload
def test_the_test_ends_when_the_page_goes(browser, workbench, machine):
    before = names(machine)
    context, pg, errors = _open(browser, workbench)
    pg.fill("#settings input[name=bins]", "20")
    pg.click("#start")
    _numbers_are_live(pg)
    context.close()                         # the page goes away
    assert errors == []
    assert wait_for(lambda: names(machine) == before, timeout=60)


def test_read_only_refuses_a_start(browser, machine, tmp_path):
    before = names(machine)
    proc, url = serve(tmp_path, "--read-only")
    try:
        context, pg, errors = _open(browser, url)
        pg.locator("#readonly").wait_for(state="visible", timeout=20_000)
        assert not pg.locator("#start").is_visible()
        status = pg.evaluate("""async () => {
            const r = await fetch('/api/latency/start', {method: 'POST',
                headers: {'Content-Type': 'application/json'},
                body: JSON.stringify({base: 0, servo: 1000000})});
            return [r.status, (await r.json()).error];
        }""")
        assert status[0] == 403 and "read-only" in status[1]
        context.close()
        assert errors == []
    finally:
        stop(proc)
    assert names(machine) == before
