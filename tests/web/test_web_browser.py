"""The Show page in a real browser: Debian's chromium driven by Playwright
(its Python API, the system chromium as the executable: no browser is
downloaded), against ``halsdk web`` attached to the test's instance.

Without chromium or playwright these tests are skipped, except in CI
(``CI=true``), where ``.ci/run`` installs chromium and their absence is an
error.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from helpers.polling import wait_for
from helpers.web import serve, stop

from halsdk import halcmd


@pytest.fixture
def machine(hal):
    hal.newthread("servo", 1_000_000)
    hal.loadrt("and2", count=2)
    hal.addf("and2.0", "servo")
    hal.net("x-in", "and2.0.in0")
    return hal


@pytest.fixture
def workbench(machine, tmp_path) -> Iterator[str]:
    proc, url = serve(tmp_path)
    try:
        yield url
    finally:
        stop(proc)


@pytest.fixture
def page(browser, workbench) -> Iterator[Any]:
    context = browser.new_context()
    pg = context.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda exc: errors.append(str(exc)))
    pg.goto(workbench)
    pg.locator("#link", has_text="live").wait_for(timeout=20_000)
    try:
        yield pg
    finally:
        context.close()
    assert errors == []


def _open(page, *labels: str) -> None:
    """Open the groups of the tree with these labels, in turn."""
    for label in labels:
        page.locator("#tree summary", has_text=label).first.click()


def _row(page, key: str):
    return page.locator(f'#tree [data-item="{key}"]')


def test_the_tree_lists_the_pins(page, machine):
    assert page.url.endswith("/")                   # token out of the URL
    _open(page, "Pins", "and2 (", "and2.0 (")
    for name in ("and2.0.in0", "and2.0.in1", "and2.0.out"):
        row = _row(page, f"pin:{name}")
        row.wait_for()
        assert row.locator(".name").inner_text() == name
    assert "x-in" in _row(page, "pin:and2.0.in0").inner_text()
    assert _row(page, "pin:and2.0.in1").locator(".value").inner_text() \
        == "FALSE"


def test_a_value_changes_live(page, machine):
    page.fill("#search", "and2.0.in1")
    value = _row(page, "pin:and2.0.in1").locator(".value")
    value.wait_for()
    assert value.inner_text() == "FALSE"
    machine.setp("and2.0.in1", True)
    page.wait_for_function(
        "() => document.querySelector('#tree [data-item=\"pin:and2.0.in1\"]"
        " .value').textContent === 'TRUE'", timeout=10_000)


def test_a_setp_from_the_page_reaches_the_pin(page, machine):
    page.fill("#search", "and2.1.in0")
    _row(page, "pin:and2.1.in0").click()
    form = page.locator("#detail form.act", has_text="setp")
    form.locator("input[name=value]").fill("1")
    form.locator("button").click()
    assert wait_for(lambda: machine.getp("and2.1.in0") is True, timeout=10)
    page.locator("#message", has_text="setp: done").wait_for()


def test_a_refusal_shows_halcmds_words(page, machine):
    page.fill("#cmdline", "setp and2.0.out 1")
    page.click("#cmdform button")
    page.locator("#cmdout.error").wait_for()
    words: list[str] = []                   # what halcmd says
    halcmd.command(machine, "setp and2.0.out 1", out=words.append,
                   err=words.append)
    assert page.locator("#cmdout").text_content() == "".join(words) == \
        "pin 'and2.0.out' is not writable\n"
    expected = machine.command("show pin and2.0.out")
    page.fill("#cmdline", "show pin and2.0.out")
    page.click("#cmdform button")
    page.wait_for_function(
        "(t) => document.querySelector('#cmdout').textContent === t",
        arg=expected, timeout=10_000)


def test_names_are_shown_as_text(page, machine):
    machine.newsig("<b>bold</b>&amp;", "bit")
    page.reload()
    page.locator("#link", has_text="live").wait_for(timeout=20_000)
    page.fill("#search", "<b>")
    row = _row(page, "signal:<b>bold</b>&amp;")
    row.wait_for()
    assert row.locator(".name").inner_text() == "<b>bold</b>&amp;"
    assert page.locator("#tree b").count() == 0


def test_a_wrong_token_is_refused(browser, workbench):
    base = workbench.partition("/?")[0]
    context = browser.new_context()
    try:
        pg = context.new_page()
        response = pg.goto(base + "/?token=wrong")
        assert response is not None and response.status == 403
        assert "token" in pg.content()
        response = pg.goto(base + "/")
        assert response is not None and response.status == 403
    finally:
        context.close()


def test_read_only_refuses_a_setp(browser, machine, tmp_path):
    proc, url = serve(tmp_path, "--read-only")
    try:
        context = browser.new_context()
        pg = context.new_page()
        pg.goto(url)
        pg.locator("#readonly").wait_for(state="visible", timeout=20_000)
        pg.fill("#search", "and2.1.in1")
        _row(pg, "pin:and2.1.in1").click()
        pg.locator("#detail h2").wait_for()
        assert not pg.locator("#detail form.act").first.is_visible()
        status = pg.evaluate("""async () => {
            const r = await fetch('/api/setp', {method: 'POST',
                headers: {'Content-Type': 'application/json'},
                body: JSON.stringify({name: 'and2.1.in1', value: '1'})});
            return [r.status, (await r.json()).error];
        }""")
        assert status[0] == 403 and "read-only" in status[1]
        context.close()
    finally:
        stop(proc)
    assert machine.getp("and2.1.in1") is False


def test_the_picture_of_the_docs(page, machine, tmp_path):
    """The Show page as docs/web.rst shows it; written to the folder
    ``$HALSDK_DOCS_SCREENSHOTS`` names, when set (``docs`` refreshes the
    picture of the page)."""
    machine.loadrt("siggen")
    machine.addf("siggen.0.update", "servo", 1)
    machine.net("wave", "siggen.0.sine")
    machine.start()
    page.set_viewport_size({"width": 1200, "height": 700})
    page.reload()
    page.locator("#link", has_text="live").wait_for(timeout=20_000)
    _open(page, "Pins", "siggen (", "siggen.0 (")
    _row(page, "pin:siggen.0.sine").click()
    page.locator("#detail button", has_text="watch").click()
    page.fill("#cmdline", "show thread")
    page.click("#cmdform button")
    page.locator("#cmdout", has_text="siggen.0.update").wait_for()
    # the sine moves: its value on the page changes while we look
    cell = page.locator('#watch [data-item="pin:siggen.0.sine"] .value')
    first = cell.text_content()
    page.wait_for_function(
        "(t) => document.querySelector('#watch .value').textContent !== t",
        arg=first, timeout=10_000)
    picture = tmp_path / "web-show.png"
    page.screenshot(path=str(picture))
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    folder = os.environ.get("HALSDK_DOCS_SCREENSHOTS")
    if folder:
        shutil.copyfile(picture, Path(folder) / "web-show.png")
