"""The Scope page of the workbench: halscope in the browser.

The samples are taken in realtime by a recorder (:meth:`Hal.recorder`:
a realtime function in the host, added to the thread the user chose,
copies the channels' values into a stream on every cycle), so none is
lost between two screens.  This process drains the stream every
:data:`POLL` seconds (on the workbench's HAL thread), keeps one sample
in ``mult``, and does the triggering in NumPy (:class:`Acquisition`);
the browser gets the screens (or, in roll mode, every sample) over the
websocket ``/ws/scope``.

A recorder belongs to one websocket (a *session*): it is removed when
the page stops it, starts another one, closes its websocket or when the
server ends.  A server killed outright leaves its recorder behind; the
host removes it the next time any recorder is made or deleted.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import secrets
import time
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import BaseRoute, Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from halsdk.errors import HalError
from halsdk.web.common import (
    Workbench,
    json_response,
    read_body,
    read_only_refusal,
    refused,
)

#: most channels of one scope
MAX_CHANNELS = 16
#: how often the stream is drained (seconds)
POLL = 0.05
#: how often the status goes to the page without a screen (seconds)
STATUS_PERIOD = 0.25
#: how often the channels are checked to still exist (seconds)
CHECK_PERIOD = 0.5
#: the record length's bounds (samples)
MIN_LENGTH, MAX_LENGTH = 10, 100_000
#: the multiplier's bounds
MAX_MULT = 10_000
#: seconds of thread cycles that the ring holds (at least MIN_DEPTH)
RING_SECONDS = 2.0
MIN_DEPTH = 1024
#: most sessions (websockets) at once, each with at most one recorder
MAX_SESSIONS = 8
MODES = ("normal", "single", "auto", "roll")


def find_trigger(values: np.ndarray, level: float, rising: bool = True,
                 start: int = 1) -> Optional[int]:
    """The first index ``i >= start`` (and ``>= 1``) where ``values``
    crosses ``level``: ``values[i-1] < level <= values[i]`` rising,
    ``values[i-1] > level >= values[i]`` falling; None when it does not."""
    start = max(int(start), 1)
    if len(values) <= start:
        return None
    before = values[start - 1:-1]
    after = values[start:]
    if rising:
        hits = np.flatnonzero((before < level) & (after >= level))
    else:
        hits = np.flatnonzero((before > level) & (after <= level))
    return int(hits[0]) + start if len(hits) else None


@dataclass
class Config:
    """What the user chose."""
    channels: list[str]
    thread: str
    mult: int = 1
    length: int = 1000
    mode: str = "normal"
    trigger: int = -1           # the channel's index, -1: none (free run)
    rising: bool = True
    level: float = 0.0
    position: float = 50.0      # pre-trigger, % of the record

    @property
    def pre(self) -> int:
        """The trigger's index in a screen."""
        return int(round(self.position / 100.0 * (self.length - 1)))


def _int(data: dict[str, Any], key: str, default: int, low: int,
         high: int) -> int:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or \
            not low <= value <= high:
        raise ValueError(f"'{key}' must be an integer from {low} to {high}")
    return value


def _float(data: dict[str, Any], key: str, default: float, low: float,
           high: float) -> float:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not low <= value <= high:
        raise ValueError(f"'{key}' must be a number from {low:g} to "
                         f"{high:g}")
    return float(value)


def parse_config(data: dict[str, Any]) -> Config:
    """The :class:`Config` of a start request; ValueError naming what is
    wrong."""
    channels = data.get("channels")
    if not isinstance(channels, list) or not all(
            isinstance(c, str) and c for c in channels):
        raise ValueError("'channels' must be a list of names")
    if not 1 <= len(channels) <= MAX_CHANNELS:
        raise ValueError(f"{len(channels)} channels: 1 to {MAX_CHANNELS} "
                         "allowed")
    thread = data.get("thread")
    if not isinstance(thread, str) or not thread:
        raise ValueError("'thread' must name a thread")
    mode = data.get("mode", "normal")
    if mode not in MODES:
        raise ValueError(f"'mode' must be one of {', '.join(MODES)}")
    edge = data.get("edge", "rising")
    if edge not in ("rising", "falling"):
        raise ValueError("'edge' must be 'rising' or 'falling'")
    return Config(
        channels=list(channels), thread=thread,
        mult=_int(data, "mult", 1, 1, MAX_MULT),
        length=_int(data, "length", 1000, MIN_LENGTH, MAX_LENGTH),
        mode=mode,
        trigger=_int(data, "trigger", -1, -1, len(channels) - 1),
        rising=edge == "rising",
        level=_float(data, "level", 0.0, -1e300, 1e300),
        position=_float(data, "position", 50.0, 0.0, 100.0))


