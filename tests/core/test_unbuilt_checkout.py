"""A source tree that was never built says so when imported."""

from __future__ import annotations

import shutil
import subprocess
import sys

import halsdk


def test_import_from_an_unbuilt_tree_says_how_to_build(tmp_path):
    """The Python files of halsdk without the compiled core, imported from
    their folder as from a fresh clone: one clear line, no circular
    import message."""
    src = halsdk.__path__[0]
    shutil.copytree(src, tmp_path / "halsdk",
                    ignore=shutil.ignore_patterns("*.so", "*.pyd",
                                                  "__pycache__"))
    proc = subprocess.run([sys.executable, "-c", "import halsdk"],
                          cwd=tmp_path, capture_output=True, text=True,
                          env={"PATH": "/usr/bin:/bin", "PYTHONPATH": ""})
    assert proc.returncode == 1
    last = proc.stderr.strip().splitlines()[-1]
    assert last == (f"ModuleNotFoundError: halsdk is not built here "
                    f"({tmp_path / 'halsdk'}): pip install -e .")
    assert "circular" not in proc.stderr
