"""The web workbench as an ASGI application (starlette).

:func:`create_app` makes it for one instance: the static page, the JSON
API of the Show page and its websocket of live values, all behind
:class:`TokenGate`.

Security (docs/web.rst):

- every request and websocket needs the token: ``?token=...`` once (the
  URL that ``halsdk web`` prints), then a cookie (HttpOnly,
  SameSite=Strict) that the first visit sets; anything else is 403;
- a websocket's ``Origin`` must name the host it connects to, and so must
  the ``Origin`` of a request that changes something, which must also be
  JSON (a cross-site form cannot send it);
- read-only refuses every change with 403 and says why;
- names are data: every change goes to halcmd as a list of words, and the
  page puts names into the document as text, never as HTML.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import secrets
from collections.abc import AsyncIterator, Awaitable
from http.cookies import CookieError, SimpleCookie
from importlib import resources
from typing import Any, Callable, Optional
from urllib.parse import parse_qsl, urlencode

from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import FileResponse, PlainTextResponse, Response
from starlette.routing import BaseRoute, Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.types import ASGIApp, Message, Receive, Scope, Send
from starlette.websockets import WebSocket, WebSocketDisconnect

from halsdk.errors import HalError
from halsdk.hal import Hal
from halsdk.web import latency, machine, scope
from halsdk.web.common import (
    HEADERS,
    Workbench,
    json_response,
    read_body,
    read_only_refusal,
    refused,
    same_origin,
    word,
)
from halsdk.web.show import KINDS, Refused

#: how often the websocket looks at the watched values (20 Hz: at least
#: the 10 updates a second that the page promises)
PUSH_PERIOD = 0.05
#: how often it looks whether objects were added or removed
TREE_PERIOD = 1.0
#: the most keys one page may watch
MAX_WATCH = 5000

FORBIDDEN = ("403 Forbidden: this workbench needs its token: open the "
             "URL that `halsdk web` printed\n")
def static_folder() -> str:
    """The folder of the page's static files (package data)."""
    return str(resources.files("halsdk.web") / "static")


def cookie_name(scope: Scope) -> str:
    """The token's cookie: one per port, since cookies ignore ports and
    two workbenches may run on one host."""
    server = scope.get("server") or ("", 0)
    return f"halsdk-web-{server[1] or 0}"


def _headers(scope: Scope) -> dict[str, str]:
    return {k.decode("latin-1").lower(): v.decode("latin-1")
            for k, v in scope.get("headers", [])}


