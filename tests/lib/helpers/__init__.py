"""Helpers shared by the test modules.

``tests/`` is on ``sys.path`` (``pythonpath`` in pyproject's pytest
options), so this package is imported as ``helpers``.  A test module
imports what it shares from here: never from another test module, nor
from ``conftest`` (which holds the fixtures and the session hooks).

The data of the tests (inputs, the reference's recorded outputs, test
component sources) lives under ``tests/data/``; :func:`data_path` names
it, :func:`repo_path` names a file of the checkout (examples, docs,
component sources).
"""

from __future__ import annotations

from pathlib import Path

#: the tests/ folder
TESTS = Path(__file__).resolve().parents[2]
#: the root of the checkout
REPO = TESTS.parent
#: tests/data/
DATA = TESTS / "data"


def data_path(*parts: str) -> Path:
    """A file or folder under tests/data/."""
    return DATA.joinpath(*parts)


def repo_path(*parts: str) -> Path:
    """A file or folder of the checkout (examples/, docs/, components/)."""
    return REPO.joinpath(*parts)


def find_test_module(name: str) -> Path:
    """The test module of basename ``name`` wherever it is under tests/
    (basenames are unique in the suite)."""
    found = sorted(TESTS.rglob(name))
    if len(found) != 1:
        raise LookupError(f"{name}: {len(found)} test modules of that name")
    return found[0]
