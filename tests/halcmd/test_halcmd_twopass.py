"""Twopass loading (``halrun FILE.ini`` with ``[HAL]TWOPASS``).

The end-to-end tests run ``halrun`` in a subprocess from a temp folder;
``GOLDEN`` is the output of the reference ``halrun machine.ini`` for the
same files (its ``Note: Using POSIX non-realtime`` lines removed).
"""

from __future__ import annotations

import os
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

from halsdk.halcmd.twopass import (
    TwopassError,
    _excluded,
    _Module,
    ini_values,
    is_twopass_ini,
)

MACHINE_INI = """\
[HAL]
TWOPASS = on
HALFILE = base.hal
HALFILE = logic.hal
[LOGIC]
LEVEL = 1
"""
BASE_HAL = """\
# the thread and the first gates
loadrt threads name1=servo period1=1000000
loadrt and2 names=gate-a
loadrt or2 count=1
net a-out gate-a.out => gate-b.in0
setp gate-a.in0 [LOGIC]LEVEL
addf gate-a servo
addf or2.0 servo
"""
LOGIC_HAL = """\
# more gates of the same modules: merged with base.hal's loadrt
loadrt and2 names=gate-b,gate-c
loadrt or2 count=2
net b-out gate-b.out => or2.1.in0
addf gate-b servo
addf or2.1 servo
show sig
show thread
getp gate-a.in0
"""
GOLDEN = """\
twopass:invoked with <> options
twopass:found ./base.hal
twopass:found ./logic.hal
Signals:
Type          Value  Name     (linked to)
bit           FALSE  a-out
                         <== gate-a.out
                         ==> gate-b.in0
bit           FALSE  b-out
                         <== gate-b.out
                         ==> or2.1.in0

Realtime Threads:
     Period  FP     Name               (     Time, Max-Time )
    1000000  YES                 servo (        0,        0 )
                  1 gate-a
                  2 or2.0
                  3 gate-b
                  4 or2.1

"""


def _instance(folder: Path) -> str:
    """A short instance name of its own for each test folder."""
    return f"tp{os.getpid()}-{zlib.crc32(str(folder).encode())}"

def _halrun(folder: Path, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = _instance(folder)
    return subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", *args],
        cwd=folder, capture_output=True, text=True, timeout=60, env=env)


