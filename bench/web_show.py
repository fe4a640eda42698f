#!/usr/bin/env python3
"""The Show page with a big instance: 10,000 pins.

A private HAL instance with ``and2 count=2500`` (10,000 pins: in0, in1,
out and time each), a 1 kHz
thread running them, and ``halsdk web`` attached to it; Debian's
chromium (headless, under Playwright) opens the page.  It prints:

- **page load**: from the navigation to the tree drawn and the websocket
  live (the ``#link`` badge says "live");
- **tree JSON**: the size of ``/api/tree`` and the time the server takes
  to answer it;
- **search**: from typing a name into the search box to its rows shown;
- **live update**: from a ``setp`` in this process to the new value on
  the page, median of ``--updates`` changes of a visible pin;
- **server CPU**: the ``halsdk web`` process's CPU time per second of
  wall time, over ``--seconds`` with the page open and 50 pins visible.

Run: ``python bench/web_show.py [--pins 10000] [--seconds 10]``.  Needs
chromium and playwright (``pip install '.[test]'``).  The reference has
no browser workbench (its halshow is a Tk program), so there is no
column for it.
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import statistics
import subprocess
import sys
import time
import urllib.request
from typing import Any

import halsdk

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from thread_overhead import process_cpu  # noqa: E402

TOKEN = "bench-web-token"


def _serve(instance: str) -> tuple[subprocess.Popen, str]:
    exe = shutil.which("halsdk") or os.path.join(
        os.path.dirname(sys.executable), "halsdk")
    env = dict(os.environ, HALSDK_INSTANCE=instance)
    proc = subprocess.Popen([exe, "web", "--token", TOKEN], env=env,
                            stdout=subprocess.PIPE, text=True,
                            start_new_session=True)
    assert proc.stdout is not None
    for line in proc.stdout:
        if "http://" in line:
            return proc, line.strip()
    raise SystemExit("halsdk web did not start")


def measure(pins: int, seconds: float, updates: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        raise SystemExit("web_show: no chromium (apt-get install chromium)")
    instance = f"bench-web-{os.getpid()}"
    hal = halsdk.Hal(instance, create=True)
    figures: dict[str, Any] = {"pins": 0}
    try:
        hal.newthread("servo", 1_000_000)
        count = -(-pins // 4)            # and2: 4 pins each
        hal.loadrt("and2", count=count)
        for i in range(count):
            hal.addf(f"and2.{i}", "servo")
        figures["pins"] = len(hal.pins())
        hal.start()
        proc, url = _serve(instance)
        try:
            base = url.partition("/?")[0]
            t0 = time.perf_counter()
            req = urllib.request.Request(
                base + "/api/tree", headers={"Cookie": ""})
            req.full_url = base + "/api/tree?token=" + TOKEN
            with urllib.request.urlopen(req) as r:
                body = r.read()
            figures["tree_ms"] = (time.perf_counter() - t0) * 1e3
            figures["tree_kib"] = len(body) / 1024
            with sync_playwright() as p:
                browser = p.chromium.launch(executable_path=chromium,
                                            headless=True)
                page = browser.new_context().new_page()
                t0 = time.perf_counter()
                page.goto(url)
                page.locator("#tree summary", has_text="Pins").wait_for()
                page.locator("#link", has_text="live").wait_for()
                figures["load_ms"] = (time.perf_counter() - t0) * 1e3
                # a search for one component's pins
                t0 = time.perf_counter()
                page.fill("#search", f"and2.{count - 1}.")
                page.locator(f'#tree [data-item="pin:and2.{count - 1}.out"]'
                             ).wait_for()
                figures["search_ms"] = (time.perf_counter() - t0) * 1e3
                # live updates of a visible pin
                key = f"pin:and2.{count - 1}.in0"
                cell = page.locator(f'#tree [data-item="{key}"] .value')
                delays = []
                for n in range(updates):
                    want = "TRUE" if n % 2 == 0 else "FALSE"
                    t0 = time.perf_counter()
                    hal.setp(f"and2.{count - 1}.in0", n % 2 == 0)
                    page.wait_for_function(
                        "([el, want]) => el.textContent === want",
                        arg=[cell.element_handle(), want])
                    delays.append((time.perf_counter() - t0) * 1e3)
                figures["update_ms"] = statistics.median(delays)
                # CPU of the server with 50 pins on the screen
                page.fill("#search", "and2.1?.")
                page.wait_for_timeout(500)
                c0, w0 = process_cpu(proc.pid), time.monotonic()
                time.sleep(seconds)
                c1, w1 = process_cpu(proc.pid), time.monotonic()
                figures["server_cpu_pct"] = 100 * (c1 - c0) / (w1 - w0)
                browser.close()
        finally:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait(timeout=30)
    finally:
        hal.close()
    return figures


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--pins", type=int, default=10_000)
    p.add_argument("--seconds", type=float, default=10.0,
                   help="how long the server's CPU is measured")
    p.add_argument("--updates", type=int, default=20)
    a = p.parse_args(argv)
    f = measure(a.pins, a.seconds, a.updates)
    print(f"Show page, {f['pins']} pins in the instance")
    print(f"  /api/tree           {f['tree_kib']:8.0f} KiB in "
          f"{f['tree_ms']:.0f} ms")
    print(f"  page load           {f['load_ms']:8.0f} ms (to the tree "
          "drawn and live)")
    print(f"  search              {f['search_ms']:8.0f} ms (to the rows "
          "shown)")
    print(f"  live update         {f['update_ms']:8.0f} ms (setp to the "
          "page, median)")
    print(f"  server CPU          {f['server_cpu_pct']:8.1f} % of a core "
          "(50 pins visible)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
