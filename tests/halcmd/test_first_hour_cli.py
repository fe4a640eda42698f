"""What a newcomer meets first on the command line (issue 22): every
console script answers ``--help``, halrun's prompt forgives a typo as the
reference does, messages say things once, and this halsdk's halrun and
halcmd are reachable whatever comes first on ``PATH``."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import repo_path
from helpers.halrun import halcmd_env, run_cli, shm_left


def console_scripts() -> dict[str, str]:
    """``[project.scripts]`` of pyproject.toml: name -> module:function
    (read as text: tomllib is Python 3.11+, halsdk supports 3.9)."""
    text = repo_path("pyproject.toml").read_text(encoding="utf-8")
    section = text.split("[project.scripts]\n", 1)[1].split("\n[", 1)[0]
    scripts = dict(re.findall(r'^([\w-]+) = "([\w.]+:\w+)"$', section,
                              re.MULTILINE))
    assert len(scripts) >= 14, section
    return scripts


def run_script(target: str, name: str, args: list[str], cwd: Path,
               env: dict) -> subprocess.CompletedProcess:
    """Run an entry point as its console script does: ``sys.argv`` set,
    the function called without arguments, its value the exit status."""
    module, function = target.split(":")
    code = ("import sys\n"
            f"sys.argv = [{name!r}, *{args!r}]\n"
            f"from {module} import {function} as main\n"
            "sys.exit(main())\n")
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("name", sorted(console_scripts()))
@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_every_console_script_answers_help(name: str, flag: str,
                                           tmp_path: Path) -> None:
    env = halcmd_env(tmp_path, f"help-{name}")
    proc = run_script(console_scripts()[name], name, [flag], tmp_path, env)
    text = proc.stdout + proc.stderr
    assert proc.returncode == 0, text
    assert "usage" in proc.stdout.lower(), text
    assert "Traceback" not in text, text
    assert "unknown option" not in text.lower(), text
    # plain words, not the reStructuredText of a docstring
    for markup in ("``", ":func:", ":mod:", ":class:"):
        assert markup not in proc.stdout, text
    assert shm_left(env) == [], "a --help made a HAL instance"


# ------------------------------------------------ halrun's prompt

def test_a_typo_at_halruns_prompt_does_not_fail_the_session(
        tmp_path: Path) -> None:
    """The reference's halrun exits 0 after ``bogus`` at its prompt (it
    ignores the interactive halcmd's status)."""
    env = halcmd_env(tmp_path, "prompt")
    proc = run_cli(["halrun"], tmp_path, env, stdin="bogus\nshow comp\n")
    assert "Unknown command 'bogus'" in proc.stdout, proc.stdout
    assert "halcmd" in proc.stdout          # the command after it ran
    assert proc.returncode == 0, proc.stdout
    # the same after a good file, with -I
    (tmp_path / "good.hal").write_text("loadrt and2\n")
    proc = run_cli(["halrun", "-I", "-f", "good.hal"], tmp_path, env,
                   stdin="bogus\nexit\n")
    assert "Unknown command 'bogus'" in proc.stdout, proc.stdout
    assert proc.returncode == 0, proc.stdout
    assert shm_left(env) == []


def test_a_failing_file_still_fails_with_the_prompt(tmp_path: Path) -> None:
    """The status is the file's: the reference's ``halrun -I -f bad.hal``
    exits 1 whatever is typed at the prompt."""
    env = halcmd_env(tmp_path, "badfile")
    (tmp_path / "bad.hal").write_text("bogus\n")
    for stdin in ("show comp\n", "show comp\nexit\n"):
        proc = run_cli(["halrun", "-I", "-f", "bad.hal"], tmp_path, env,
                       stdin=stdin)
        assert proc.returncode == 1, proc.stdout
    (tmp_path / "quits.hal").write_text("bogus\nexit\n")
    proc = run_cli(["halrun", "-I", "-f", "quits.hal"], tmp_path, env)
    assert proc.returncode == 1, proc.stdout
    assert shm_left(env) == []


# ------------------------------------------------ messages said once

def test_halcmd_without_an_instance_says_it_once(tmp_path: Path) -> None:
    env = halcmd_env(tmp_path, "noinst")
    proc = run_cli(["halcmd", "show", "comp"], tmp_path, env)
    assert proc.returncode == 1
    name = env["HALSDK_INSTANCE"]
    assert proc.stdout.count("no HAL instance") == 1, proc.stdout
    assert proc.stdout.count("start one with") == 1, proc.stdout
    assert f"'{name}'" in proc.stdout, proc.stdout


# ------------------------------------------------ ours, whatever is on PATH

@pytest.fixture
def impostors(tmp_path: Path) -> Path:
    """A folder with a ``halrun`` and a ``halcmd`` that are not ours
    (LinuxCNC's, say), to put first on PATH."""
    folder = tmp_path / "other-bin"
    folder.mkdir()
    for name in ("halrun", "halcmd"):
        script = folder / name
        script.write_text("#!/bin/sh\necho NOT-HALSDK\nexit 42\n")
        script.chmod(0o755)
    return folder


@pytest.mark.parametrize("command", [
    [sys.executable, "-m", "halsdk.halcmd"],
    [sys.executable, "-m", "halsdk.machine.cli"],
])
def test_ours_whatever_comes_first_on_path(command: list[str],
                                           tmp_path: Path,
                                           impostors: Path) -> None:
    env = halcmd_env(tmp_path, "path")
    env["PATH"] = f"{impostors}{os.pathsep}{env['PATH']}"
    (tmp_path / "t.hal").write_text("loadrt and2\nshow comp and2\n")
    proc = subprocess.run([*command, "halrun", "-f", "t.hal"], cwd=tmp_path,
                          env=env, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "and2" in proc.stdout and "NOT-HALSDK" not in proc.stdout
    proc = subprocess.run([*command, "halcmd", "--help"], cwd=tmp_path,
                          env=env, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0 and "halcmd" in proc.stdout, proc.stderr
    proc = subprocess.run([*command, "--help"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and "PATH" in proc.stdout, proc.stderr
    assert shm_left(env) == []


@pytest.mark.parametrize("message, hint", [
    ("HAL instance 'x' was left by a host (pid 7) that is gone, and it "
     "could not be removed; remove it with 'halrun -U'", False),
    ("HAL instance 'x' already has a host (pid 7)", True),
])
def test_halrun_gives_one_consistent_advice(message: str, hint: bool,
                                            monkeypatch: pytest.MonkeyPatch,
                                            capsys: pytest.CaptureFixture[str]
                                            ) -> None:
    """After a crashed host, halrun says what the core says (remove it
    with halrun -U) and does not add "is another halrun running?"; that
    question is for a live host only."""
    import halsdk
    from halsdk.errors import InstanceError
    from halsdk.halcmd import cli

    def refuse(create: bool = True) -> None:
        raise InstanceError(message)

    monkeypatch.setattr(halsdk, "Hal", refuse)
    assert cli.halrun_main(["-f", "none.hal"]) == 1
    err = capsys.readouterr().err
    assert err.count(message) == 1, err
    assert ("another halrun running" in err) is hint, err
