"""The load listings of the motion module motmod compared with the
reference's (``tests/data/motion/motmod-*``: ``show pin/param/funct/thread``
after loading trivkins, homemod, tpmod and motmod), and the loads the
reference refuses too, refused with our reason."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from helpers import data_path
from helpers.halrun import halcmd_env as _env
from helpers.halrun import normalize
from helpers.halrun import run_cli as _cli
from helpers.halrun import shm_left as _shm_left

MOTION = data_path("motion")


def _tables(text: str) -> list[str]:
    """The show tables without component lines, addresses and owner ids."""
    out = []
    for line in normalize(text).splitlines():
        f = line.split()
        if not f or line.startswith("Note:") or "servo-thread.t" in line \
                or "base-thread.t" in line:
            continue
        if re.match(r"^    ID  (bit|float|s32|u32)", line):
            out.append(" ".join(f[1:]))
        elif len(f) >= 4 and f[-3] in ("YES", "NO") and f[-2].isdigit():
            out.append(" ".join(f[-3:]))          # a function row
        elif re.match(r"^ +\d+ +(YES|NO) ", line):
            out.append(" ".join(f[:3]))
        elif line.endswith(":"):
            out.append(line)
    return out


@pytest.mark.parametrize("case", ["motmod-3joints", "motmod-5joints"])
def test_load_listing_matches_reference(case: str, tmp_path: Path):
    hal_file = MOTION / f"{case}.hal"
    (tmp_path / hal_file.name).write_bytes(hal_file.read_bytes())
    env = _env(tmp_path, case)
    proc = _cli(["halrun", "-f", hal_file.name], tmp_path, env)
    assert proc.returncode == 0, proc.stdout
    ours = _tables(proc.stdout)
    ref = _tables(hal_file.with_suffix(".out").read_text())
    assert len(ref) > 300
    assert ours == ref
    assert _shm_left(env) == []


# loads the reference refuses too (its stderr in the .out file); our
# reason for each
REF_ERRORS = {
    "motmod-err-num-joints": "motmod: num_joints=17 is out of range (1..16)",
    "motmod-err-num-dio": "motmod: num_dio=65 is out of range (1..64)",
    "motmod-err-no-kins": "motmod: no kinematics module is loaded "
                          "(loadrt trivkins first)",
    "motmod-err-extrajoints": "motmod: num_extrajoints=1 needs kinematics "
                              "of type BOTH",
}


@pytest.mark.parametrize("case", sorted(REF_ERRORS))
def test_load_refusals_like_the_reference(case: str, tmp_path: Path):
    hal_file = MOTION / f"{case}.hal"
    assert "rtapi_app_main" in hal_file.with_suffix(".out").read_text() \
        or "undefined symbol" in hal_file.with_suffix(".out").read_text()
    (tmp_path / hal_file.name).write_bytes(hal_file.read_bytes())
    env = _env(tmp_path, case)
    proc = _cli(["halrun", "-f", hal_file.name], tmp_path, env)
    assert proc.returncode != 0
    assert REF_ERRORS[case] in proc.stdout
    assert _shm_left(env) == []
