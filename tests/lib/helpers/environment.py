"""The process environment of a test: HALSDK_PATH."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator


@contextlib.contextmanager
def on_halsdk_path(folder: str) -> Iterator[str]:
    """Put folder first on HALSDK_PATH while the block runs (the loader
    searches it before the installed components)."""
    old = os.environ.get("HALSDK_PATH")
    os.environ["HALSDK_PATH"] = folder + (os.pathsep + old if old else "")
    try:
        yield folder
    finally:
        if old is None:
            os.environ.pop("HALSDK_PATH", None)
        else:
            os.environ["HALSDK_PATH"] = old
