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
    running alongside is not counted. Under pytest-xdist each worker checks
    its own and hands what it found to the controller."""
    prefix = f"halsdk-{os.getuid()}"
    mark = f"-{os.getpid()}"
    return {n for n in os.listdir("/dev/shm")
            if n.startswith(prefix) and (mark + "-" in n or n.endswith(mark))}


_before: set[str] = set()
_left_by_workers: list[str] = []


def pytest_sessionstart(session: pytest.Session) -> None:
    _before.update(_halsdk_segments())


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The examples run whole machines in real time and check how closely
    they follow: they are ``serial`` (CI runs them alone, after the rest
    ran on two workers; see the README)."""
    examples = os.path.join("tests", "examples") + os.sep
    for item in items:
        if examples in str(item.path):
            item.add_marker(pytest.mark.serial)


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: object, error: object) -> None:
    """pytest-xdist, in the controller: a worker's leftover instances."""
    output = getattr(node, "workeroutput", {})
    _left_by_workers.extend(output.get("halsdk_left", []))


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """The suite ends by checking that no test left an instance behind."""
    left = sorted(_halsdk_segments() - _before)
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:        # an xdist worker: tell the controller
        workeroutput["halsdk_left"] = left
        return
    left += _left_by_workers
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
