"""The Latency page of the workbench: a latency test in the instance, its
figures and histograms, live.

The test itself is :class:`halsdk.tools.latency.LatencyTest` (the engine a
``halsdk latency`` command shares): two threads (``latency-base``,
``latency-servo``), a timedelta and a latencybins on each.  The page
starts, resets and stops it; a :class:`~halsdk.tools.latency.LatencyMonitor`
reads the histograms in a thread of its own, and the websocket pushes the
figures four times a second.

API (changes are JSON POSTs, refused under ``--read-only``):

- ``GET /api/latency/state``: running, the scheduling, every thread's
  figures and histogram, the defaults and limits of the settings;
- ``POST /api/latency/start`` ``{"base": ns, "servo": ns, "base_binsize":
  ns, "servo_binsize": ns, "bins": n, "realtime": true}`` (``base`` 0:
  the servo thread only; ``realtime`` false: no realtime scheduling,
  when the test starts the instance); ``POST /api/latency/reset``;
  ``POST /api/latency/stop``;
- ``/ws/latency``: the state, pushed at :data:`PUSH_PERIOD`.

What the test added is removed by stop, when the server ends, and when
the last page showing it has been gone for :data:`IDLE_GRACE` seconds.
"""

from __future__ import annotations

import asyncio
import contextlib
from typing import Any, Optional

from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import BaseRoute, Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from halsdk.errors import HalError
from halsdk.tools import latency as engine
from halsdk.tools.latency import LatencyError, LatencyMonitor, LatencyTest
from halsdk.web.common import (
    Workbench,
    json_response,
    read_body,
    read_only_refusal,
    refused,
)

#: how often the websocket pushes the figures (4 Hz)
PUSH_PERIOD = 0.25
#: how long a running test outlives the last page that showed it, in s
#: (a reload reconnects within it)
IDLE_GRACE = 5.0

#: the settings of a start: JSON key -> (default, least, most)
SETTINGS: dict[str, tuple[int, int, int]] = {
    "base": (engine.BASE_PERIOD, 0, engine.MAX_PERIOD),
    "servo": (engine.SERVO_PERIOD, engine.MIN_PERIOD["servo"],
              engine.MAX_PERIOD),
    "base_binsize": (engine.BINSIZE, 1, engine.MAX_BINSIZE),
    "servo_binsize": (engine.BINSIZE, 1, engine.MAX_BINSIZE),
    "bins": (engine.BINS, 1, engine.MAX_BINS),
}


def parse_settings(data: dict[str, Any]) -> dict[str, int]:
    """The settings of a start from its JSON body (missing: the
    default; ``realtime``, true by default, as 1 or 0); ValueError
    naming a bad one."""
    realtime = data.get("realtime", True)
    if not isinstance(realtime, bool):
        raise ValueError("'realtime' is not true or false")
    out = {"realtime": int(realtime)}
    for key, (default, least, most) in SETTINGS.items():
        value = data.get(key, default)
        if isinstance(value, str) and value.strip().lstrip("-").isdigit():
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f"'{key}' is not an integer")
        if not least <= value <= most:
            raise ValueError(f"'{key}' {value} is not from {least} to "
                             f"{most}")
        out[key] = value
    return out


