"""Existing LinuxCNC HAL files run unchanged (issue 18, halcmd part):
``loadrt threads`` and its defaults, quoted module parameters, quotes in
``loadusr`` words and INI values, and Python programs that ``import hal``
started by ``halrun``.

Every ``tests/data/halfiles_lcnc/NAME.hal`` that has a ``NAME.out`` runs
with our ``halrun -f`` and is compared with the reference's output
(normalized as in ``tests/golden/test_halcmd_golden.py``); ``NAME.rc``
holds the reference's exit status.  To make a golden: copy ``NAME.hal``,
``NAME.ini`` and the folder's ``*.py`` to an empty folder and there run
``.../reference halrun OPTIONS -f NAME.hal > NAME.out 2>&1; echo $? >
NAME.rc``, with the OPTIONS of the file's ``# options:`` first line.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from helpers import data_path
from helpers.halrun import normalize, run_cli, shm_left

import halsdk
import halsdk.compat
from halsdk.hal import Hal

FILES = data_path("halfiles_lcnc")
GOLDENS = sorted(p for p in FILES.glob("*.hal")
                 if p.with_suffix(".out").exists())


def _options(hal_file: Path) -> list[str]:
    first = hal_file.read_text().splitlines()[:1]
    if first and first[0].startswith("# options:"):
        return first[0].split(":", 1)[1].split()
    return []


def _env(name: str) -> dict:
    """Its own instance, and this Python first on PATH: the files start
    ``python3``, which must be the Python that has this halsdk."""
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = f"h1-{os.getpid()}-{name}"
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env["PATH"]
    return env


def _halrun(hal_file: Path, tmp_path: Path, env: dict):
    for extra in FILES.iterdir():
        if extra.suffix == ".py" or extra.name.startswith(hal_file.stem + "."):
            (tmp_path / extra.name).write_bytes(extra.read_bytes())
    return run_cli(["halrun", *_options(hal_file), "-f", hal_file.name],
                   tmp_path, env)


def test_the_files_are_there():
    assert len(GOLDENS) >= 11


@pytest.mark.parametrize("hal_file", GOLDENS, ids=lambda p: p.stem)
def test_as_the_reference(hal_file: Path, tmp_path: Path):
    env = _env(hal_file.stem)
    proc = _halrun(hal_file, tmp_path, env)
    expected = normalize(hal_file.with_suffix(".out").read_text())
    assert normalize(proc.stdout) == expected
    ref_rc = int(hal_file.with_suffix(".rc").read_text())
    assert (proc.returncode == 0) == (ref_rc == 0), proc.stdout
    assert shm_left(env) == []


def test_ini_value_with_a_blank_makes_two_words(tmp_path: Path):
    """The reference fails too (its module loader's words differ)."""
    env = _env("ini-split")
    proc = _halrun(FILES / "quotes_ini_split.hal", tmp_path, env)
    assert proc.returncode != 0
    assert "and2: 'two' is not name=value" in proc.stdout
    assert "quotes_ini_split.hal:3: insmod for and2 failed" in proc.stdout
    assert shm_left(env) == []


def test_single_quotes_are_not_removed(tmp_path: Path):
    """The reference's module loader removes only double quotes: a
    single-quoted number is refused, by both."""
    (tmp_path / "sq.hal").write_text("loadrt stepgen step_type='0,0'\n")
    env = _env("single")
    proc = run_cli(["halrun", "-f", "sq.hal"], tmp_path, env)
    assert proc.returncode != 0
    assert "step_type=\"'0\" is not an integer" in proc.stdout
    assert "sq.hal:1: insmod for stepgen failed, returned -1" in proc.stdout
    assert shm_left(env) == []


def test_a_quoted_name_with_a_blank_is_refused_clearly(tmp_path: Path):
    """The blank reaches the module (as in the reference), but halsdk
    refuses HAL names with blanks (docs/compat.md)."""
    (tmp_path / "bl.hal").write_text('loadrt and2 names="x y,z"\n')
    env = _env("blank")
    proc = run_cli(["halrun", "-f", "bl.hal"], tmp_path, env)
    assert proc.returncode != 0
    assert "and2: pin name 'x y.in0' contains a blank" in proc.stdout
    assert shm_left(env) == []


def test_quoted_words_through_the_api(hal: Hal):
    """``Hal.loadrt`` and ``newinst`` read words as halcmd's loadrt."""
    hal.loadrt("and2", 'names="g-a,g-b"')
    assert [f.name for f in hal.items("function")] == ["g-a", "g-b"]
    with pytest.raises(halsdk.HalError, match="unterminated quoted"):
        hal.loadrt("or2", 'names="x')


def test_loadusr_programs_get_the_compat_modules(tmp_path: Path):
    """The compat folder first on PYTHONPATH, the user's after it."""
    (tmp_path / "pp.py").write_text(
        "import os, sys\n"
        "print('PP', os.environ['PYTHONPATH'], flush=True)\n")
    (tmp_path / "pp.hal").write_text("loadusr -w python3 pp.py\n")
    env = _env("pypath")
    env["PYTHONPATH"] = "/nowhere/a" + os.pathsep + "/nowhere/b"
    proc = run_cli(["halrun", "-f", "pp.hal"], tmp_path, env)
    assert proc.returncode == 0, proc.stdout
    first = halsdk.compat.pythonpath()
    assert f"PP {first}:/nowhere/a:/nowhere/b" in proc.stdout.splitlines()
    assert shm_left(env) == []


def test_program_env_puts_compat_first_once():
    first = halsdk.compat.pythonpath()
    assert halsdk.compat.program_env({})["PYTHONPATH"] == first
    env = halsdk.compat.program_env({"PYTHONPATH": f"/a:{first}:/b"})
    assert env["PYTHONPATH"] == f"{first}:/a:/b"
