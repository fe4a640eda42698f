"""The load listings of the kinematics modules (trivkins, corexykins,
scarakins, lineardeltakins) compared with the reference's:
``tests/data/motion/kins-NAME.hal`` run with our ``halrun -f``, its show
tables compared with the reference's output ``kins-NAME.out`` (exit
status ``kins-NAME.rc``); the loads the reference refuses are refused
with our reason."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers import data_path
from helpers.halrun import halcmd_env as _env
from helpers.halrun import normalize
from helpers.halrun import run_cli as _cli
from helpers.halrun import shm_left as _shm_left

MOTION = data_path("motion")


def _tables(text: str) -> list[str]:
    """The show tables of a halrun output, without the module's chatter."""
    keep = ("Loaded HAL Components:", "ID      Type", "Component Pins:",
            "Owner   ", "Parameters:", "Exported Functions:")
    return [line for line in normalize(text).splitlines()
            if line.startswith(keep) or line.startswith("    ID")
            or line.startswith(" IDIDI")]


GOLDENS = sorted(MOTION.glob("kins-*.hal"))
# our reason for each load the reference refuses too
REASONS = {
    "kins-trivkins-bad-letter": "'q' (joint 3) is not an axis letter",
    "kins-trivkins-empty": "coordinates= is empty",
    "kins-trivkins-unknown-param": "Unknown parameter `foo=1'",
    "kins-corexykins-coordinates": "Unknown parameter `coordinates=xyz'",
}


def test_golden_corpus_is_there():
    assert len(GOLDENS) >= 9
    assert set(REASONS) < {p.stem for p in GOLDENS}


@pytest.mark.parametrize("hal_file", GOLDENS, ids=lambda p: p.stem)
def test_load_listing_matches_reference(hal_file: Path, tmp_path: Path):
    (tmp_path / hal_file.name).write_bytes(hal_file.read_bytes())
    env = _env(tmp_path, hal_file.stem)
    proc = _cli(["halrun", "-f", hal_file.name], tmp_path, env)
    ref = hal_file.with_suffix(".out").read_text()
    ref_ok = int(hal_file.with_suffix(".rc").read_text()) == 0
    assert (proc.returncode == 0) == ref_ok, proc.stdout
    assert _tables(proc.stdout) == _tables(ref)
    if not ref_ok:
        assert REASONS[hal_file.stem] in proc.stdout
    assert _shm_left(env) == []