@dataclass
class Acquisition:
    """The triggering of continuous samples (no HAL here).

    :meth:`feed` takes the stream's records (their sample numbers and
    values, one row per thread cycle), keeps one in ``mult``, counts the
    samples lost (gaps in the sample numbers) and returns the messages
    for the page: in roll mode the new samples, else at most one screen
    (the latest found) of ``length`` samples with the trigger at
    :attr:`Config.pre`."""
    config: Config
    lost: int = 0
    samples: int = 0
    frames: int = 0
    state: str = "armed"
    _next: Optional[int] = None         # the next sample number expected
    _buf: Optional[np.ndarray] = None   # (samples, channels), decimated
    _buf_start: int = 0                 # decimated index of _buf[0]
    _search: int = 0                    # where the trigger search goes on
    _armed_at: int = 0                  # auto: when the wait started
    _started: bool = field(default=False)

    def feed(self, sampleno: np.ndarray, values: np.ndarray
             ) -> list[dict[str, Any]]:
        cfg = self.config
        if len(sampleno) == 0:
            return []
        sampleno = sampleno.astype(np.int64)
        if self._next is not None:
            gaps = np.diff(np.concatenate(([self._next - 1], sampleno))) - 1
            self.lost += int(gaps[gaps > 0].sum())
        self._next = int(sampleno[-1]) + 1
        keep = sampleno % cfg.mult == 0
        index = sampleno[keep] // cfg.mult
        new = np.asarray(values, dtype=np.float64)[keep]
        if len(index) == 0:
            return []
        if not self._started:
            self._started = True
            self._buf_start = int(index[0])
            self._search = self._buf_start
            self._armed_at = self._buf_start
        self.samples += len(new)
        if cfg.mode == "roll":
            self.state = "roll"
            self.frames += 1
            return [{"roll": {"start": int(index[0]),
                              "channels": new.T.tolist()}}]
        if self._buf is None:
            self._buf = new
            self._buf_start = int(index[0])
        else:
            # a gap (lost samples) restarts the record: no screen spans it
            if int(index[0]) != self._buf_start + len(self._buf):
                self._buf = new
                self._buf_start = int(index[0])
                self._search = max(self._search, self._buf_start)
            else:
                self._buf = np.concatenate((self._buf, new))
        return self._screens()

    def _screens(self) -> list[dict[str, Any]]:
        cfg = self.config
        assert self._buf is not None
        if self.state == "done":
            self._trim(self._buf_start + len(self._buf))
            return []
        end = self._buf_start + len(self._buf)         # one past the last
        pre, length = cfg.pre, cfg.length
        screen: Optional[dict[str, Any]] = None
        while True:
            first = max(self._search, self._buf_start + pre, self._buf_start + 1)
            trig = None
            if cfg.trigger >= 0 and first < end:
                col = self._buf[:, cfg.trigger]
                hit = find_trigger(col, cfg.level, cfg.rising,
                                   first - self._buf_start)
                if hit is not None:
                    trig = hit + self._buf_start
            if trig is not None:
                if trig - pre + length > end:
                    self._search = trig   # wait for the rest of the screen
                    break
                screen = self._screen(trig - pre, pre)
                self._search = trig - pre + length
                self._armed_at = self._search
                if cfg.mode == "single":
                    self.state = "done"
                    break
                continue
            self._search = max(self._search, end - 1)
            free = cfg.mode == "auto" or cfg.trigger < 0
            if free and end - self._armed_at >= length and \
                    end - self._buf_start >= length:
                screen = self._screen(end - length, None)
                self._armed_at = end
                self._search = end
                if cfg.mode == "single":
                    self.state = "done"
            break
        self._trim(self._search - pre - 1)
        if screen is None:
            return []
        self.frames += 1
        if self.state != "done":
            self.state = "triggered" if screen["trigger"] is not None \
                else "auto"
        return [{"frame": screen}]

    def _screen(self, start: int, trigger: Optional[int]) -> dict[str, Any]:
        assert self._buf is not None
        i = start - self._buf_start
        part = self._buf[i:i + self.config.length]
        return {"start": start, "trigger": trigger,
                "channels": part.T.tolist()}

    def _trim(self, keep_from: int) -> None:
        """Drop what no screen can need any more (before ``keep_from``,
        and beyond a bound)."""
        assert self._buf is not None
        end = self._buf_start + len(self._buf)
        keep_from = max(keep_from, end - 2 * self.config.length - 1)
        cut = keep_from - self._buf_start
        if cut > 0:
            self._buf = self._buf[cut:]
            self._buf_start += cut
            self._search = max(self._search, self._buf_start)


