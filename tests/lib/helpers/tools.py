"""Programs of the machine that some tests need (mosquitto, openssl):
without one those tests are skipped, with the reason and the install
command, except in CI (``CI`` set), where a missing program is a
failure (``.ci/run`` installs them)."""

from __future__ import annotations

import os
import shutil
from typing import NoReturn

import pytest


def in_ci() -> bool:
    return bool(os.environ.get("CI"))


def unavailable(why: str) -> NoReturn:
    """Skip the test for ``why`` (which says what to install), or fail it
    in CI."""
    if in_ci():
        pytest.fail(f"{why} (CI is set: the tests need it)")
    pytest.skip(why)


def need_program(name: str, package: str, what: str) -> str:
    """The path of program ``name``; skips (fails in CI) when missing."""
    path = shutil.which(name)
    if path is None:
        unavailable(f"{name} is not installed: {what} (apt-get install "
                    f"{package})")
    return path
