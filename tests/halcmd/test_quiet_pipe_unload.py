"""Issue 19: the installed programs end quietly when their reader goes
away (``halcmd show pin | head -1``), and ``unload all`` never ends the
halcmd that runs it."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

BIN = Path(sys.executable).parent


def _program(name: str) -> str:
    path = BIN / name
    if not path.exists():
        pytest.skip(f"{name} is not installed next to {sys.executable}")
    return str(path)


def _first_line_then_close(args: list[str], cwd: Path,
                           env=None) -> tuple[str, int, str]:
    """What ``ARGS | head -1`` does: read one line, close the pipe, and
    return (line, exit status, stderr)."""
    proc = subprocess.Popen(args, cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    assert proc.stdout is not None and proc.stderr is not None
    try:
        line = proc.stdout.readline().decode()
        proc.stdout.close()
        err = proc.stderr.read().decode()
        return line, proc.wait(timeout=60), err
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def _big_file(tmp_path: Path) -> None:
    # far more than a pipe buffer (64 KiB) of "show pin", then one more
    # command: the rest of the file must still run
    (tmp_path / "big.hal").write_text(
        "show pin\n" * 400 + "newsig after-the-pipe bit\n")


def test_halcmd_show_pin_head(hal, tmp_path):
    hal.loadrt("siggen", num_chan=8)
    _big_file(tmp_path)
    line, code, err = _first_line_then_close(
        [_program("halcmd"), "-f", "big.hal"], tmp_path)
    assert line == "Component Pins:\n"
    assert (code, err) == (0, "")          # no traceback, as the reference
    assert hal.find("signal", "after-the-pipe") is not None


def test_halrun_show_pin_head(tmp_path):
    instance = f"i19-halrun-{os.getpid()}"
    env = dict(os.environ, HALSDK_INSTANCE=instance)
    (tmp_path / "big.hal").write_text(
        "loadrt siggen num_chan=8\n" + "show pin\n" * 400)
    line, code, err = _first_line_then_close(
        [_program("halrun"), "-f", "big.hal"], tmp_path, env)
    assert line == "Component Pins:\n"
    assert (code, err) == (0, "")
    # halrun still removed its instance
    assert not any(instance in n for n in os.listdir("/dev/shm"))


def test_halmeter_text_mode_head(hal, tmp_path):
    hal.newsig("watched", "float")
    line, code, err = _first_line_then_close(
        [_program("halmeter"), "-s", "sig", "watched", "-p", "1"],
        tmp_path)
    assert line.strip() != ""
    assert (code, err) == (0, "")


def test_unload_all_spares_the_calling_halcmd(hal, tmp_path):
    hal.loadrt("and2")
    (tmp_path / "u.hal").write_text(
        "unload all\nnewsig after-unload bit\nshow comp\n")
    proc = subprocess.run([_program("halcmd"), "-f", "u.hal"],
                          cwd=tmp_path, capture_output=True, text=True,
                          timeout=60)
    # before: SIGTERM to itself, exit status 143, the rest skipped
    assert (proc.returncode, proc.stderr) == (0, "")
    assert hal.find("signal", "after-unload") is not None
    assert hal.find("component", "and2") is None
    # its own component was made again (a new ID), as in the reference
    assert " halcmd" in proc.stdout.split("Loaded HAL Components:")[1]


def test_unload_all_spares_other_halcmd_sessions(hal, tmp_path):
    (tmp_path / "w.hal").write_text("loadusr -w sleep 3\n")
    (tmp_path / "u.hal").write_text("unload all\nunloadusr all\n")
    waiting = subprocess.Popen([_program("halcmd"), "-f", "w.hal"],
                               cwd=tmp_path)
    try:
        name = f"halcmd{waiting.pid}"
        for _ in range(500):
            if hal.find("component", name) is not None:
                break
            subprocess.run(["sleep", "0.01"])
        proc = subprocess.run([_program("halcmd"), "-f", "u.hal"],
                              cwd=tmp_path, capture_output=True, text=True,
                              timeout=60)
        assert (proc.returncode, proc.stderr) == (0, "")
        assert waiting.poll() is None       # not signalled
        assert hal.find("component", name) is not None
        assert waiting.wait(timeout=30) == 0
    finally:
        if waiting.poll() is None:
            waiting.kill()
            waiting.wait()


def test_a_nul_in_a_hal_line_ends_the_line(tmp_path):
    """A NUL ends a line as it ends the reference's C string: no
    ValueError traceback from a file name that holds one."""
    instance = f"i19-nul-{os.getpid()}"
    env = dict(os.environ, HALSDK_INSTANCE=instance)
    (tmp_path / "nul.hal").write_bytes(
        b"loadrt and2\nshow pin and2.0.in\x000\nsource a\x00b.hal\n")
    r = subprocess.run([_program("halrun"), "-f", "nul.hal"], cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=60)
    assert "and2.0.in0" in r.stdout and "and2.0.in1" in r.stdout
    assert r.returncode == 1
    assert "Could not open hal file 'a'" in r.stderr
    assert "Traceback" not in r.stderr


def test_halsdk_run_with_a_nul_in_halfile(tmp_path):
    (tmp_path / "m.ini").write_bytes(
        b"[EMC]\nMACHINE = m\n[HAL]\nHALFILE = mi\x00ll.hal\n")
    env = dict(os.environ, HALSDK_INSTANCE=f"i19-nulrun-{os.getpid()}")
    r = subprocess.run([_program("halsdk"), "run", "m.ini"], cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode != 0
    assert "m.ini:4: cannot read HAL file 'mi'" in r.stderr
    assert "Traceback" not in r.stderr
