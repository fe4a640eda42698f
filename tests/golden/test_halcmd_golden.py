"""The differential corpus of halcmd/halrun: every
``tests/data/halfiles/NAME.hal`` runs with our ``halrun -f`` and is
compared with ``NAME.out``, the output of the reference ``halrun -f
NAME.hal`` (stdout and stderr together) after
:func:`helpers.halrun.normalize`, which removes what cannot match (see
there).

``NAME.rc`` holds the reference's exit status; only zero/non-zero is
compared (the reference halrun's codes come from its shell script).

To make a golden: copy ``NAME.hal`` and its companions (``NAME.ini``,
``NAME.inc``) to an empty folder and there run
``HALTEST_WORD=bar .../reference halrun OPTIONS -f NAME.hal > NAME.out 2>&1``
where OPTIONS are those of the file's first line ``# options: ...``;
write the exit status to ``NAME.rc``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers import data_path
from helpers.halrun import NOTE, halcmd_env, normalize, run_cli, shm_left

HALFILES = data_path("halfiles")


def _options(hal_file: Path) -> list[str]:
    """Options from a first line ``# options: -k ...`` of a HAL file."""
    first = hal_file.read_text().splitlines()[:1]
    if first and first[0].startswith("# options:"):
        return first[0].split(":", 1)[1].split()
    return []


GOLDENS = sorted(p for p in HALFILES.glob("*.hal")
                 if p.with_suffix(".out").exists())


def test_corpus_is_there():
    assert len(GOLDENS) >= 20


@pytest.mark.parametrize("hal_file", GOLDENS, ids=lambda p: p.stem)
def test_golden(hal_file: Path, tmp_path: Path):
    """Our halrun prints what the reference printed (normalized)."""
    for extra in HALFILES.glob(hal_file.stem + ".*"):
        if extra.suffix not in (".out", ".rc"):
            (tmp_path / extra.name).write_bytes(extra.read_bytes())
    env = halcmd_env(tmp_path, hal_file.stem)
    proc = run_cli(["halrun", *_options(hal_file), "-f", hal_file.name],
                   tmp_path, env)
    expected = normalize(hal_file.with_suffix(".out").read_text())
    assert normalize(proc.stdout) == expected
    ref_rc = int(hal_file.with_suffix(".rc").read_text())
    assert (proc.returncode == 0) == (ref_rc == 0), proc.stdout
    assert shm_left(env) == []


def test_normalize_keeps_widths_and_drops_notes():
    text = (NOTE + "\n"
            "     7  User  halcmd4395" + " " * 37 + "  4395 ready\n"
            "     8  bit   IN           TRUE  and2.0.in0\n"
            " 00008  7fa520eee189  7fa52003d140  NO       0   and2.0\n")
    out = normalize(text).splitlines()
    assert out[0] == "    ID  User  halcmd<PID>" + " " * 36 + "   PID ready"
    assert out[1] == "    ID  bit   IN           TRUE  and2.0.in0"
    assert out[2].endswith("  NO       0   and2.0")
    assert "7fa5" not in out[2]
