"""Issue 20's "done when", as a user does it: ``halsdk web mill.ini`` on
an unchanged copy of the example mill (examples/mill), and all four pages
working on it in a real browser (Debian's chromium under Playwright):
Show lists the mill's pins, Scope records one, Machine shows the task
controller live and switches it on, Latency runs a test in the mill's
instance and removes it.  SIGTERM then ends it all with status 0 and
nothing left in /dev/shm.
"""

from __future__ import annotations

import os
import shutil
from typing import Any

import pytest
from helpers import repo_path
from helpers.web import serve, stop

from halsdk.testing import private_instance_name

pytestmark = pytest.mark.slow


def _segments(instance: str) -> list[str]:
    return [n for n in os.listdir("/dev/shm")
            if n.startswith(f"halsdk-{os.getuid()}-")
            and n.endswith(f"-{instance}")]


def _page(context: Any, url: str, path: str, errors: list[str]) -> Any:
    pg = context.new_page()
    pg.on("pageerror", lambda exc: errors.append(f"{path}: {exc}"))
    pg.goto(url.split("/?")[0] + path)
    pg.locator("#link", has_text="live").wait_for(timeout=30_000)
    return pg


def test_all_four_pages_on_the_example_mill(browser, tmp_path):
    mill = tmp_path / "mill"
    shutil.copytree(repo_path("examples", "mill"), mill)
    instance = private_instance_name()
    proc, url = serve(mill, "mill.ini", "--instance", instance)
    errors: list[str] = []
    try:
        context = browser.new_context(
            viewport={"width": 1400, "height": 850})
        first = context.new_page()
        first.goto(url)                 # the token into the cookie
        first.close()

        show = _page(context, url, "/", errors)
        show.fill("#search", "pid-x.")
        row = show.locator('#tree [data-item="pin:pid-x.output"]')
        row.wait_for(timeout=20_000)
        assert row.locator(".name").inner_text() == "pid-x.output"

        scope = _page(context, url, "/scope", errors)
        box = scope.locator('#channels input.name[data-ch="0"]')
        box.fill("pid-x.command")
        box.dispatch_event("change")
        scope.select_option("#mode", "roll")
        scope.click("#run")
        scope.wait_for_function(
            "() => window.scope.status && window.scope.status.samples > 200",
            timeout=30_000)
        assert scope.evaluate("window.scope.status.lost") == 0
        scope.click("#stop")

        machine = _page(context, url, "/machine", errors)
        machine.locator("#state", has_text="ESTOP").wait_for(
            timeout=30_000)
        assert machine.locator("#nomachine").is_hidden()
        for axis in "XYZ":
            assert machine.locator(f'#dro tr[data-axis="{axis}"]').count() \
                == 1
        machine.click("#estop")
        machine.locator("#state", has_text="ESTOP_RESET").wait_for()
        machine.click("#power")
        machine.locator("#state", has_text="ON").wait_for(timeout=20_000)

        latency = _page(context, url, "/latency", errors)
        latency.click("#start")
        latency.wait_for_function("""() => {
            const rows = document.querySelectorAll('#figures tbody tr');
            return rows.length === 2 && [...rows].every((r) =>
              Number(r.querySelector('.samples').textContent) > 0);
        }""", timeout=30_000)
        latency.click("#stop")
        latency.locator("#status", has_text="No latency test").wait_for(
            timeout=20_000)
        context.close()
    finally:
        stop(proc)                      # SIGTERM; asserts status 0
    assert errors == []
    assert _segments(instance) == []
