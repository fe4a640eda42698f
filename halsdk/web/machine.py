"""The Machine page of the workbench: a running machine's task controller
operated from the browser.

The page is a client of the machine like ``halsdk ctl``: one
:class:`~halsdk.machine.MachineClient` (:func:`halsdk.machine.connect`)
per workbench, made when a page first looks and made again, once a
second, while no task controller runs (the page says why).  Its routes:

- ``GET /api/machine/status``: the status the websocket pushes;
- ``GET /api/machine/messages``: the error channel's messages so far
  (the last :data:`MAX_MESSAGES`);
- ``GET /api/machine/preview``: the XY path of the open program, from
  the G-code interpreter (:mod:`halsdk.gcode`, its canonical moves);
- ``POST /api/machine/<action>``: a command (:data:`ACTIONS`), each
  refused under ``--read-only``; its answer is ``{"ok": true}``, or the
  task's reason (409), a bad request (400), no machine (503);
- ``/ws/machine``: the status :data:`PUSH_PERIOD` apart (20 a second)
  and the new messages.

Commands run on a thread of the page (a command waits until the task
took it, never on the event loop); the status is a read of shared memory
of a few microseconds.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import math
import os
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Callable, Optional

from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import BaseRoute, Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from halsdk.errors import HalError, InvalidError
from halsdk.machine import (
    MachineClient,
    MachineError,
    MachineTimeout,
    RemoteStatus,
    TaskMode,
    connect,
)
from halsdk.machine.client import ChannelError, kind_name
from halsdk.machine.remote_status import AXIS_LETTERS, exec_state_name
from halsdk.web.common import (
    Workbench,
    json_response,
    read_body,
    read_only_refusal,
)

#: seconds between two status pushes of the websocket (20 a second)
PUSH_PERIOD = 0.05
#: seconds between two attempts to find the machine
RETRY_PERIOD = 1.0
#: seconds a connection and a command may take to be answered
CONNECT_TIMEOUT = 3.0
#: the messages of the error channel the page keeps
MAX_MESSAGES = 200
#: the canonical commands a program's preview takes at most
MAX_PREVIEW_MOVES = 100_000
#: traj mode of teleop (jogging axes once homed)
TELEOP = 3


# ----------------------------------------------------------------- preview

class _TooLong(Exception):
    pass


def _arc_points(start: tuple[float, float], end: tuple[float, float],
                center: tuple[float, float], turn: int) -> list[float]:
    """An XY arc from ``start`` to ``end`` as points (start excluded):
    counter-clockwise for ``turn`` > 0, ``abs(turn) - 1`` extra turns."""
    cx, cy = center
    r0 = math.hypot(start[0] - cx, start[1] - cy)
    r1 = math.hypot(end[0] - cx, end[1] - cy)
    a0 = math.atan2(start[1] - cy, start[0] - cx)
    a1 = math.atan2(end[1] - cy, end[0] - cx)
    sweep = a1 - a0
    if turn > 0:
        while sweep <= 1e-12:
            sweep += 2 * math.pi
        sweep += 2 * math.pi * (turn - 1)
    else:
        while sweep >= -1e-12:
            sweep -= 2 * math.pi
        sweep -= 2 * math.pi * (-turn - 1)
    steps = max(2, min(720, int(abs(sweep) / (math.pi / 36)) + 1))
    out: list[float] = []
    for k in range(1, steps + 1):
        f = k / steps
        a = a0 + sweep * f
        r = r0 + (r1 - r0) * f
        out += [cx + r * math.cos(a), cy + r * math.sin(a)]
    out[-2:] = [end[0], end[1]]
    return out


def preview_paths(commands: list[Any], start: tuple[float, float]
                  ) -> list[dict[str, Any]]:
    """The XY polylines of canonical commands (:mod:`halsdk.gcode.canon`)
    from ``start``: ``{"kind": "rapid"|"feed", "points": [x, y, ...]}``,
    consecutive moves of one kind in one polyline; arcs of the XY plane
    as points on the arc, arcs of other planes as their chord in XY."""
    from halsdk.gcode import canon as C

    paths: list[dict[str, Any]] = []
    here = start

    def add(kind: str, points: list[float]) -> None:
        if not paths or paths[-1]["kind"] != kind:
            paths.append({"kind": kind, "points": [here[0], here[1]]})
        paths[-1]["points"].extend(points)

    for cmd in commands:
        if isinstance(cmd, C.StraightTraverse):
            kind = "rapid"
        elif isinstance(cmd, (C.StraightFeed, C.ArcFeed, C.SyncedFeed,
                              C.Probe)):
            kind = "feed"
        else:
            continue
        end = (float(cmd.end[0]), float(cmd.end[1]))
        if isinstance(cmd, C.ArcFeed) and cmd.plane == 17:
            add(kind, _arc_points(here, end, cmd.center, cmd.turn))
        else:
            add(kind, [end[0], end[1]])
        here = end
    for path in paths:
        path["points"] = [round(v, 4) for v in path["points"]]
    return paths


def _ini_units(ini: Any) -> str:
    units = str(ini.get("TRAJ", "LINEAR_UNITS") or "mm").strip().lower()
    return "inch" if units in ("inch", "in", "imperial") else "mm"


def make_preview(path: str, st: Optional[RemoteStatus]) -> dict[str, Any]:
    """The preview of program ``path`` as the machine of status ``st``
    would run it (its INI file's tool table, parameters and units, its
    offsets and position now): ``{"file", "paths", "error"}``; an error
    of the program keeps the path up to it."""
    from halsdk.gcode import GCodeError, Parameters, Program
    from halsdk.gcode import canon as C
    from halsdk.gcode.interp import Interpreter
    from halsdk.gcode.remap import configure as configure_remap
    from halsdk.machine import ToolTable
    from halsdk.machine.controller import subroutine_path

    class Recorder(C.RecordingCanon):
        def emit(self, command: C.Command) -> None:
            if len(self.commands) >= MAX_PREVIEW_MOVES:
                raise _TooLong
            super().emit(command)

    params = Parameters()
    table: Any = ToolTable()
    units = "mm"
    start = (0.0, 0.0)
    ini: Any = None
    if st is not None:
        start = (float(st.position[0]), float(st.position[1]))
        if st.ini_filename:
            table, units, ini = _machine_files(st.ini_filename, params)
        index = min(max(int(st.g5x_index or 1), 1), 9)
        params.set(5220, index)
        for i in range(9):
            params.set(5201 + 20 * index + i, float(st.g5x_offset[i]))
            params.set(5211 + i, float(st.g92_offset[i]))
        params.set(5210, 1.0 if any(st.g92_offset) else 0.0)
    rec = Recorder()
    error = ""
    try:
        interp = Interpreter(params, table, rec,
                             random_toolchanger=table.random, units=units)
        if st is not None:
            interp.pos = [float(v) for v in st.position[:9]]
        search: list[str] = []
        if ini is not None:
            # as the machine reads its programs: the subroutine path,
            # #<_ini[...]>, the REMAPs and the [PYTHON] plugin
            search = subroutine_path(ini)
            interp.ini = ini.get
            configure_remap(interp, ini, search)
        interp.run(Program.from_file(path, params, search))
    except _TooLong:
        error = (f"the preview shows the first {MAX_PREVIEW_MOVES} moves "
                 "only")
    except (GCodeError, HalError, ValueError, OSError) as exc:
        error = str(exc)
    return {"file": path, "paths": preview_paths(rec.commands, start),
            "error": error}


def _machine_files(ini_path: str, params: Any) -> tuple[Any, str, Any]:
    """The tool table, the units and the INI file (None if unreadable)
    of the machine; its parameter file into ``params`` (what can be read
    of them)."""
    from halsdk.ini import IniFile
    from halsdk.machine import ToolTable
    try:
        ini = IniFile(ini_path)
    except (OSError, HalError):
        return ToolTable(), "mm", None
    folder = os.path.dirname(os.path.abspath(ini_path))
    random = str(ini.get("EMCIO", "RANDOM_TOOLCHANGER") or "0"
                 ).strip() not in ("0", "")
    table: Any = ToolTable(random=random)
    name = ini.get("EMCIO", "TOOL_TABLE")
    if name:
        with contextlib.suppress(OSError, HalError, ValueError):
            table = ToolTable.load(os.path.join(folder, str(name)),
                                   random=random)
    name = ini.get("RS274NGC", "PARAMETER_FILE")
    if name:
        with contextlib.suppress(OSError, HalError, ValueError):
            file = os.path.join(folder, str(name))
            if os.path.exists(file):
                params.load(file)
    return table, _ini_units(ini), ini


# ----------------------------------------------------------------- status

def work_position(st: RemoteStatus) -> list[float]:
    """The position in the work coordinates of ``st`` (G5x with its XY
    rotation, G92 and the tool offset taken off), X to W."""
    p = [float(v) for v in st.position[:9]]
    rel = [p[i] - float(st.g5x_offset[i]) for i in range(9)]
    if st.rotation_xy:
        t = math.radians(-float(st.rotation_xy))
        x, y = rel[0], rel[1]
        rel[0] = x * math.cos(t) - y * math.sin(t)
        rel[1] = x * math.sin(t) + y * math.cos(t)
    return [rel[i] - float(st.g92_offset[i]) - float(st.tool_offset[i])
            for i in range(9)]


def status_dict(st: RemoteStatus) -> dict[str, Any]:
    """What the page shows of a status (JSON)."""
    axes = st.axis_names or "XYZ"
    index = [AXIS_LETTERS.index(a) for a in axes]
    work = work_position(st)
    spindle = st.spindles[0] if st.spindles else None
    return {
        "connected": True,
        "task_pid": st.task_pid,
        "state": st.task_state.name,
        "mode": st.task_mode.name,
        "interp": st.interp_state.name,
        "exec": exec_state_name(st.exec_state),
        "estop": st.estop,
        "enabled": st.enabled,
        "paused": st.paused,
        "axes": axes,
        "machine": [round(float(st.position[i]), 4) for i in index],
        "work": [round(work[i], 4) for i in index],
        "xy": [float(st.position[0]), float(st.position[1])],
        "g5x": st.g5x_index,
        "joints": [{"homed": j.homed, "homing": j.homing}
                   for j in st.joints],
        "all_homed": st.all_homed,
        "teleop": st.motion_mode == TELEOP,
        "velocity": st.current_vel,
        "feedrate": st.feedrate,
        "rapidrate": st.rapidrate,
        "spindle": None if spindle is None else {
            "speed": spindle.speed, "direction": spindle.direction,
            "override": spindle.override},
        "tool": st.tool_in_spindle,
        "file": st.file,
        "line": st.motion_line or st.current_line,
        "mdi": st.command,
        "heartbeat": st.heartbeat,
    }


# ----------------------------------------------------------------- the page

class MachinePage:
    """The page's state: the client (None while no machine runs), the
    messages of the error channel, the open program's preview."""

    def __init__(self, instance: Optional[str]) -> None:
        self.instance = instance
        self.client: Optional[MachineClient] = None
        self.why = "looking for the machine"
        self.messages: collections.deque[dict[str, Any]] = \
            collections.deque(maxlen=MAX_MESSAGES)
        self.serial = 0                     # of the last message
        self.preview: dict[str, Any] = {"file": "", "paths": [], "error": ""}
        self.preview_version = 0
        self._preview_of: Optional[str] = None
        self._previewing: Optional[Future[Any]] = None
        self._commands = ThreadPoolExecutor(1, "halsdk-web-machine")
        self._background = ThreadPoolExecutor(1, "halsdk-web-machine-bg")
        self._connecting: Optional[Future[Any]] = None
        self._next_try = 0.0
        self._lock = threading.Lock()
        self._closed = False
        #: the axes of continuous jogs started and not stopped: stopped
        #: when a page goes away (never left jogging)
        self.jogging: set[str] = set()

    # -- connection ------------------------------------------------------

    def _connect(self) -> None:
        try:
            client = connect(self.instance, CONNECT_TIMEOUT, name="web")
        except HalError as exc:
            self.why = str(exc)
            return
        with self._lock:
            if self._closed:
                client.close()
                return
            self.client = client
            self.why = ""

    def _try_connect(self) -> None:
        now = time.monotonic()
        if self._closed or now < self._next_try or (
                self._connecting is not None and
                not self._connecting.done()):
            return
        self._next_try = now + RETRY_PERIOD
        self._connecting = self._background.submit(self._connect)

    def _lost(self, why: str) -> None:
        with self._lock:
            client, self.client = self.client, None
        self.why = why
        self._next_try = time.monotonic() + RETRY_PERIOD
        if client is not None:
            with contextlib.suppress(Exception):
                self._background.submit(client.close)

    def _stop_jogs(self, client: MachineClient) -> None:
        for axis in sorted(self.jogging):
            with contextlib.suppress(Exception):
                _jog_stop(client, {"axis": axis})
            self.jogging.discard(axis)

    def stop_jogs(self) -> None:
        """Stop the continuous jogs the pages started (a page that went
        away cannot stop its own); on the page's thread, not waited
        for (a cancelled websocket handler cannot wait)."""
        client = self.client
        if client is None or not self.jogging or self._closed:
            return
        with contextlib.suppress(RuntimeError):     # shut down already
            self._commands.submit(self._stop_jogs, client)

    def close(self) -> None:
        with self._lock:
            self._closed = True
            client, self.client = self.client, None
        if client is not None and self.jogging:
            with contextlib.suppress(Exception):
                self._commands.submit(self._stop_jogs, client).result(10)
        self._commands.shutdown(wait=True, cancel_futures=True)
        self._background.shutdown(wait=True, cancel_futures=True)
        if client is not None:
            with contextlib.suppress(Exception):
                client.close()

    # -- status, messages, preview ----------------------------------------

    def _add_message(self, kind: int, text: str) -> None:
        self.serial += 1
        self.messages.append({"serial": self.serial, "kind": kind_name(kind),
                              "text": text, "time": time.time()})

    def messages_after(self, serial: int) -> list[dict[str, Any]]:
        return [m for m in self.messages if m["serial"] > serial]

    def poll(self) -> dict[str, Any]:
        """The status now (fast: call it on the event loop)."""
        client = self.client
        if client is None:
            self._try_connect()
            return {"connected": False, "why": self.why,
                    "instance": self.instance}
        try:
            st = client.status()
            for kind, text in client.errors():
                self._add_message(kind, text)
        except HalError as exc:
            self._lost(str(exc))
            return {"connected": False, "why": self.why,
                    "instance": self.instance}
        if st.file != self._preview_of:
            self._preview_of = st.file
            self._previewing = self._background.submit(
                self._make_preview, st.file, st)
        out = status_dict(st)
        out["instance"] = client.instance
        out["preview"] = self.preview_version
        return out

    def _make_preview(self, path: str, st: RemoteStatus) -> None:
        preview = make_preview(path, st) if path else \
            {"file": "", "paths": [], "error": ""}
        if self._preview_of == path:
            self.preview = preview
            self.preview_version += 1

    async def current_preview(self) -> dict[str, Any]:
        """The preview of the program open now (made first if needed)."""
        self.poll()
        making = self._previewing
        if making is not None:
            with contextlib.suppress(Exception):
                await asyncio.wrap_future(making)
        return {"version": self.preview_version, **self.preview}

    # -- commands ----------------------------------------------------------

    async def run(self, action: str, data: dict[str, Any]
                  ) -> tuple[int, dict[str, Any]]:
        """Command ``action`` with ``data``: ``(HTTP status, answer)``."""
        client = self.client
        if client is None:
            self._try_connect()
            return 503, {"ok": False, "error": self.why or
                         "no machine is running"}
        fn = ACTIONS[action]
        loop = asyncio.get_running_loop()
        try:
            result = await loop.run_in_executor(self._commands, fn, client,
                                                data)
        except MachineTimeout as exc:
            return 504, {"ok": False, "error": str(exc)}
        except MachineError as exc:
            return 409, {"ok": False, "error": str(exc)}
        except ChannelError as exc:
            self._lost(str(exc))
            return 503, {"ok": False, "error": str(exc)}
        except (InvalidError, ValueError, TypeError, KeyError) as exc:
            return 400, {"ok": False, "error": _reason(exc)}
        except HalError as exc:
            return 409, {"ok": False, "error": str(exc)}
        if action == "jog" and data.get("distance") is None:
            self.jogging.add(str(data["axis"]).upper())
        elif action == "jog-stop":
            self.jogging.discard(str(data["axis"]).upper())
        return 200, {"ok": True,
                     **(result if isinstance(result, dict) else {})}


