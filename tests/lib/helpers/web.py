"""The browser tests' tools: Debian's chromium driven by Playwright (its
Python API, the system chromium as the executable: nothing is
downloaded), and ``halsdk web`` served on the test's instance.

Without chromium or playwright the browser tests are skipped, except in
CI (``CI`` set, :func:`helpers.tools.unavailable`), where ``.ci/run``
installs chromium and their absence is an error.  Use: ``from
helpers.web import browser, serve, stop`` (``browser`` is a
module-scoped fixture).
"""

from __future__ import annotations

import os
import queue
import shutil
import subprocess
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from helpers.running_machine import halsdk_command
from helpers.tools import unavailable

TOKEN = "browser-test-token-42"


def chromium_path() -> str | None:
    for name in ("chromium", "chromium-browser"):
        found = shutil.which(name)
        if found:
            return found
    return None


def _unavailable(why: str) -> None:
    unavailable(f"browser tests: {why} (.ci/run installs Debian's "
                "chromium; playwright is a test extra)")


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    exe = chromium_path()
    if exe is None:
        _unavailable("no chromium (apt-get install chromium)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _unavailable("no playwright (pip install '.[test]')")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe, headless=True)
        try:
            yield b
        finally:
            b.close()


def serve(cwd: Path, *args: str) -> tuple[subprocess.Popen, str]:
    """``halsdk web`` on the test's instance; the process and its URL."""
    proc = subprocess.Popen(
        halsdk_command() + ["web", "--token", TOKEN, *args], cwd=cwd,
        env=dict(os.environ), stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)
    lines: queue.Queue = queue.Queue()

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.put(line)
        lines.put("")

    threading.Thread(target=read, daemon=True).start()
    while True:
        try:
            line = lines.get(timeout=60)
        except queue.Empty:
            line = ""
        if "http://" in line:
            return proc, line.strip()
        if not line:
            proc.kill()
            proc.wait()
            raise AssertionError(f"halsdk web did not start: "
                                 f"{proc.stderr.read() if proc.stderr else ''}")


def stop(proc: subprocess.Popen) -> None:
    proc.terminate()
    try:
        proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
    assert proc.returncode == 0