def _write(folder: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (folder / name).write_text(text)


# ---------------------------------------------------------------- merging

def test_count_and_num_chan_are_added() -> None:
    m = _Module("and2")
    m.add(["count=2"])
    m.add(["count=3"])
    assert m.words() == ["and2", "count=5"]
    n = _Module("x")
    n.add(["num_chan=1"])
    n.add(["num_chan=0x2"])
    assert n.words() == ["x", "num_chan=3"]


def test_names_personality_debug_and_other_words() -> None:
    m = _Module("pid")
    m.add(["names=x,y", "debug=1", "personality=1,2"])
    m.add(["names=z", "debug=2", "personality=3", "extra=4"])
    assert m.words() == ["pid", "names=x,y,z", "personality=1,2,3",
                         "debug=3", "extra=4"]


def test_forms_cannot_be_mixed() -> None:
    m = _Module("and2")
    m.add(["count=1"])
    with pytest.raises(TwopassError, match="cannot mix count=, num_chan= "
                       r"and names= forms \(module=and2, first used "
                       "form=count$"):
        m.add(["names=zz"])


def test_bad_number_is_an_error() -> None:
    with pytest.raises(TwopassError, match="bad number"):
        _Module("and2").add(["count=many"])


def test_ini_values_and_trigger(tmp_path: Path) -> None:
    ini = tmp_path / "a.ini"
    ini.write_text("[HAL]\nHALFILE = a.hal\nHALFILE = b.hal\n"
                   "[OTHER]\nHALFILE = c.hal\n")
    assert ini_values(str(ini), "HAL", "HALFILE") == ["a.hal", "b.hal"]
    assert not is_twopass_ini(str(ini))
    ini.write_text("[HAL]\nTWOPASS =\n")
    assert not is_twopass_ini(str(ini))      # empty: not enabled
    ini.write_text("[HAL]\nTWOPASS = on,verbose\n")
    assert is_twopass_ini(str(ini))


def test_notwopass_magic_comment() -> None:
    assert _excluded(["loadrt x\n", "  # No TwoPass here\n"])
    assert _excluded(["#NOTWOPASS\n"])
    assert not _excluded(["loadrt x # notwopass\n", "# two pass\n"])


# ---------------------------------------------------------------- halrun

def test_halrun_ini_matches_the_reference(tmp_path: Path) -> None:
    _write(tmp_path, {"machine.ini": MACHINE_INI, "base.hal": BASE_HAL,
                      "logic.hal": LOGIC_HAL})
    result = _halrun(tmp_path, "machine.ini")
    assert result.returncode == 0, result.stderr
    assert result.stdout == GOLDEN
    assert result.stderr == ""


def test_verbose_reports_the_merged_loadrt(tmp_path: Path) -> None:
    _write(tmp_path, {"machine.ini": MACHINE_INI.replace(
        "TWOPASS = on", "TWOPASS = on,verbose,nodelete"),
        "base.hal": BASE_HAL, "logic.hal": LOGIC_HAL})
    result = _halrun(tmp_path, "machine.ini")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == "twopass:invoked with <verbose nodelete> options"
    assert "twopass: loadrt and2 names=gate-a,gate-b,gate-c" in lines
    assert "twopass: loadrt or2 count=3" in lines
    assert lines.index("twopass: pass0:END") < \
        lines.index("twopass: pass1:BEGIN")


def test_failing_command_stops_its_file_only(tmp_path: Path) -> None:
    ini = MACHINE_INI.replace("LEVEL = 1", "LEVEL = 2")   # bad bit value
    _write(tmp_path, {"machine.ini": ini, "base.hal": BASE_HAL,
                      "logic.hal": LOGIC_HAL})
    result = _halrun(tmp_path, "machine.ini")
    assert result.returncode == 1
    assert ("twopass: Error in file ./base.hal:\n"
            "    value '2' invalid for bit\nsetp failed\n") in result.stdout
    # base.hal stopped at the setp: its addf lines did not run ...
    assert "1 gate-b" in result.stdout and "gate-a\n" not in \
        result.stdout.split("Realtime Threads:")[1]
    # ... but logic.hal ran
    assert "b-out" in result.stdout


def test_mixed_forms_fail_in_pass0(tmp_path: Path) -> None:
    _write(tmp_path, {"m.ini": "[HAL]\nTWOPASS = yes\nHALFILE = one.hal\n"
                               "HALFILE = two.hal\n",
                      "one.hal": "loadrt and2 count=1\n",
                      "two.hal": "loadrt and2 names=zz\nshow comp\n"})
    result = _halrun(tmp_path, "m.ini")
    assert result.returncode == 1
    assert result.stdout == (
        "twopass:invoked with <> options\n"
        "twopass:found ./one.hal\ntwopass:found ./two.hal\n"
        "twopass: Error in file ./two.hal:\n"
        "    loadrt_substitute: cannot mix count=, num_chan= and names= "
        "forms (module=and2, first used form=count\n")


def test_notwopass_file_runs_first_with_k_and_v(tmp_path: Path) -> None:
    _write(tmp_path, {"n.ini": "[HAL]\nTWOPASS = yes\nHALFILE = excl.hal\n"
                               "HALFILE = one.hal\n",
                      "excl.hal": "# NoTwoPass\nloadrt or2 count=1\n"
                                  "bogus\nloadrt not count=1\n",
                      "one.hal": "loadrt and2 count=1\n"
                                 "net x and2.0.out or2.0.in0\nshow sig\n"})
    result = _halrun(tmp_path, "n.ini")
    assert result.returncode == 0, result.stdout + result.stderr
    out = result.stdout
    assert "twopass:Sourcing ./excl.hal WITHOUT twopass processing" in out
    assert "./excl.hal:2: Realtime module 'or2' loaded" in out     # -v
    assert "./excl.hal:4: Realtime module 'not' loaded" in out     # -k
    assert "./excl.hal:3: Unknown command 'bogus'" in result.stderr
    assert "==> or2.0.in0" in out


def test_ini_without_twopass_is_refused(tmp_path: Path) -> None:
    _write(tmp_path, {"no.ini": "[HAL]\nHALFILE = one.hal\n",
                      "one.hal": "loadrt and2 count=1\n"})
    result = _halrun(tmp_path, "no.ini")
    assert result.returncode == 1
    assert result.stdout == ("halrun: An INI file may only be used if it "
                             "specifies [HAL]TWOPASS\n")


def test_missing_halfile(tmp_path: Path) -> None:
    _write(tmp_path, {"m.ini": "[HAL]\nTWOPASS = on\nHALFILE = gone.hal\n"})
    result = _halrun(tmp_path, "m.ini")
    assert result.returncode == 1
    assert "twopass:CANNOT FIND FILE FOR:gone.hal" in result.stdout


def test_halfile_relative_to_the_ini_folder(tmp_path: Path) -> None:
    conf = tmp_path / "conf"
    conf.mkdir()
    _write(conf, {"m.ini": "[HAL]\nTWOPASS = on\nHALFILE = a.hal\n"
                           "HALFILE = a.hal\n",
                  "a.hal": "loadrt and2 count=1\nshow funct and2\n"})
    result = _halrun(tmp_path, "conf/m.ini")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "twopass:found conf/a.hal" in result.stdout
    # the same file twice: count=1 twice gives two instances
    assert result.stdout.count("and2.1\n") == 2


def test_interactive_after_twopass(tmp_path: Path) -> None:
    _write(tmp_path, {"machine.ini": MACHINE_INI, "base.hal": BASE_HAL,
                      "logic.hal": LOGIC_HAL})
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = _instance(tmp_path)
    result = subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-I",
         "machine.ini"], input="list funct\n", cwd=tmp_path,
        capture_output=True, text=True, timeout=60, env=env)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(GOLDEN)
    assert result.stdout[len(GOLDEN):].split() == [
        "gate-a", "gate-b", "gate-c", "or2.0", "or2.1", "or2.2"]
