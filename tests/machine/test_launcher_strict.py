"""``halsdk run`` on an INI file with typing mistakes: warnings on stderr
naming file:line, section and key; ``--strict`` refuses to start and
leaves nothing behind."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

from helpers.running_machine import (
    MILL,
    client_env,
    halsdk_command,
    mill_ini,
    running_machine,
)

from halsdk.testing import private_instance_name


def in_section(text: str, section: str, old: str, new: str) -> str:
    """``old`` replaced by ``new`` once, within ``[section]``."""
    start = text.index(f"[{section}]\n")
    end = text.find("\n[", start + 1)
    end = len(text) if end < 0 else end
    body = text[start:end]
    assert old in body
    return text[:start] + body.replace(old, new, 1) + text[end:]


def strict_run(folder: Path, ini: Path, *extra: str
               ) -> tuple[subprocess.CompletedProcess, str]:
    instance = private_instance_name()
    proc = subprocess.run(
        halsdk_command() + ["run", "--strict", str(ini), *extra],
        env=client_env(instance), cwd=str(folder), text=True,
        capture_output=True, timeout=90)
    return proc, instance


def left_behind(instance: str) -> list[str]:
    return [n for n in os.listdir("/dev/shm") if instance in n]


def test_help_shows_strict(tmp_path):
    proc = subprocess.run(halsdk_command() + ["run", "--help"],
                          cwd=str(tmp_path), capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0
    assert "--strict" in proc.stdout


def test_a_typo_is_a_warning_and_the_machine_runs(tmp_path):
    ini = mill_ini(tmp_path)
    text = ini.read_text()
    ini.write_text(in_section(text, "JOINT_0", "MAX_VELOCITY =",
                              "MAX_VELOCTY ="))
    line = ini.read_text().splitlines().index("MAX_VELOCTY = 40") + 1
    with running_machine(tmp_path, ini=ini) as machine:
        pass
    out = machine.stop()
    assert (f"warning: {ini}:{line}: [JOINT_0]MAX_VELOCTY: unknown key: "
            "not a key of [JOINT_n] (did you mean MAX_VELOCITY?)") in out


def test_strict_refuses_a_typo_and_starts_nothing(tmp_path):
    ini = mill_ini(tmp_path)
    ini.write_text(in_section(ini.read_text(), "JOINT_0", "MAX_VELOCITY =",
                              "MAX_VELOCTY ="))
    proc, instance = strict_run(tmp_path, ini)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "--strict: the machine is not started" in proc.stderr
    assert "[JOINT_0]MAX_VELOCTY" in proc.stderr
    assert "did you mean MAX_VELOCITY?" in proc.stderr
    assert "machine running" not in proc.stdout
    assert left_behind(instance) == []


def test_strict_refuses_a_repeated_section(tmp_path):
    ini = mill_ini(tmp_path)
    # [JOINT_1] copied from [JOINT_0] and not renamed
    ini.write_text(ini.read_text().replace("[JOINT_1]", "[JOINT_0]"))
    proc, instance = strict_run(tmp_path, ini)
    assert proc.returncode == 1
    assert re.search(r"mill\.ini:\d+: \[JOINT_0\]: section given again "
                     r"\(first at line \d+\)", proc.stderr), proc.stderr
    assert "[KINS]JOINTS = 3 but [JOINT_1] is missing" in proc.stderr
    assert left_behind(instance) == []


def test_strict_refuses_joints_fewer_than_the_hal_files_wire(tmp_path):
    """JOINTS = 2 but the HAL file makes and wires three joints: found
    once the HAL files are loaded; the machine is shut down again."""
    for name in ("mill.hal", "toolchange.hal", "tool.tbl"):
        shutil.copy(MILL / name, tmp_path / name)
    hal = (tmp_path / "mill.hal").read_text()
    hal = hal.replace("num_joints=[KINS]JOINTS", "num_joints=3")
    (tmp_path / "mill.hal").write_text(hal.replace("[JOINT_2]", "[ZSERVO]"))
    text = (MILL / "mill.ini").read_text()
    text = text.replace("JOINTS = 3", "JOINTS = 2").replace(
        "coordinates=xyz", "coordinates=xy").replace("[JOINT_2]", "[ZSERVO]")
    ini = tmp_path / "mill.ini"
    ini.write_text(text)
    proc, instance = strict_run(tmp_path, ini)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "[KINS]JOINTS = 2 but the motion module has 3 joints" in \
        proc.stderr
    assert "[KINS]JOINTS = 2 but the HAL files wire joint 2: joint.2." in \
        proc.stderr
    assert "machine running" not in proc.stdout
    assert left_behind(instance) == []


def test_the_example_mill_starts_under_strict(tmp_path):
    for name in ("mill.ini", "mill.hal", "toolchange.hal", "tool.tbl"):
        shutil.copy(MILL / name, tmp_path / name)
    proc, _ = strict_run(tmp_path, tmp_path / "mill.ini", "--stepped",
                         "--seconds", "0.2")
    assert proc.returncode == 0, proc.stderr
    assert "warning" not in proc.stderr
    assert "stopped" in proc.stdout
