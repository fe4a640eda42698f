#!/usr/bin/env python3
"""Regenerate the golden outputs of the rs274 programs from the reference.

    python3 tests/gcode/programs/regenerate.py [--reference PATH] [NAME ...]

For every program ``GROUP/NAME.ngc`` under this folder (or only those
whose ``GROUP/NAME`` is given) it runs the reference's standalone
interpreter, ``reference rs274 -g prog.ngc``, in a fresh folder under
/tmp holding a copy of the program, of ``NAME.tbl`` (passed as ``-t``),
``NAME.ini`` (passed as ``-i``) and ``NAME.var`` (passed as ``-v``) when
they exist (``NAME.args`` holds more options, ``-b`` or ``-n 0``), and of
the library
files of the group (``.ngc`` files whose first line starts with
``o<``: subroutine files and REMAP procedures, not programs), of its
``.py`` files (the ``[PYTHON]`` plugin of REMAP programs) and of its user
M-code programs (files named ``M100`` to ``M199``, copied with their
execute bit, for an INI file's USER_M_PATH). It writes next to the
program:

* ``NAME.out``: the standard output (the golden data compared byte for
  byte by tests/gcode/test_rs274_golden.py);
* ``NAME.status``: the exit status;
* ``NAME.err``: the standard error without the word of the reference's
  ``executing`` banner (its newline stays); compared with ours, which
  adds file:line:col before each message.

Runs are sequential. The reference is an oracle only: this script is run
by hand, never by the test suite.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: the reference tool beside the checkout (../shared/tools/reference), as
#: bench/benchlib.py finds it; HALSDK_REFERENCE_TOOL overrides it
DEFAULT_REFERENCE = os.environ.get(
    "HALSDK_REFERENCE_TOOL",
    str(HERE.parents[2].parent / "shared" / "tools" / "reference"))


def run_reference(args: list[str], cwd: str, timeout: float
                  ) -> subprocess.CompletedProcess[bytes]:
    """Run the reference tool in a session of its own; past ``timeout``
    kill the whole session (the tool runs ``rs274`` as another user, so
    killing the tool alone would leave a runaway ``rs274`` spinning)."""
    proc = subprocess.Popen(args, cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(OSError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        raise
    return subprocess.CompletedProcess(args, proc.returncode, out, err)


def is_library(path: Path) -> bool:
    """A subroutine file (first line ``o<name> sub``), not a program."""
    with open(path, encoding="utf-8") as f:
        return f.readline().lstrip().lower().startswith("o<")


def programs() -> list[Path]:
    """Every program under this folder, sorted."""
    return sorted(p for p in HERE.glob("*/*.ngc") if not is_library(p))


def run_one(prog: Path, reference: str) -> int:
    with tempfile.TemporaryDirectory(prefix="rs274-golden-") as tmp:
        os.chmod(tmp, 0o755)
        work = Path(tmp)
        shutil.copy(prog, work / "prog.ngc")
        args = [reference, "rs274", "-g"]
        tbl = prog.with_suffix(".tbl")
        if tbl.exists():
            shutil.copy(tbl, work / "tool.tbl")
            args += ["-t", "tool.tbl"]
        ini = prog.with_suffix(".ini")
        if ini.exists():
            shutil.copy(ini, work / "prog.ini")
            args += ["-i", "prog.ini"]
        var = prog.with_suffix(".var")
        if var.exists():
            shutil.copy(var, work / "prog.var")
            args += ["-v", "prog.var"]
        for lib in prog.parent.glob("*.ngc"):
            if lib != prog and is_library(lib):
                shutil.copy(lib, work / lib.name)
        for module in prog.parent.glob("*.py"):
            # the [PYTHON] plugin files of the group's INI files
            shutil.copy(module, work / module.name)
        for f in work.iterdir():
            os.chmod(f, 0o644)
        for mcode in prog.parent.glob("M1[0-9][0-9]"):
            shutil.copy(mcode, work / mcode.name)
            os.chmod(work / mcode.name,
                     0o755 if os.access(mcode, os.X_OK) else 0o644)
        extra = prog.with_suffix(".args")
        if extra.exists():
            args += extra.read_text().split()
        args.append("prog.ngc")
        done = run_reference(args, str(work), 60)
    prog.with_suffix(".out").write_bytes(done.stdout)
    prog.with_suffix(".status").write_text(f"{done.returncode}\n")
    err = done.stderr.decode("utf-8", "replace")
    if err.startswith("executing"):
        err = err[len("executing"):]
    prog.with_suffix(".err").write_text(err)
    return done.returncode


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--reference", default=DEFAULT_REFERENCE)
    p.add_argument("names", nargs="*", help="GROUP/NAME of programs")
    a = p.parse_args()
    chosen = programs()
    if a.names:
        chosen = [q for q in chosen
                  if f"{q.parent.name}/{q.stem}" in a.names]
    for prog in chosen:
        rc = run_one(prog, a.reference)
        print(f"{prog.parent.name}/{prog.stem}: {rc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