def _reason(exc: BaseException) -> str:
    if isinstance(exc, KeyError):
        return f"'{exc.args[0]}' is missing"
    return str(exc)


# ----------------------------------------------------------------- actions

def _number(data: dict[str, Any], key: str,
            default: Optional[float] = None) -> float:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not math.isfinite(value):
        raise ValueError(f"'{key}' is missing or not a number")
    return float(value)


def _integer(data: dict[str, Any], key: str, default: int) -> int:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"'{key}' is not a whole number")
    return value


def _text(data: dict[str, Any], key: str) -> str:
    value = data.get(key)
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"'{key}' is missing or empty")
    if "\n" in value or "\r" in value or "\0" in value:
        raise ValueError(f"'{key}' is one line")
    return value.strip()


def _ensure_mode(m: MachineClient, mode: TaskMode) -> None:
    if m.status().task_mode is not mode:
        m.mode(mode)


def _axis(m: MachineClient, data: dict[str, Any]) -> tuple[str, int]:
    """The jog's axis letter and its joint (the joint of the same rank:
    the identity kinematics of the example machines)."""
    letter = data.get("axis")
    axes = m.status().axis_names
    if not isinstance(letter, str) or len(letter) != 1 or \
            letter.upper() not in axes:
        raise ValueError(f"'axis' is not one of the machine's axes "
                         f"({' '.join(axes)})")
    letter = letter.upper()
    return letter, axes.index(letter)


