"""The Machine page in a real browser (Debian's chromium under
Playwright): ``halsdk web mill.ini`` starts the simulated mill (a copy
with quick homing, on a private instance) and the workbench together; the
page homes it, runs an MDI line and the DRO shows the move, runs the demo
program with its backplot, and the process ends cleanly on SIGTERM.

The picture of docs/web.rst is written to the folder that
``$HALSDK_DOCS_SCREENSHOTS`` names, when set.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from helpers import repo_path
from helpers.running_machine import mill_ini
from helpers.web import serve, stop

from halsdk.testing import private_instance_name

pytestmark = pytest.mark.slow


def segments(instance: str) -> list[str]:
    return [n for n in os.listdir("/dev/shm")
            if n.startswith(f"halsdk-{os.getuid()}-") and
            n.endswith(f"-{instance}")]


@pytest.fixture
def mill(tmp_path) -> Iterator[tuple[str, str, Path]]:
    """``halsdk web mill.ini``: (url, instance, folder); stopped with
    SIGTERM at the end (status 0), leaving nothing in /dev/shm."""
    shutil.copy(repo_path("examples", "mill", "demo.ngc"), tmp_path)
    instance = private_instance_name()
    proc, url = serve(tmp_path, str(mill_ini(tmp_path)), "--instance",
                      instance)
    try:
        yield url, instance, tmp_path
    finally:
        stop(proc)                  # SIGTERM; asserts status 0
    assert segments(instance) == []


def _open(browser: Any, url: str) -> tuple[Any, Any, list[str]]:
    context = browser.new_context(viewport={"width": 1280, "height": 820})
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(url)                      # the token into the cookie
    page.goto(url.split("/?")[0] + "/machine")
    page.locator("#link", has_text="live").wait_for(timeout=20_000)
    page.locator("#state", has_text="E").wait_for(timeout=20_000)
    return context, page, errors


def _dro(page: Any, axis: str, kind: str) -> Any:
    return page.locator(f'#dro tr[data-axis="{axis}"] td.{kind}')


def test_home_mdi_program_and_backplot(browser, mill, tmp_path):
    url, instance, folder = mill
    context, page, errors = _open(browser, url)
    try:
        assert page.locator("#instance").inner_text() == \
            f"instance {instance}"
        assert page.locator("#nomachine").is_hidden()
        page.click("#estop")                    # reset the E-stop
        page.locator("#state", has_text="ESTOP_RESET").wait_for()
        page.click("#power")
        page.locator("#state", has_text="ON").wait_for()
        page.click("#home-all")
        for axis in "XYZ":
            page.locator(f'#dro tr[data-axis="{axis}"] td.homed',
                         has_text="✓").wait_for(timeout=30_000)
        page.fill("#mdi-line", "G0 X10")
        page.click("#mdi-send")
        _dro(page, "X", "machine").filter(has_text="10.000").wait_for(
            timeout=30_000)
        assert _dro(page, "Y", "machine").inner_text() == "0.000"
        page.locator("#mode", has_text="MDI").wait_for()
        # a refused command: its reason on the page, and on the error
        # channel's list
        page.fill("#mdi-line", "G0 X10 (a comment")
        page.click("#mdi-send")
        page.locator("#answer.error").wait_for(timeout=10_000)
        page.locator("#messages li").first.wait_for(timeout=10_000)
        # the task's rule: bad G-code turns the machine off; on again
        page.locator("#state", has_text="ESTOP_RESET").wait_for()
        page.click("#power")
        page.locator("#state", has_text="ON").wait_for()
        # the demo program: its preview, then the tool path as it runs
        page.fill("#program-path", str(folder / "demo.ngc"))
        page.click("#program-open")
        page.locator("#program-file", has_text="demo.ngc").wait_for(
            timeout=10_000)
        page.wait_for_function(
            "() => preview.paths.length > 0", timeout=20_000)
        page.click("#program-run")
        page.locator("#interp", has_text="READING").wait_for(timeout=10_000)
        # until it reached the arc of the outline (line 16)
        page.wait_for_function(
            "() => Number(document.querySelector('#program-line')"
            ".textContent) >= 16 || status.interp === 'IDLE'",
            timeout=90_000)
        assert page.evaluate("trail.length") > 10
        picture = tmp_path / "web-machine.png"
        page.screenshot(path=str(picture), full_page=True)
        assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        target = os.environ.get("HALSDK_DOCS_SCREENSHOTS")
        if target:
            shutil.copyfile(picture, Path(target) / "web-machine.png")
        page.click("#program-abort")
        page.locator("#interp", has_text="IDLE").wait_for(timeout=20_000)
    finally:
        context.close()
    assert errors == []


def test_without_a_task_controller_the_page_says_so(browser, hal,
                                                    tmp_path):
    hal.newthread("servo", 1_000_000)
    proc, url = serve(tmp_path)             # attached to the test's HAL
    try:
        context = browser.new_context()
        page = context.new_page()
        page.goto(url)
        page.goto(url.split("/?")[0] + "/machine")
        page.locator("#link", has_text="live").wait_for(timeout=20_000)
        banner = page.locator("#nomachine")
        banner.wait_for(timeout=20_000)
        assert "No task controller" in banner.inner_text()
        page.locator("#nomachine-why", has_text="no task").wait_for()
        assert "off" in (page.locator("#panel").get_attribute("class")
                         or "")
        context.close()
    finally:
        stop(proc)


def test_read_only_refuses_a_command(browser, tmp_path):
    instance = private_instance_name()
    proc, url = serve(tmp_path, str(mill_ini(tmp_path)), "--instance",
                      instance, "--read-only")
    try:
        context, page, errors = _open(browser, url)
        assert page.locator("#readonly").is_visible()
        assert page.locator("#home-all").is_hidden()
        answer = page.evaluate("""async () => {
            const r = await fetch('/api/machine/estop-reset', {
                method: 'POST', headers: {'Content-Type': 'application/json'},
                body: '{}'});
            return [r.status, (await r.json()).error];
        }""")
        assert answer[0] == 403 and "read-only" in answer[1]
        page.wait_for_timeout(300)
        assert page.locator("#state").inner_text() == "ESTOP"
        context.close()
        assert errors == []
    finally:
        stop(proc)
    assert segments(instance) == []