class LatencyPage:
    """The page's state in the workbench: the one test and its monitor.
    Its methods run on the workbench's HAL worker thread."""

    def __init__(self, bench: Workbench):
        self.bench = bench
        self.test: Optional[LatencyTest] = None
        self.monitor: Optional[LatencyMonitor] = None
        self.settings: Optional[dict[str, int]] = None
        self.sockets = 0
        self.idle_task: Optional[asyncio.Task[None]] = None

    @property
    def running(self) -> bool:
        return self.test is not None and self.test.started

    def start(self, settings: dict[str, int]) -> dict[str, Any]:
        if self.running:
            raise LatencyError("latency test: already running; stop it "
                               "first")
        threads = engine.setups(
            settings["base"], settings["servo"],
            base_binsize=settings["base_binsize"],
            servo_binsize=settings["servo_binsize"], bins=settings["bins"])
        test = LatencyTest(self.bench.hal, threads)
        test.start(realtime=bool(settings["realtime"]))
        self.test, self.settings = test, settings
        self.monitor = LatencyMonitor(test)
        self.monitor.start()
        return self.state()

    def reset(self) -> dict[str, Any]:
        if self.test is None or not self.running:
            raise LatencyError("latency test: not running")
        self.test.reset()
        return self.state()

    def stop(self) -> dict[str, Any]:
        if self.monitor is not None:
            self.monitor.stop()
        if self.test is not None:
            self.test.stop()                # LatencyError: kept, retry
        self.test = self.monitor = None
        return self.state()

    def state(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "running": False, "realtime": None, "note": "", "threads": [],
            "sweeps": 0, "error": None}
        if self.running and self.monitor is not None:
            try:
                out = self.monitor.figures()
            except (HalError, LatencyError) as exc:
                out["error"] = str(exc)
        out["settings"] = self.settings
        out["defaults"] = {k: v[0] for k, v in SETTINGS.items()}
        out["limits"] = {k: [v[1], v[2]] for k, v in SETTINGS.items()}
        out["min_period"] = engine.MIN_PERIOD
        out["read_only"] = self.bench.read_only
        return out

    def close(self) -> None:
        """The server ends: remove the test."""
        with contextlib.suppress(HalError, LatencyError):
            self.stop()


def page_of(bench: Workbench) -> LatencyPage:
    page = bench.pages.get("latency")
    if page is None:
        page = bench.pages["latency"] = LatencyPage(bench)
    return page


def routes(bench: Workbench) -> list[BaseRoute]:
    """The API routes of the page (under /api/latency/)."""
    page = page_of(bench)

    async def state(request: Request) -> Response:
        return json_response(await bench.call(page.state))

    async def change(request: Request) -> Response:
        action = request.path_params["action"]
        if action not in ("start", "reset", "stop"):
            return json_response({"error": f"unknown action {action!r}"},
                                 404)
        refusal = read_only_refusal(bench, f"latency {action}")
        if refusal is not None:
            return refusal
        try:
            data = await read_body(request)
            if action == "start":
                settings = parse_settings(data)
                result = await bench.call(page.start, settings)
            elif action == "reset":
                result = await bench.call(page.reset)
            else:
                result = await bench.call(page.stop)
        except PermissionError as exc:
            return refused(str(exc))
        except LatencyError as exc:
            return json_response({"ok": False, "error": f"{exc}\n",
                                  "state": await bench.call(page.state)},
                                 409)
        except ValueError as exc:
            return json_response({"ok": False, "error": f"{exc}\n"}, 400)
        return json_response({"ok": True, "error": "", "state": result})

    async def live(ws: WebSocket) -> None:
        await ws.accept()
        page.sockets += 1
        receiver = asyncio.ensure_future(ws.receive())
        try:
            while True:
                await ws.send_json({"state": await bench.call(page.state)})
                done, _ = await asyncio.wait({receiver},
                                             timeout=PUSH_PERIOD)
                if done:
                    message = receiver.result()
                    if message.get("type") == "websocket.disconnect":
                        break
                    receiver = asyncio.ensure_future(ws.receive())
        except (WebSocketDisconnect, RuntimeError, OSError, HalError):
            pass
        finally:
            receiver.cancel()
            page.sockets -= 1
            if page.sockets == 0 and page.running:
                # a task of its own: this handler may be cancelled now
                page.idle_task = asyncio.get_running_loop().create_task(
                    _idle(page))

    async def _idle(page: LatencyPage) -> None:
        """The last page is gone: stop the test after the grace time,
        unless a page came back."""
        if page.sockets or not page.running:
            return
        await asyncio.sleep(IDLE_GRACE)
        if page.sockets == 0 and page.running:
            with contextlib.suppress(HalError, LatencyError):
                await bench.call(page.stop)

    return [
        Route("/api/latency/state", state),
        Route("/api/latency/{action:str}", change, methods=["POST"]),
        WebSocketRoute("/ws/latency", live),
    ]
