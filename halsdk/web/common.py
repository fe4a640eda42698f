"""What every page of the workbench shares: the response headers, the
one worker thread of HAL calls (:class:`Workbench`), and the reading of
a change's JSON body with its origin check."""

from __future__ import annotations

import asyncio
import contextlib
import json
from concurrent.futures import ThreadPoolExecutor
from functools import partial
from typing import Any, Callable, Optional, TypeVar
from urllib.parse import urlsplit

from starlette.requests import Request
from starlette.responses import JSONResponse

from halsdk.hal import Hal
from halsdk.web.show import Show

HEADERS = {
    "Content-Security-Policy": (
        "default-src 'self'; connect-src 'self'; img-src 'self' data: blob:; "
        "object-src 'none'; base-uri 'none'; frame-ancestors 'none'"),
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-store",
}

T = TypeVar("T")


def same_origin(origin: Optional[str], host: Optional[str]) -> bool:
    """True when an ``Origin`` header names the ``Host`` it was sent to."""
    if not origin or not host:
        return False
    try:
        parts = urlsplit(origin)
    except ValueError:
        return False
    return parts.scheme in ("http", "https") and parts.netloc == host


class Workbench:
    """The state of one workbench: the instance's :class:`Show` and the
    one worker thread that every HAL call runs on, one at a time (so a
    slow command never runs beside a value read of another page).

    ``pages`` holds the state of the other pages by name (their modules
    put it there; :meth:`close` closes what has a ``close``)."""

    def __init__(self, hal: Hal, *, read_only: bool = False):
        self.hal = hal
        self.show = Show(hal, read_only=read_only)
        self.read_only = read_only
        self.pages: dict[str, Any] = {}
        self._pool = ThreadPoolExecutor(1, thread_name_prefix="halsdk-web")

    async def call(self, fn: Callable[..., T], *args: Any) -> T:
        loop = asyncio.get_running_loop()
        return await loop.run_in_executor(self._pool, partial(fn, *args))

    def submit(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` on the worker without waiting for it: the
        clean-up of a handler that may itself be cancelled (a test
        client or a server shutting down cancels it, and every await
        in its ``finally`` is then cancelled too). Once the workbench
        is closed, :meth:`close` cleans up instead."""
        with contextlib.suppress(RuntimeError):     # the pool is shut down
            self._pool.submit(fn, *args)

    def close(self) -> None:
        for page in list(self.pages.values()):
            close = getattr(page, "close", None)
            if close is not None:
                close()
        self._pool.shutdown(wait=True, cancel_futures=True)


def json_response(data: Any, status: int = 200) -> JSONResponse:
    return JSONResponse(data, status_code=status, headers=HEADERS)


def refused(message: str) -> JSONResponse:
    """403 with halcmd's shape of answer."""
    return json_response({"ok": False, "output": "",
                          "error": message + "\n"}, 403)


def read_only_refusal(bench: Workbench, action: str) -> Optional[JSONResponse]:
    """The 403 of a change when the workbench is read-only, else None."""
    if not bench.read_only:
        return None
    return refused(f"{action}: read-only: this workbench was started with "
                   "--read-only and changes nothing")


async def read_body(request: Request) -> dict[str, Any]:
    """The JSON object of a change; ValueError for anything else,
    PermissionError when its Origin is another site."""
    kind = request.headers.get("content-type", "").split(";")[0].strip()
    if kind != "application/json":
        raise ValueError("a change is a JSON request "
                         "(Content-Type: application/json)")
    origin = request.headers.get("origin")
    if origin is not None and not same_origin(origin,
                                              request.headers.get("host")):
        raise PermissionError("the request's Origin is not this workbench")
    try:
        data = json.loads(await request.body())
    except ValueError:
        raise ValueError("the request's body is not JSON") from None
    if not isinstance(data, dict):
        raise ValueError("the request's body is not a JSON object")
    return data


def word(data: dict[str, Any], key: str) -> str:
    """``data[key]`` as one word (a string or a number)."""
    value = data.get(key)
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise ValueError(f"'{key}' is missing or not a string")
    return str(value)