class Session:
    """One websocket of the page and its recorder (HAL calls: run them on
    the workbench's HAL thread)."""

    def __init__(self, bench: Workbench):
        self.bench = bench
        self.id = secrets.token_hex(8)
        self.recorder: Optional[str] = None
        self.stream: Any = None
        self.config: Optional[Config] = None
        self.acq: Optional[Acquisition] = None
        self.period = 0                 # of the thread, ns
        self.error: Optional[str] = None
        self._checked = 0.0

    def start(self, config: Config) -> dict[str, Any]:
        hal = self.bench.hal
        old = self.config
        if old is None or self.recorder is None or \
                old.channels != config.channels or \
                old.thread != config.thread:
            self.stop()
            thread = hal.thread(config.thread)
            self.period = int(thread.period)
            depth = max(MIN_DEPTH, int(RING_SECONDS * 1e9 / self.period))
            depth = min(depth, hal.RECORDER_MAX_DEPTH)
            self.recorder = hal.recorder(config.channels, config.thread,
                                         depth)
            self.stream = hal.stream(self.recorder)
        self.config = config
        self.acq = Acquisition(config)
        self.error = None
        self._checked = time.monotonic()
        return {"ok": True, "recorder": self.recorder,
                "dt": self.period * config.mult * 1e-9,
                "depth": int(self.stream.maxdepth)}

    def stop(self) -> None:
        name, self.recorder, self.stream = self.recorder, None, None
        self.acq = None
        if name is not None:
            with contextlib.suppress(HalError):
                self.bench.hal.recorder_delete(name)

    def poll(self) -> list[dict[str, Any]]:
        """The messages of what the recorder took since the last poll."""
        if self.stream is None or self.acq is None or self.config is None:
            return []
        now = time.monotonic()
        if now - self._checked >= CHECK_PERIOD:
            self._checked = now
            gone = [n for n in self.config.channels if not self._exists(n)]
            if gone:
                self.stop()
                self.error = (f"stopped: channel '{gone[0]}' is gone "
                              "(its component was unloaded?)")
                return [{"status": self.status()}]
        names = [f"c{i}" for i in range(len(self.config.channels))]
        arr = self.stream.read_many(-1, names)
        if len(arr) == 0:
            return []
        values = np.column_stack([arr[n].astype(np.float64)
                                  for n in names])
        return self.acq.feed(arr["sample"], values)

    def _exists(self, name: str) -> bool:
        hal = self.bench.hal
        return any(hal.find(kind, name) is not None
                   for kind in ("pin", "signal", "param"))

    def status(self) -> dict[str, Any]:
        acq = self.acq
        return {
            "running": self.recorder is not None,
            "state": acq.state if acq else "stopped",
            "error": self.error,
            "lost": acq.lost if acq else 0,
            "overruns": int(self.stream.overruns) if self.stream else 0,
            "samples": acq.samples if acq else 0,
            "frames": acq.frames if acq else 0,
            "dt": (self.period * self.config.mult * 1e-9
                   if self.config else None),
        }


class ScopePage:
    """The page's state in the workbench: its sessions."""

    def __init__(self, bench: Workbench):
        self.bench = bench
        self.sessions: dict[str, Session] = {}

    def close(self) -> None:
        for session in list(self.sessions.values()):
            session.stop()
        self.sessions.clear()


