"""Suite-wide setup: the test components, and the /dev/shm check."""

from __future__ import annotations

import os
import sys

import pytest
from helpers import data_path
from helpers.environment import on_halsdk_path

from halsdk.build import build_component

COMPONENTS = str(data_path("components"))
TEST_COMPONENTS = ["tand2.pyx", "tcounter.pyx", "tlowpass.pyx", "cscale.c"]


def _halsdk_segments() -> set[str]:
    """Instances of this session: their names carry the session's pid (the
    fixture's and the tests' private names do), so a second pytest session
    running alongside is not counted."""
    prefix = f"halsdk-{os.getuid()}"
    mark = f"-{os.getpid()}"
    return {n for n in os.listdir("/dev/shm")
            if n.startswith(prefix) and (mark + "-" in n or n.endswith(mark))}


_before: set[str] = set()


def pytest_sessionstart(session: pytest.Session) -> None:
    _before.update(_halsdk_segments())


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """The suite ends by checking that no test left an instance behind."""
    left = sorted(_halsdk_segments() - _before)
    if left:
        print(f"\nFAILED: HAL instances left in /dev/shm: {', '.join(left)}")
        session.exitstatus = 1
    else:
        print("\n/dev/shm check: no HAL instance left behind")


@pytest.fixture(scope="session", autouse=True)
def component_path(tmp_path_factory: pytest.TempPathFactory) -> str:
    """Build the test components (cached by content) into a folder on
    HALSDK_PATH, so that loadrt finds them by name."""
    folder = str(tmp_path_factory.mktemp("halsdk-path"))
    for source in TEST_COMPONENTS:
        build_component(os.path.join(COMPONENTS, source), out_dir=folder)
    with on_halsdk_path(folder):
        yield folder


@pytest.fixture
def python_tools_first(monkeypatch: pytest.MonkeyPatch) -> str:
    """Put the bin folder of the Python under test first on PATH, so that
    ``loadusr PROGRAM`` runs this halsdk's program and not one of the same
    name from elsewhere (the reference installs mb2hal, for one)."""
    folder = os.path.dirname(sys.executable)
    monkeypatch.setenv("PATH", folder + os.pathsep + os.environ["PATH"])
    return folder
