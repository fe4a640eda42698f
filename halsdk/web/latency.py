"""The Latency page of the workbench (under construction)."""

from __future__ import annotations

from starlette.routing import BaseRoute

from halsdk.web.common import Workbench


def routes(bench: Workbench) -> list[BaseRoute]:
    """The API routes of the page (under /api/latency/)."""
    return []