def _page(bench: Workbench) -> ScopePage:
    page = bench.pages.get("scope")
    if page is None:
        page = bench.pages["scope"] = ScopePage(bench)
    return page


def sources(bench: Workbench) -> dict[str, Any]:
    """The threads and the names a channel can show."""
    hal = bench.hal
    prefix = hal.RECORDER_PREFIX
    return {
        "threads": [{"name": t.name, "period": int(t.period)}
                    for t in hal.threads()],
        "pins": [p.name for p in hal.pins()],
        "signals": [s.name for s in hal.signals()],
        "params": [p.name for p in hal.params()
                   if not p.name.startswith(prefix)],
        "max_channels": MAX_CHANNELS,
        "read_only": bench.read_only,
    }


def routes(bench: Workbench) -> list[BaseRoute]:
    """The API routes of the page (under /api/scope/) and its websocket."""
    page = _page(bench)

    async def get_sources(request: Request) -> Response:
        return json_response(await bench.call(sources, bench))

    async def session_of(data: dict[str, Any]) -> Session:
        sid = data.get("session")
        session = page.sessions.get(sid) if isinstance(sid, str) else None
        if session is None:
            raise LookupError("no such scope session: open the page's "
                              "websocket first")
        return session

    async def start(request: Request) -> Response:
        refusal = read_only_refusal(bench, "scope start")
        if refusal is not None:
            return refusal
        try:
            data = await read_body(request)
            session = await session_of(data)
            config = parse_config(data)
        except PermissionError as exc:
            return refused(str(exc))
        except LookupError as exc:
            return json_response({"ok": False, "error": str(exc)}, 404)
        except ValueError as exc:
            return json_response({"ok": False, "error": str(exc)}, 400)
        try:
            result = await bench.call(session.start, config)
        except HalError as exc:
            return json_response({"ok": False, "error": str(exc)}, 409)
        return json_response(result)

    async def stop(request: Request) -> Response:
        refusal = read_only_refusal(bench, "scope stop")
        if refusal is not None:
            return refusal
        try:
            session = await session_of(await read_body(request))
        except PermissionError as exc:
            return refused(str(exc))
        except LookupError as exc:
            return json_response({"ok": False, "error": str(exc)}, 404)
        except ValueError as exc:
            return json_response({"ok": False, "error": str(exc)}, 400)
        await bench.call(session.stop)
        return json_response({"ok": True})

    async def live(ws: WebSocket) -> None:
        await ws.accept()
        if len(page.sessions) >= MAX_SESSIONS:
            await ws.send_json({"error": f"at most {MAX_SESSIONS} scopes "
                                         "at once"})
            await ws.close()
            return
        session = Session(bench)
        page.sessions[session.id] = session
        loop = asyncio.get_running_loop()

        async def reader() -> None:
            while True:                 # only to see the close
                with contextlib.suppress(ValueError):
                    json.loads(await ws.receive_text())

        task = asyncio.ensure_future(reader())
        try:
            await ws.send_json({"hello": {"session": session.id,
                                          "read_only": bench.read_only}})
            next_status = 0.0
            while not task.done():
                try:
                    messages = await bench.call(session.poll)
                except HalError as exc:
                    await bench.call(session.stop)
                    session.error = f"stopped: {exc}"
                    messages = []
                    next_status = 0.0
                sent_status = False
                for message in messages:
                    if "frame" in message or "status" in message:
                        message["status"] = session.status()
                        sent_status = True
                    await ws.send_json(message)
                if not sent_status and loop.time() >= next_status:
                    await ws.send_json({"status": session.status()})
                    sent_status = True
                if sent_status:
                    next_status = loop.time() + STATUS_PERIOD
                await asyncio.wait({task}, timeout=POLL)
        except (WebSocketDisconnect, RuntimeError, OSError, HalError):
            pass
        finally:
            task.cancel()
            with contextlib.suppress(BaseException):
                await task
            page.sessions.pop(session.id, None)
            bench.submit(session.stop)

    return [
        Route("/api/scope/sources", get_sources),
        Route("/api/scope/start", start, methods=["POST"]),
        Route("/api/scope/stop", stop, methods=["POST"]),
        WebSocketRoute("/ws/scope", live),
    ]