def _jog(m: MachineClient, data: dict[str, Any]) -> None:
    letter, joint = _axis(m, data)
    velocity = _number(data, "velocity")
    distance = data.get("distance")
    if distance is not None:
        distance = _number(data, "distance")
        if distance <= 0:
            raise ValueError("'distance' must be more than 0")
    _ensure_mode(m, TaskMode.MANUAL)
    st = m.status()
    if st.all_homed:
        # axes, as LinuxCNC's GUIs do once the machine is homed
        if st.motion_mode != TELEOP:
            m.teleop_enable(True)
        m.jog(letter, velocity, distance)
    else:
        if st.motion_mode == TELEOP:
            m.teleop_enable(False)
        m.jog(joint, velocity, distance)


def _jog_stop(m: MachineClient, data: dict[str, Any]) -> None:
    letter, joint = _axis(m, data)
    if m.status().motion_mode == TELEOP:
        m.jog_stop(letter)
    else:
        m.jog_stop(joint)


def _home(m: MachineClient, data: dict[str, Any]) -> None:
    joint = _integer(data, "joint", -1)
    _ensure_mode(m, TaskMode.MANUAL)
    m.home(joint)


def _unhome(m: MachineClient, data: dict[str, Any]) -> None:
    joint = _integer(data, "joint", -1)
    _ensure_mode(m, TaskMode.MANUAL)
    m.unhome(joint)


