#!/usr/bin/env python3
"""Make the reference goldens of component differential tests.

    python tests/data/complib/golden.py NAME [NAME ...]

For each ``tests/data/complib/NAME.hal``: copy it and its inputs (every
``NAME.*`` and ``NAME-*.*`` file that is not a golden) into an empty
folder, run the reference's ``halrun -f NAME.hal`` there and write

- ``NAME.out``: its standard output;
- ``NAME.err``: its standard error without the ``Note: Using POSIX
  non-realtime`` lines (only when something is left);
- ``NAME.rc``: its exit status (only when not 0).

Only one reference HAL may run at a time on a machine, so the runs take
the lock file ``/tmp/halsdk-reference.lock``.  This is a maintainer's
tool: it needs the reference installed (``../shared/tools/reference
install``); the tests only read its results.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: the reference tool: $HALSDK_REFERENCE, else shared/tools/reference
#: beside the checkout (tests/data/complib -> the checkout's parent)
REFERENCE = os.environ.get("HALSDK_REFERENCE") or str(
    HERE.parents[3] / "shared" / "tools" / "reference")
NOTE = "Note: Using POSIX non-realtime"
GOLDEN = (".out", ".err", ".rc")
LOCK = "/tmp/halsdk-reference.lock"
TIMEOUT = 60
#: the user the reference tool runs the reference as
REFERENCE_USER = "halref"


def inputs(name: str) -> list[Path]:
    """The files a test needs: NAME.hal and its companions."""
    found = [p for p in HERE.iterdir()
             if (p.name.startswith(name + ".") or
                 p.name.startswith(name + "-"))
             and p.suffix not in GOLDEN and p.suffix != ".py"]
    return sorted(found)


def make(name: str) -> int:
    hal = HERE / f"{name}.hal"
    if not hal.is_file():
        print(f"{hal}: no such file", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory(prefix="complib-") as tmp:
        os.chmod(tmp, 0o755)    # the reference runs as another user
        for p in inputs(name):
            shutil.copy(p, tmp)
            os.chmod(os.path.join(tmp, p.name), 0o644)
        with open(LOCK, "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                proc = subprocess.run(
                    [REFERENCE, "halrun", "-f", hal.name], cwd=tmp,
                    capture_output=True, text=True, timeout=TIMEOUT)
            except subprocess.TimeoutExpired:
                # e.g. its rtapi_app crashed under halsampler: end every
                # process of the reference's user, then clean up its HAL
                subprocess.run(["pkill", "-KILL", "-u", REFERENCE_USER])
                subprocess.run([REFERENCE, "halrun", "-U"], cwd=tmp,
                               capture_output=True, timeout=60)
                print(f"{name}: the reference did not finish in {TIMEOUT} s"
                      " (no golden written)", file=sys.stderr)
                return 1
    if "Realtime already running" in proc.stderr:
        print(f"{name}: another reference HAL is running (someone did not "
              "take the lock); no golden written", file=sys.stderr)
        return 1
    (HERE / f"{name}.out").write_text(proc.stdout)
    err = "".join(line for line in proc.stderr.splitlines(True)
                  if line.rstrip("\n") != NOTE)
    for suffix, text in ((".err", err),
                         (".rc", f"{proc.returncode}\n"
                          if proc.returncode else "")):
        path = HERE / f"{name}{suffix}"
        if text:
            path.write_text(text)
        elif path.exists():
            path.unlink()
    print(f"{name}: exit {proc.returncode}, {len(proc.stdout.splitlines())}"
          f" lines out, {len(err.splitlines())} lines err")
    return 0


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__, file=sys.stderr)
        return 2
    return max(make(name) for name in argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
