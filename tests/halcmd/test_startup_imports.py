"""Issue 21 (2): what ``halcmd`` and ``halrun`` import when they start.

Shell scripts run ``halcmd getp``/``setp`` in loops, so every module the
programs import on the way is paid on every call.  The heavy ones are
imported where they are used (loadrt, loadusr, a request to the host,
``show``/``save``...).  These tests guard that without timing anything: a
fresh interpreter runs the program's entry point, then reports which of
the modules below it imported (bench/startup.py measures the time).
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

from halsdk.loader import Loaded

#: never needed to start halcmd or halrun (numpy: only where arrays are
#: made; the rest: by the commands and requests that use them)
HEAVY = (
    "numpy", "hypothesis", "argparse", "asyncio", "dataclasses", "inspect",
    "importlib.metadata", "tempfile", "shutil", "traceback", "subprocess",
    "json", "halsdk.loader", "halsdk.core.records", "halsdk.machine",
    "halsdk.drivers", "halsdk.gcode", "halsdk.compat.hal",
    "halsdk.halcmd.twopass", "halsdk.halcmd.check",
)
#: what an attached halcmd does not need but a host does
HOST_ONLY = ("halsdk.core.channel", "socket", "signal")

_PROBE = """
import sys
from halsdk.halcmd.cli import halcmd_main, halrun_main
main = halcmd_main if sys.argv[1] == "halcmd" else halrun_main
status = main(sys.argv[2:])
sys.stdout.flush()
sys.stderr.write(repr((status, sorted(sys.modules))) + "\\n")
"""


def _run(args: list[str], cwd: Path) -> tuple[str, int, set[str]]:
    """Run the entry point in a fresh interpreter: (its stdout, its exit
    status, the modules it imported)."""
    proc = subprocess.run([sys.executable, "-c", _PROBE, *args], cwd=cwd,
                          capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL, env=dict(os.environ))
    last = proc.stderr.strip().splitlines()[-1]
    status, modules = ast.literal_eval(last)
    return proc.stdout, status, set(modules)


def _at_start() -> set[str]:
    """What this interpreter imports before running anything (its
    ``site``: a ``.pth`` file of another package may import tempfile or
    shutil already); those are not the programs' doing."""
    proc = subprocess.run(
        [sys.executable, "-c", "import sys; print(sorted(sys.modules))"],
        capture_output=True, text=True, timeout=60, check=True,
        stdin=subprocess.DEVNULL)
    return set(ast.literal_eval(proc.stdout))


_BARE: set[str] = set()


def _loaded(modules: set[str], names: tuple[str, ...]) -> list[str]:
    """Which of ``names`` (or their submodules) the program imported,
    beyond what the bare interpreter had imported already."""
    if not _BARE:
        _BARE.update(_at_start())
    mine = modules - _BARE
    return sorted(n for n in names
                  if n in mine or any(m.startswith(n + ".") for m in mine))


def test_import_of_the_cli_is_light(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-c",
         "import sys, halsdk.halcmd.cli; print(sorted(sys.modules))"],
        cwd=tmp_path, capture_output=True, text=True, timeout=60,
        check=True)
    modules = set(ast.literal_eval(proc.stdout))
    assert "halsdk.halcmd.commands" in modules      # the probe works
    assert _loaded(modules, HEAVY + HOST_ONLY) == []


def test_halcmd_getp_of_a_running_instance(hal, tmp_path):
    hal.loadrt("and2")
    hal.setp("and2.0.in0", True)
    out, status, modules = _run(["halcmd", "getp", "and2.0.in0"], tmp_path)
    assert (out, status) == ("TRUE\n", 0)
    assert "halsdk.hal" in modules
    assert _loaded(modules, HEAVY + HOST_ONLY) == []
    # the halcmd<pid> component it made is gone again
    assert [c.name for c in hal.components("halcmd*")] == []


def test_halcmd_setp_then_show(hal, tmp_path):
    # a command that needs more (show's records) still works, and loads
    # what it needs when it runs
    hal.loadrt("and2")
    out, status, _ = _run(["halcmd", "setp", "and2.0.in1", "1"], tmp_path)
    assert status == 0
    assert hal.pin("and2.0.in1").value is True
    out, status, modules = _run(["halcmd", "show", "pin", "and2.0.in1"],
                                tmp_path)
    assert status == 0 and "and2.0.in1" in out and "TRUE" in out
    assert "halsdk.core.records" in modules


def test_halrun_empty_file(tmp_path, monkeypatch):
    instance = f"startup-imports-{os.getpid()}"
    monkeypatch.setenv("HALSDK_INSTANCE", instance)
    (tmp_path / "empty.hal").write_text("")
    out, status, modules = _run(["halrun", "-f", "empty.hal"], tmp_path)
    assert (out, status) == ("", 0)
    # the host serves requests and keeps a registry of loaded modules
    assert {"halsdk.core.channel", "halsdk.loader"} <= modules
    assert _loaded(modules, HEAVY) == ["halsdk.loader"]
    assert not any(instance in n for n in os.listdir("/dev/shm"))


def test_halrun_loadrt_loadusr(tmp_path, monkeypatch):
    # the lazily imported paths: loadrt (the loader), loadusr
    # (subprocess, shutil), show (records)
    instance = f"startup-imports-l-{os.getpid()}"
    monkeypatch.setenv("HALSDK_INSTANCE", instance)
    (tmp_path / "run.hal").write_text(
        "loadrt and2 count=2\n"
        "loadusr -w true\n"
        "setp and2.1.in0 1\n"
        "getp and2.1.in0\n"
        "show comp and2\n")
    out, status, modules = _run(["halrun", "-f", "run.hal"], tmp_path)
    assert status == 0
    assert out.startswith("TRUE\n") and "and2" in out
    assert {"halsdk.loader", "subprocess", "halsdk.core.records"} <= modules
    assert not any(instance in n for n in os.listdir("/dev/shm"))


@pytest.mark.parametrize("same", [True, False])
def test_loaded_record_compares_like_the_dataclass_it_was(same):
    a = Loaded("and2", sys, [1, 2], "count=2")
    b = Loaded("and2", sys, [1, 2] if same else [1], "count=2")
    assert (a == b) is same
    assert Loaded("and2", sys).comp_ids == [] and Loaded("x", sys).args == ""
    assert Loaded("x", sys).comp_ids is not Loaded("x", sys).comp_ids
    assert repr(a) == ("Loaded(name='and2', module=" + repr(sys)
                       + ", comp_ids=[1, 2], args='count=2')")
    with pytest.raises(TypeError):
        hash(a)
