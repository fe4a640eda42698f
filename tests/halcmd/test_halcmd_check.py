"""The netlist checker (``halcmd --check FILE``, ``halrun --check FILE``)
and the long-name warning of the executor.

Inputs are in ``tests/data/halfiles_check/``; every run copies them to a temp
folder and runs there in a subprocess with its own ``HALSDK_INSTANCE``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zlib
from pathlib import Path

import pytest
from helpers import data_path

CHECK_FILES = data_path("halfiles_check")


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for path in CHECK_FILES.iterdir():
        if path.is_file():
            shutil.copy(path, tmp_path / path.name)
    return tmp_path


def _instance(folder: Path) -> str:
    """A short instance name of its own for each test folder."""
    return f"chk{os.getpid()}-{zlib.crc32(str(folder).encode())}"

def _run(folder: Path, prog: str, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = _instance(folder)
    env["HALSDK_PATH"] = str(folder)          # finds iopin.py
    return subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", prog, *args],
        cwd=folder, capture_output=True, text=True, timeout=60, env=env)


def _check(folder: Path, name: str, prog: str = "halcmd"
           ) -> tuple[int, list[str], str]:
    result = _run(folder, prog, "--check", name)
    return result.returncode, result.stdout.splitlines(), result.stderr


def test_clean_file_has_no_finding(folder: Path) -> None:
    rc, lines, err = _check(folder, "clean.hal")
    assert rc == 0
    assert lines == []
    assert err == "clean.hal: 0 error(s), 0 warning(s)\n"


def test_halrun_check_is_the_same(folder: Path) -> None:
    assert _check(folder, "problems.hal", "halrun")[:2] == \
        _check(folder, "problems.hal", "halcmd")[:2]


def test_problems_are_found_with_their_lines(folder: Path) -> None:
    rc, lines, err = _check(folder, "problems.hal")
    assert rc == 1
    expected = [
        "problems.hal:3: warning: input pin 'and2.0.in0' is not connected "
        "and never set with setp",
        "problems.hal:3: warning: input pin 'and2.1.in1' is not connected "
        "and never set with setp",
        "problems.hal:4: warning: function 'Big_Gate' is never added to a "
        "thread",
        "problems.hal:6: error: signal 'fanout' has more than one writer: "
        "'and2.0.out', 'and2.1.out'",
        "problems.hal:8: warning: signal 'flt' has no pins",
        "problems.hal:9: error: type mismatch: pin 'and2.0.in1' is bit, "
        "signal 'flt' is float",
        "problems.hal:10: error: Pin 'or2-never-exists' does not exist",
        "problems.hal:11: warning: signal 'orphan-reader' has reader(s) "
        "('Big_Gate.in0') but no writer and is never set with sets",
        "problems.hal:13: warning: signal name(s) longer than the "
        "reference's 47 characters: 'this-is-a-very-long-signal-name-that-"
        "the-reference-cannot-hold'",
        "problems.hal:15: warning: in thread 'servo', 'and2.1' reads signal "
        "'fanout' before 'and2.0' writes it (one period late)",
    ]
    for line in expected:
        assert line in lines
    naming = [x for x in lines if "naming conventions" in x]
    assert naming and all(x.startswith("problems.hal:4: warning:")
                          for x in naming)
    assert any("'Big_Gate.in0'" in x for x in naming)
    # the multiple-writer line is reported once, not also as a net failure
    assert sum(x.startswith("problems.hal:6:") for x in lines) == 1
    # findings come in line order
    numbers = [int(x.split(":")[1]) for x in lines]
    assert numbers == sorted(numbers)
    assert err.endswith("4 error(s), 12 warning(s)\n")


def test_out_and_io_pin_on_one_signal(folder: Path) -> None:
    rc, lines, _ = _check(folder, "direction.hal")
    assert rc == 1
    assert ("direction.hal:5: error: signal 'bus' has an out pin "
            "('and2.0.out') and io pin(s) ('iopin.data')") in lines


def test_reader_before_writer_only_when_reversed(folder: Path) -> None:
    rc, lines, _ = _check(folder, "order.hal")
    assert rc == 0                                  # a warning only
    assert lines == ["order.hal:15: warning: in thread 'fast', 'd' reads "
                     "signal 'cd' before 'c' writes it (one period late)"]


def test_sourced_file_findings_use_its_name(folder: Path) -> None:
    rc, lines, _ = _check(folder, "sourcing.hal")
    assert rc == 1
    assert lines[-2:] == [
        "sourced.inc:2: warning: signal name(s) breaking the naming "
        "conventions (lowercase letters, digits, '.', '-' and '_' only): "
        "'Bad_Name'",
        "sourced.inc:3: error: value 'maybe' invalid for bit; setp failed"]
    assert "sourcing.hal:1: warning: input pin 'g.in0' is not connected " \
        "and never set with setp" in lines


def test_loadusr_pins_are_unknown_not_errors(folder: Path) -> None:
    rc, lines, _ = _check(folder, "usr.hal")
    assert lines[0] == ("usr.hal:1: warning: loadusr 'someprogram' is not "
                        "run by the checker; the pins it makes are unknown")
    assert lines[1].startswith("usr.hal:2: warning: Pin 'someprogram.out' "
                               "does not exist (perhaps a pin of the "
                               "program started by loadusr at line 1)")


def _check_instances() -> set[str]:
    """The checker's private instances (other pytest sessions on the
    machine make instances of their own, which must not count here)."""
    return {p for p in os.listdir("/dev/shm")
            if p.startswith("halsdk") and "-check-" in p}


def test_nothing_runs_and_nothing_is_left(folder: Path) -> None:
    before = _check_instances()
    rc, lines, _ = _check(folder, "nothing_runs.hal")
    assert rc == 0
    assert not (folder / "made-by-loadusr").exists()
    assert not (folder / "saved.hal").exists()
    assert _check_instances() == before


def test_check_leaves_a_running_instance_alone(folder: Path) -> None:
    """The checker uses a private instance: a halrun of the same
    HALSDK_INSTANCE running meanwhile sees none of the checked file."""
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = _instance(folder)
    host = subprocess.Popen(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-I"],
        cwd=folder, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert host.stdin is not None
        host.stdin.write("loadrt or2 names=host-gate\n")
        host.stdin.flush()
        rc, lines, _ = _check(folder, "clean.hal")
        assert rc == 0 and lines == []
        out, err = host.communicate("list comp\nlist funct\n", timeout=30)
    finally:
        if host.poll() is None:
            host.kill()
            host.wait()
    assert host.returncode == 0, err
    words = out.split()
    assert "host-gate" in words and "or2" in words
    assert not {"and2", "not", "threads", "gate", "inv"} & set(words)


def test_missing_file(folder: Path) -> None:
    rc, lines, err = _check(folder, "nope.hal")
    assert rc == 1
    assert "nope.hal:0: error: cannot open the file" in err


def test_check_without_file(folder: Path) -> None:
    result = _run(folder, "halcmd", "--check")
    assert result.returncode == 2
    assert "--check needs a HAL file" in result.stderr


# ---------------------------------------------------------------- warning

LONG = ("loadrt and2 names=gate\n"
        "net this-is-a-very-long-signal-name-that-the-reference-cannot-hold"
        " gate.out\n"
        "getp gate.in0\n")


def test_long_name_warning_on_stderr(folder: Path) -> None:
    (folder / "long.hal").write_text(LONG)
    result = _run(folder, "halrun", "-f", "long.hal")
    assert result.returncode == 0
    assert result.stdout == "FALSE\n"
    assert result.stderr == (
        "long.hal:2: Warning: signal name 'this-is-a-very-long-signal-name-"
        "that-the-reference-cannot-hold' is 62 characters long; the "
        "reference HAL accepts at most 47\n")


def test_long_name_warning_silenced_by_big_q(folder: Path) -> None:
    (folder / "long.hal").write_text(LONG)
    result = _run(folder, "halrun", "-Q", "-f", "long.hal")
    assert result.returncode == 0
    assert result.stderr == ""


def test_short_names_give_no_warning(folder: Path) -> None:
    name = "s" * 47
    (folder / "ok.hal").write_text(f"loadrt and2 names=gate\n"
                                   f"net {name} gate.out\n")
    result = _run(folder, "halrun", "-f", "ok.hal")
    assert result.returncode == 0
    assert result.stderr == ""