class TokenGate:
    """ASGI middleware: the token (query once, then the cookie) for every
    request and websocket; the websocket's Origin must match its Host."""

    def __init__(self, app: ASGIApp, token: str):
        self.app = app
        self.token = token

    def _good(self, given: Optional[str]) -> bool:
        return given is not None and secrets.compare_digest(
            given.encode("utf-8", "surrogateescape"),
            self.token.encode("utf-8"))

    async def __call__(self, scope: Scope, receive: Receive,
                       send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = _headers(scope)
        query = parse_qsl(scope.get("query_string", b"").decode("latin-1"),
                          keep_blank_values=True)
        given = [v for k, v in query if k == "token"]
        name = cookie_name(scope)
        cookie: Optional[str] = None
        try:
            jar = SimpleCookie(headers.get("cookie", ""))
            if name in jar:
                cookie = jar[name].value
        except CookieError:
            cookie = None
        by_query = bool(given) and all(self._good(g) for g in given)
        if not (by_query or self._good(cookie)):
            await self._refuse(scope, receive, send, FORBIDDEN)
            return
        if scope["type"] == "websocket":
            if not same_origin(headers.get("origin"), headers.get("host")):
                await self._refuse(scope, receive, send,
                                   "403 Forbidden: the websocket's Origin "
                                   "is not this workbench\n")
                return
            await self.app(scope, receive, send)
            return
        if not by_query:
            await self.app(scope, receive, send)
            return
        set_cookie = (f"{name}={self.token}; Path=/; HttpOnly; "
                      "SameSite=Strict").encode("latin-1")
        if scope["method"] in ("GET", "HEAD") and scope["path"] == "/":
            # into the cookie and out of the address bar (and history)
            rest = urlencode([(k, v) for k, v in query if k != "token"])
            response = Response(status_code=303, headers={
                "Location": "/" + ("?" + rest if rest else ""),
                **HEADERS})
            response.raw_headers.append((b"set-cookie", set_cookie))
            await response(scope, receive, send)
            return

        async def send_with_cookie(message: Message) -> None:
            if message["type"] == "http.response.start":
                message = dict(message)
                message["headers"] = [*message.get("headers", []),
                                      (b"set-cookie", set_cookie)]
            await send(message)

        await self.app(scope, receive, send_with_cookie)

    async def _refuse(self, scope: Scope, receive: Receive, send: Send,
                      text: str) -> None:
        if scope["type"] == "websocket":
            # closing before accepting: the server answers the
            # handshake with 403
            await receive()                 # websocket.connect
            await send({"type": "websocket.close", "code": 1008})
            return
        await PlainTextResponse(text, status_code=403,
                                headers=HEADERS)(scope, receive, send)


#: the changes of the page: the halcmd words of each from its JSON body
ACTIONS: dict[str, Callable[[dict[str, Any]], list[str]]] = {
    "setp": lambda d: ["setp", word(d, "name"), word(d, "value")],
    "sets": lambda d: ["sets", word(d, "name"), word(d, "value")],
    "unlinkp": lambda d: ["unlinkp", word(d, "pin")],
    "net": lambda d: ["net", word(d, "signal"),
                      *[word({"pin": p}, "pin") for p in _list(d, "pins")]],
    "addf": lambda d: ["addf", word(d, "function"), word(d, "thread"),
                       *([word(d, "position")]
                         if d.get("position") not in (None, "") else [])],
    "delf": lambda d: ["delf", word(d, "function"), word(d, "thread")],
}


def _list(data: dict[str, Any], key: str) -> list[Any]:
    value = data.get(key, [])
    if not isinstance(value, list):
        raise ValueError(f"'{key}' is not a list")
    return value


#: the pages: their path and their static HTML file
PAGES = {"/": "index.html", "/scope": "scope.html",
         "/machine": "machine.html", "/latency": "latency.html"}


def create_app(hal: Hal, *, token: str, read_only: bool = False) -> Starlette:
    """The workbench of ``hal``, behind ``token``."""
    if not token:
        raise ValueError("the workbench needs a token")
    bench = Workbench(hal, read_only=read_only)
    static = static_folder()

    def page(filename: str) -> Callable[[Request], Awaitable[Response]]:
        async def serve(request: Request) -> Response:
            return FileResponse(f"{static}/{filename}", headers=HEADERS)
        return serve

    async def info(request: Request) -> Response:
        return json_response(await bench.call(bench.show.info))

    async def tree(request: Request) -> Response:
        return json_response(await bench.call(bench.show.tree))

    async def item(request: Request) -> Response:
        kind = request.query_params.get("kind", "")
        name = request.query_params.get("name", "")
        if kind not in KINDS.values():
            return json_response({"error": f"unknown kind {kind!r}"}, 400)
        return json_response(await bench.call(bench.show.detail, kind, name))

    async def values(request: Request) -> Response:
        keys = request.query_params.getlist("key")[:MAX_WATCH]
        return json_response(await bench.call(bench.show.values, keys))

    async def change(request: Request) -> Response:
        action = request.path_params["action"]
        if action not in ACTIONS:
            return json_response({"error": f"unknown action {action!r}"}, 404)
        refusal = read_only_refusal(bench, action)
        if refusal is not None:
            return refusal

        async def run() -> dict[str, Any]:
            words = ACTIONS[action](await read_body(request))
            return await bench.call(bench.show.run_words, words)
        return await _answer(run)

    async def command(request: Request) -> Response:
        """The command line; read-only still runs the commands that only
        read (show, getp, ...)."""
        async def run() -> dict[str, Any]:
            line = (await read_body(request)).get("line")
            if not isinstance(line, str):
                raise ValueError("'line' is missing or not a string")
            return await bench.call(bench.show.command, line)
        return await _answer(run)

    async def _answer(run: Callable[[], Awaitable[dict[str, Any]]]
                      ) -> Response:
        """The reply to a change or a command: 403 refused, 400 a bad
        request, else its result (409 when halcmd said no)."""
        try:
            result = await run()
        except (PermissionError, Refused) as exc:
            return refused(str(exc))
        except ValueError as exc:
            return json_response({"ok": False, "output": "", "error": f"{exc}\n"},
                         400)
        return json_response(result, 200 if result["ok"] else 409)

    async def live(ws: WebSocket) -> None:
        await ws.accept()
        watched: list[str] = []
        last: dict[str, Optional[str]] = {}
        counts: Optional[dict[str, int]] = None
        loop = asyncio.get_running_loop()
        next_tree = loop.time()

        async def reader() -> None:
            nonlocal watched, last
            while True:
                try:
                    message = json.loads(await ws.receive_text())
                except ValueError:
                    continue                # not JSON: not a request
                keys = message.get("watch") if isinstance(message,
                                                          dict) else None
                if isinstance(keys, list):
                    watched = [k for k in keys if isinstance(k, str)][
                        :MAX_WATCH]
                    last = {}               # send them all once

        task = asyncio.ensure_future(reader())
        try:
            while not task.done():
                keys = list(watched)
                now = await bench.call(bench.show.values, keys)
                changed = {k: v for k, v in now.items()
                           if k not in last or last[k] != v}
                last.update(changed)
                if changed:
                    await ws.send_json({"values": changed})
                if loop.time() >= next_tree:
                    next_tree = loop.time() + TREE_PERIOD
                    info = await bench.call(bench.show.info)
                    if counts is not None and info["counts"] != counts:
                        await ws.send_json({"tree": info})
                    counts = info["counts"]
                await asyncio.wait({task}, timeout=PUSH_PERIOD)
        except (WebSocketDisconnect, RuntimeError, OSError, HalError):
            pass
        finally:
            task.cancel()
            with contextlib.suppress(BaseException):
                await task

    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        yield
        bench.close()

    routes: list[BaseRoute] = [
        *[Route(path, page(filename)) for path, filename in PAGES.items()],
        Route("/api/info", info),
        Route("/api/tree", tree),
        Route("/api/item", item),
        Route("/api/values", values),
        Route("/api/command", command, methods=["POST"]),
        Route("/api/{action}", change, methods=["POST"]),
        WebSocketRoute("/ws", live),
        *scope.routes(bench),
        *machine.routes(bench),
        *latency.routes(bench),
        Mount("/static", StaticFiles(directory=static), name="static"),
    ]
    app = Starlette(routes=routes, lifespan=lifespan)
    app.state.workbench = bench
    app.add_middleware(TokenGate, token=token)
    return app