def _mdi(m: MachineClient, data: dict[str, Any]) -> None:
    line = _text(data, "line")
    _ensure_mode(m, TaskMode.MDI)
    m.mdi(line, wait=False)


def _open(m: MachineClient, data: dict[str, Any]) -> dict[str, Any]:
    path = os.path.abspath(os.path.expanduser(_text(data, "path")))
    if not os.path.isfile(path):
        raise ValueError(f"{path}: no such file on the controller")
    _ensure_mode(m, TaskMode.AUTO)
    m.program_open(path)
    return {"file": path}


def _run(m: MachineClient, data: dict[str, Any]) -> None:
    line = _integer(data, "line", 0)
    _ensure_mode(m, TaskMode.AUTO)
    m.run(line)


def _mode(m: MachineClient, data: dict[str, Any]) -> None:
    word = data.get("mode")
    if not isinstance(word, str) or word.upper() not in TaskMode.__members__:
        raise ValueError("'mode' is one of manual, auto, mdi")
    m.mode(TaskMode[word.upper()])


def _scale(data: dict[str, Any], top: float) -> float:
    scale = _number(data, "scale")
    if not 0.0 <= scale <= top:
        raise ValueError(f"'scale' {scale:g} is not 0 to {top:g}")
    return scale


def _simple(method: str) -> Callable[[MachineClient, dict[str, Any]], None]:
    def run(m: MachineClient, data: dict[str, Any]) -> None:
        getattr(m, method)()
    return run


