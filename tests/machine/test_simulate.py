"""``halsdk run machine.ini --simulate --program part.ngc``: a program run
in stepped, simulated time as fast as possible, its figures printed and
written as JSON, the exit status non-zero on any error (what a machine
builder puts in CI)."""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from helpers.running_machine import MILL, client_env, halsdk_command, mill_ini
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from halsdk.testing import private_instance_name

KEYS = {"ini", "program", "ok", "program_time", "homing_time",
        "servo_period", "task_cycle", "servo_cycles", "skipped_task_cycles",
        "max_following_error",
        "ferror_limit", "limit_hits", "errors", "wall_time", "run_wall_time",
        "speed"}


def mill_copy(tmp_path: Path) -> Path:
    """A copy of the example folder (its tool table must stay as it is)."""
    folder = tmp_path / "mill"
    shutil.copytree(MILL, folder)
    return folder


def simulate(folder: Path, program: str, *extra: str, ini: str = "mill.ini"
             ) -> subprocess.CompletedProcess:
    """The installed console script, in ``folder``, on a private
    instance; it must end by itself (a generous bound, not a timing)."""
    return subprocess.run(
        halsdk_command() + ["run", ini, "--simulate", "--program", program,
                            *extra],
        env=client_env(private_instance_name()), cwd=str(folder), text=True,
        capture_output=True, timeout=240)


def test_help_lists_the_options(tmp_path):
    proc = subprocess.run(halsdk_command() + ["run", "--help"],
                          cwd=str(tmp_path), capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0
    for option in ("--simulate", "--program", "--json", "--timeout"):
        assert option in proc.stdout


@pytest.mark.parametrize("args", [["--simulate"], ["--program", "x.ngc"],
                                  ["--simulate", "--program", "x.ngc",
                                   "--stepped"]])
def test_options_that_do_not_go_together(tmp_path, args):
    proc = subprocess.run(halsdk_command() + ["run", "mill.ini", *args],
                          cwd=str(tmp_path), capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 2
    assert "--simulate" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_the_demo_program(tmp_path):
    folder = mill_copy(tmp_path)
    table = (folder / "tool.tbl").read_text()
    out = tmp_path / "out.json"
    proc = simulate(folder, "demo.ngc", "--json", str(out))
    assert proc.returncode == 0, proc.stdout + proc.stderr
    r = json.loads(out.read_text())
    assert set(r) == KEYS
    assert r["ok"] is True and r["errors"] == [] and r["limit_hits"] == []
    # the demo measures 21.5 s of program (one task cycle per servo cycle);
    # here the task looks every 10 ms
    assert 20.0 < r["program_time"] < 23.0
    assert r["homing_time"] > 1.0               # the example homes slowly
    assert r["task_cycle"] == pytest.approx(0.010)
    assert len(r["max_following_error"]) == 3
    for e, limit in zip(r["max_following_error"], r["ferror_limit"]):
        assert 0 < e < limit
    # the task slept through the long moves (10 ms per task cycle)
    assert r["skipped_task_cycles"] > 100
    assert "program time:" in proc.stdout
    assert "max following error joint 2" in proc.stdout
    # the machine's files are left alone (two tool changes ran)
    assert (folder / "tool.tbl").read_text() == table


@pytest.mark.slow
def test_two_runs_give_the_same_program_time(tmp_path):
    folder = mill_copy(tmp_path)
    results = []
    for n in range(2):
        out = tmp_path / f"out{n}.json"
        proc = simulate(folder, "demo.ngc", "--json", str(out))
        assert proc.returncode == 0, proc.stdout + proc.stderr
        results.append(json.loads(out.read_text()))
    a, b = results
    for key in ("program_time", "homing_time", "servo_cycles",
                "max_following_error"):
        assert a[key] == b[key], key


def test_a_bad_gcode_word_names_file_and_line(tmp_path):
    folder = mill_copy(tmp_path)
    (folder / "bad.ngc").write_text("G21 G90\nG0 X10 Y10\nG5 X20\nM2\n")
    out = tmp_path / "out.json"
    proc = simulate(folder, "bad.ngc", "--json", str(out))
    assert proc.returncode == 1
    r = json.loads(out.read_text())
    assert r["ok"] is False
    assert any("bad.ngc:3" in e for e in r["errors"]), r["errors"]
    assert "bad.ngc:3" in proc.stdout
    assert "Traceback" not in proc.stdout + proc.stderr


def test_a_move_beyond_a_soft_limit_is_a_limit_hit(tmp_path):
    folder = mill_copy(tmp_path)
    (folder / "far.ngc").write_text(
        "G21 G90\nG0 X10 Y10\nG1 X500 F600\nM2\n")
    out = tmp_path / "out.json"
    proc = simulate(folder, "far.ngc", "--json", str(out))
    assert proc.returncode == 1
    r = json.loads(out.read_text())
    assert r["limit_hits"], r
    assert any("line 3" in e and "X=500" in e for e in r["limit_hits"])
    assert "limit hits:     1" in proc.stdout
    assert r["program_time"] < 5.0      # stopped at the refused move


def test_a_missing_program_is_an_error(tmp_path):
    folder = mill_copy(tmp_path)
    proc = simulate(folder, "nothing.ngc")
    assert proc.returncode == 1
    assert "nothing.ngc" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_a_machine_that_does_not_start(tmp_path):
    (tmp_path / "broken.ini").write_text("[EMC]\nMACHINE = x\n")
    (tmp_path / "p.ngc").write_text("M2\n")
    proc = simulate(tmp_path, "p.ngc", ini="broken.ini")
    assert proc.returncode == 1
    assert "HALFILE" in proc.stderr
    assert "Traceback" not in proc.stderr


# ---------------------------------------------------------- in process

moves = st.lists(
    st.tuples(st.sampled_from(["G0", "G1"]),
              st.floats(0, 230), st.floats(0, 100), st.floats(-20, 0)),
    min_size=1, max_size=6)


@pytest.mark.slow
@settings(max_examples=6, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(moves=moves, change=st.booleans())
def test_skipping_task_cycles_changes_no_servo_cycle(tmp_path, monkeypatch,
                                                     moves, change):
    """The skip of SimMachine: the same program time, servo cycles,
    following errors and errors as a task that looks every task cycle,
    also when motmod refuses a move beyond the soft limit (X > 201)."""
    from halsdk.machine.simulate import simulate as run
    monkeypatch.setenv("HALSDK_INSTANCE", private_instance_name())
    folder = tmp_path / f"m{os.urandom(4).hex()}"
    folder.mkdir()
    ini = mill_ini(folder)
    lines = ["G21 G90 G94 F900"]
    for i, (g, x, y, z) in enumerate(moves):
        lines.append(f"{g} X{x:.3f} Y{y:.3f} Z{z:.3f}")
        if change and i == 0:
            lines.append("T1 M6")       # waits for motion at rest
    lines.append("M2")
    program = folder / "p.ngc"
    program.write_text("\n".join(lines) + "\n")
    results = [run(str(ini), str(program), skipping=s, out=io.StringIO(),
                   err=io.StringIO()) for s in (False, True)]
    every, skipped = results
    beyond = any(x > 201 for _, x, _, _ in moves)
    assert every.ok is not beyond, every.errors
    assert skipped.errors == every.errors
    assert skipped.limit_hits == every.limit_hits
    assert skipped.program_time == every.program_time
    assert skipped.servo_cycles == every.servo_cycles
    assert skipped.max_following_error == every.max_following_error
