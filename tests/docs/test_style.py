"""The Python code of the repository is ruff clean (PEP 8 and more)."""

from __future__ import annotations

import shutil
import subprocess

from helpers import REPO

ROOT = str(REPO)


def test_ruff_clean():
    ruff = shutil.which("ruff")
    assert ruff, "ruff is part of the test extras: pip install '.[test]'"
    proc = subprocess.run([ruff, "check", "--no-cache", "halsdk", "tests",
                           "bench", "docs", "components", "halcompile",
                           "setup.py"],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