#: the commands of the page: ``POST /api/machine/<name>`` with a JSON body
ACTIONS: dict[str, Callable[[MachineClient, dict[str, Any]], Any]] = {
    "estop": _simple("estop"),
    "estop-reset": _simple("estop_reset"),
    "on": _simple("on"),
    "off": _simple("off"),
    "mode": _mode,
    "home": _home,
    "unhome": _unhome,
    "jog": _jog,
    "jog-stop": _jog_stop,
    "mdi": _mdi,
    "open": _open,
    "run": _run,
    "pause": _simple("pause"),
    "resume": _simple("resume"),
    "step": _simple("step"),
    "abort": _simple("abort"),
    "feed": lambda m, d: m.feed_override(_scale(d, 2.0)),
    "rapid": lambda m, d: m.rapid_override(_scale(d, 1.0)),
    "spindle-override": lambda m, d: m.spindle_override(_scale(d, 2.0)),
}


# ----------------------------------------------------------------- routes

def routes(bench: Workbench) -> list[BaseRoute]:
    """The API routes of the page (under /api/machine/) and its
    websocket."""
    page = MachinePage(bench.hal.instance)
    bench.pages["machine"] = page

    async def status(request: Request) -> Response:
        return json_response(page.poll())

    async def messages(request: Request) -> Response:
        page.poll()
        return json_response({"messages": list(page.messages)})

    async def preview(request: Request) -> Response:
        return json_response(await page.current_preview())

    async def command(request: Request) -> Response:
        action = request.path_params["action"]
        if action not in ACTIONS:
            return json_response({"ok": False, "error":
                                  f"unknown machine command {action!r}"},
                                 404)
        refusal = read_only_refusal(bench, f"machine {action}")
        if refusal is not None:
            return refusal
        try:
            data = await read_body(request)
        except PermissionError as exc:
            return json_response({"ok": False, "error": str(exc)}, 403)
        except ValueError as exc:
            return json_response({"ok": False, "error": str(exc)}, 400)
        code, answer = await page.run(action, data)
        return json_response(answer, code)

    async def live(ws: WebSocket) -> None:
        await ws.accept()
        serial = max(0, page.serial - 50)   # the recent ones first

        async def reader() -> None:
            while True:
                await ws.receive_text()     # nothing to ask: ignored

        task = asyncio.ensure_future(reader())
        try:
            while not task.done():
                st = page.poll()
                news = page.messages_after(serial)
                message: dict[str, Any] = {"status": st}
                if news:
                    serial = news[-1]["serial"]
                    message["messages"] = news
                await ws.send_json(message)
                await asyncio.wait({task}, timeout=PUSH_PERIOD)
        except (WebSocketDisconnect, RuntimeError, OSError):
            pass
        finally:
            task.cancel()
            with contextlib.suppress(BaseException):
                await task
            page.stop_jogs()

    return [
        Route("/api/machine/status", status),
        Route("/api/machine/messages", messages),
        Route("/api/machine/preview", preview),
        Route("/api/machine/{action}", command, methods=["POST"]),
        WebSocketRoute("/ws/machine", live),
    ]
