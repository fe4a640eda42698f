"""More of the differential corpus: streams goldens and named tests.

``tests/data/streams/NAME.hal`` use ``threads``, ``sampler``, ``streamer``
and the ``halsampler``/``halstreamer`` programs through ``loadusr -w``.
Their goldens are the reference's stdout (``NAME.out``) and stderr
without the ``Note: Using POSIX non-realtime`` lines (``NAME.stderr``,
absent when empty) of ``.../reference halrun -f NAME.hal`` run in a
folder holding the inputs.  Here our ``halrun`` runs them the same way.

The other tests cover commands and options whose reference output cannot
be a golden (help texts, debugging output) or that the reference lacks;
``tests/halcmd/test_halcmd_coverage.py`` refers to them by name.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import data_path
from helpers.halrun import tools_env as _env

from halsdk.core import _core
from halsdk.halcmd import CommandRunner

STREAMS = data_path("streams")
NOTE = "Note: Using POSIX non-realtime"
STREAM_GOLDENS = sorted(p for p in STREAMS.glob("*.hal")
                        if p.with_suffix(".out").exists())


def _shm_left(env: dict) -> list[str]:
    return [n for n in os.listdir("/dev/shm")
            if env["HALSDK_INSTANCE"] in n]


def _halrun(args: list[str], cwd: Path, env: dict, stdin: str = "",
            merge: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", *args],
        cwd=cwd, env=env, input=stdin, stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT if merge else subprocess.PIPE, text=True,
        timeout=120)


def test_stream_corpus_is_there():
    assert len(STREAM_GOLDENS) >= 4
    texts = " ".join(p.read_text() for p in STREAM_GOLDENS)
    for word in ("loadrt threads", "loadrt sampler", "loadrt streamer",
                 "loadusr -w halsampler", "-n ", "loadusr -w halstreamer"):
        assert word in texts


@pytest.mark.parametrize("hal_file", STREAM_GOLDENS, ids=lambda p: p.stem)
def test_stream_golden(hal_file: Path, tmp_path: Path):
    """threads + streamer + sampler + halsampler -n N: the reference's
    lines, on stdout and on stderr."""
    work = tmp_path / "work"
    work.mkdir()
    for extra in STREAMS.iterdir():
        if extra.suffix not in (".out", ".stderr"):
            shutil.copy(extra, work / extra.name)
    env = _env(hal_file.stem, tmp_path / "bin")
    proc = _halrun(["-f", hal_file.name], work, env, merge=False)
    assert proc.stdout == hal_file.with_suffix(".out").read_text()
    err_file = hal_file.with_suffix(".stderr")
    expected_err = err_file.read_text() if err_file.exists() else ""
    err = "".join(line for line in proc.stderr.splitlines(True)
                  if line.rstrip("\n") != NOTE)
    assert err == expected_err
    assert proc.returncode == 0
    assert _shm_left(env) == []


# ------------------------------------------------------- named tests

def test_help_options(tmp_path: Path):
    """-h prints a usage naming the options, and exits with success."""
    env = _env("help", tmp_path / "bin")
    proc = subprocess.run([sys.executable, "-m", "halsdk.halcmd.cli",
                           "halcmd", "-h"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0
    for opt in ("-f", "-i", "-k", "-q", "-Q", "-s", "-v", "-V", "-e"):
        assert f"  {opt} " in proc.stdout, opt
    proc = _halrun(["-h"], tmp_path, env)
    assert proc.returncode == 0
    for opt in ("-I", "-U"):
        assert opt in proc.stdout
    assert _shm_left(env) == []


def test_very_verbose_option(tmp_path: Path):
    """-V runs the file; the results of commands are printed as without
    it (the reference adds its own debugging lines, which we do not)."""
    (tmp_path / "v.hal").write_text("newsig a s32\nsets a 5\ngets a\n"
                                    "bogus\n")
    env = _env("vv", tmp_path / "bin")
    proc = _halrun(["-k", "-V", "-f", "v.hal"], tmp_path, env)
    assert proc.returncode == 1
    assert "5\n" in proc.stdout
    assert "v.hal:4: Unknown command 'bogus'\n" in proc.stdout
    assert _shm_left(env) == []


def test_release_mutex_option(tmp_path: Path):
    """-R is accepted; the core's mutex is robust, so there is nothing
    left to release after a crash."""
    (tmp_path / "r.hal").write_text("newsig a bit\n")
    env = _env("rel", tmp_path / "bin")
    proc = _halrun(["-R", "-f", "r.hal"], tmp_path, env)
    assert proc.returncode == 0, proc.stdout
    assert "Traceback" not in proc.stdout
    assert _shm_left(env) == []


def test_waitusr_waits_for_exit(tmp_path: Path):
    (tmp_path / "ucomp.py").write_text(
        "import time\nimport halsdk\n"
        "c = halsdk.component('wcomp')\nc.newpin('x', 'bit', 'out')\n"
        "c.ready()\ntime.sleep(0.6)\nc.exit()\n")
    (tmp_path / "w.hal").write_text(
        f"loadusr -Wn wcomp {sys.executable} ucomp.py\n"
        "list comp wcomp\nwaitusr wcomp\nlist comp wcomp\n")
    env = _env("wait", tmp_path / "bin")
    start = time.monotonic()
    proc = _halrun(["-k", "-f", "w.hal"], tmp_path, env)
    lines = proc.stdout.splitlines()
    assert lines[0] == "wcomp "
    assert lines[1:] == [""]              # gone after waitusr
    assert time.monotonic() - start >= 0.5
    assert proc.returncode == 0
    assert _shm_left(env) == []


def _executor(hal, out: list, err: list) -> CommandRunner:
    return CommandRunner(hal, out=out.append, err=err.append, register=False)


def test_status_all_and_default(hal):
    """``status``/``status all`` print the lock status then the memory."""
    out: list[str] = []
    err: list[str] = []
    ex = _executor(hal, out, err)
    assert ex.run_line("status all")
    text = "".join(out)
    assert text.startswith("HAL locking status:\n  current lock value 0")
    assert "HAL memory status\n" in text
    out.clear()
    assert ex.run_line("status")
    assert "".join(out) == text
    assert not ex.run_line("status nosuch")


def test_newinst_delinst(hal):
    """newinst/delinst (not in the reference 2.9 halcmd)."""
    out: list[str] = []
    err: list[str] = []
    ex = _executor(hal, out, err)
    assert ex.run_line("loadrt tcounter names=c1"), err
    assert ex.run_line("newinst tcounter extra step=7"), err
    assert _core.find("pin", "extra.count") is not None
    assert ex.run_line("delinst extra"), err
    assert _core.find("pin", "extra.count") is None
    assert not ex.run_line("delinst extra")
    assert err[-1].startswith("delinst failed")
    assert ex.run_line("loadrt and2")
    assert not ex.run_line("newinst and2 x")
    assert err[-1].startswith("newinst failed")


def test_save_to_file_then_source(hal, tmp_path: Path):
    """``save ITEM FILE`` writes what ``save ITEM`` prints; sourcing the
    file rebuilds the nets."""
    out: list[str] = []
    err: list[str] = []
    ex = _executor(hal, out, err)
    for line in ("loadrt and2 count=2", "net a and2.0.out => and2.1.in0",
                 "setp and2.1.in1 1", f"save netla {tmp_path}/n.hal",
                 "save netla", "delsig a"):
        assert ex.run_line(line), err
    assert (tmp_path / "n.hal").read_text() == "".join(out)
    assert _core.find("signal", "a") is None
    assert ex.run_line(f"source {tmp_path}/n.hal"), err
    assert hal.pin("and2.1.in0").signal.name == "a"


def test_unload_all_and_unloadusr_all(tmp_path: Path):
    """``unloadusr all`` ends the user components (not halcmd itself);
    ``unload all`` removes the realtime modules as well."""
    (tmp_path / "ucomp.py").write_text(
        "import time\nimport halsdk\n"
        "c = halsdk.component('ucomp')\nc.newpin('x', 'bit', 'out')\n"
        "c.ready()\ntime.sleep(60)\n")
    (tmp_path / "u.hal").write_text(
        "loadrt and2\nloadrt or2\n"
        f"loadusr -Wn ucomp {sys.executable} ucomp.py\n"
        "list comp ucomp\nunloadusr all\n"
        "list comp ucomp\nlist comp *r2 *d2\nunload all\nlist pin\n")
    env = _env("unall", tmp_path / "bin")
    proc = _halrun(["-f", "u.hal"], tmp_path, env)
    assert proc.stdout.splitlines() == ["ucomp ", "", "or2 and2 ", ""]
    assert proc.returncode == 0
    assert _shm_left(env) == []
