"""examples/mill holds the demo's mill files (halsdk/demo/mill) for a
checkout; the two must not drift apart."""

from __future__ import annotations

import pytest
from helpers import repo_path

FILES = ("mill.ini", "mill.hal", "toolchange.hal", "tool.tbl", "demo.ngc")


@pytest.mark.parametrize("name", FILES)
def test_the_example_mill_is_the_demos(name):
    example = repo_path("examples", "mill", name)
    assert not example.is_symlink()
    assert example.read_bytes() == \
        repo_path("halsdk", "demo", "mill", name).read_bytes()
