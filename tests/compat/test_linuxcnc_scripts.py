"""Scripts written against the reference's documented ``linuxcnc`` module
run unchanged against ``halsdk run``.

Each script of ``linuxcnc_scripts/`` follows a usage pattern of the
reference manual's Python Interface chapter (``import linuxcnc``, no
halsdk import).  It runs as ``python script.py`` in a folder of its own,
a client process of one machine that this module starts (the example mill
with quick homing, realtime threads), and must exit with 0 and print the
lines its ``# expect:`` comments list, in that order.  Every script ends
in E-stop; after each one the machine is put back in E-stop, MANUAL mode,
anyway, so that a failed script does not fail the next.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers.running_machine import RunningMachine, running_machine

import halsdk

SCRIPTS = Path(__file__).resolve().parent / "linuxcnc_scripts"
#: seconds a script may take at most (each of its waits is bounded too)
SCRIPT_TIMEOUT = 180
EXPECT = "# expect: "

RESET = """\
import linuxcnc
c = linuxcnc.command()
c.abort()
c.wait_complete(10)
c.state(linuxcnc.STATE_ESTOP)
c.wait_complete(10)
c.mode(linuxcnc.MODE_MANUAL)
c.wait_complete(10)
"""


def scripts() -> list[Path]:
    return sorted(SCRIPTS.glob("*.py"))


def expected_lines(script: Path) -> list[str]:
    return [line[len(EXPECT):].rstrip("\n")
            for line in script.read_text().splitlines(keepends=True)
            if line.startswith(EXPECT)]


def script_env(machine: RunningMachine) -> dict[str, str]:
    """The machine's client environment, with this halsdk on the path
    (the installed one, or the source tree the tests import)."""
    env = dict(machine.env)
    env["PYTHONPATH"] = os.pathsep.join(
        [env["PYTHONPATH"], str(Path(halsdk.__file__).parents[1])])
    return env


def run(machine: RunningMachine, args: list[str], cwd: Path
        ) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *args], cwd=str(cwd),
                          env=script_env(machine), capture_output=True,
                          text=True, timeout=SCRIPT_TIMEOUT)


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory
            ) -> Iterator[RunningMachine]:
    folder = tmp_path_factory.mktemp("linuxcnc-machine")
    with running_machine(folder) as m:
        yield m


@pytest.fixture
def fresh(machine: RunningMachine, tmp_path: Path) -> Iterator[RunningMachine]:
    """The shared machine; afterwards put back in E-stop and MANUAL."""
    yield machine
    if machine.proc.poll() is None:
        proc = run(machine, ["-c", RESET], tmp_path)
        assert proc.returncode == 0, proc.stdout + proc.stderr


def test_there_are_enough_scripts() -> None:
    found = scripts()
    assert len(found) >= 10
    for script in found:
        assert expected_lines(script), f"{script.name} expects nothing"
        text = script.read_text()
        assert "import linuxcnc" in text
        assert not re.search(r"^\s*(import|from)\s+halsdk", text, re.M), \
            f"{script.name} imports halsdk"


@pytest.mark.parametrize("script", scripts(), ids=lambda p: p.stem)
def test_reference_style_script(fresh: RunningMachine, script: Path,
                                tmp_path: Path) -> None:
    proc = run(fresh, [str(script)], tmp_path)
    host = "".join(fresh.output[-40:])
    report = (f"exit code {proc.returncode}\n--- stdout\n{proc.stdout}"
              f"--- stderr\n{proc.stderr}--- machine\n{host}")
    assert proc.returncode == 0, report
    lines = proc.stdout.splitlines()
    at = 0
    for want in expected_lines(script):
        while at < len(lines) and lines[at] != want:
            at += 1
        assert at < len(lines), f"missing (in order): {want!r}\n{report}"
        at += 1
    assert fresh.proc.poll() is None, "the machine stopped\n" + report
