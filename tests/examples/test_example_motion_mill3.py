"""examples/motion: the simulated three-joint mill is enabled, homed,
jogged and read through halsdk.motion, deterministically."""

from __future__ import annotations

import importlib.util
import os

import pytest
from helpers import repo_path

EXAMPLE = str(repo_path("examples", "motion", "mill3.py"))


@pytest.fixture(scope="module")
def mill3():
    spec = importlib.util.spec_from_file_location("mill3_example", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_mill3_enables_homes_jogs_and_reports(mill3, capsys):
    result = mill3.run(realtime=False, instance=f"test-mill3-{os.getpid()}")
    out = capsys.readouterr().out
    assert result["homed"] == [True, True, True]
    x, y, z = result["pos"]
    assert x == pytest.approx(20.0, abs=1e-9)      # two cumulative +10 jogs
    assert y == pytest.approx(40.0, abs=1e-9)      # the absolute jog
    assert -80 < z < -5                            # stopped after the jog
    for joint in result["ferror_max"]:
        assert 0 < joint < 5                       # moved, under FERROR
    assert result["errors"] == []
    assert "homed: mode free, enabled" in out
