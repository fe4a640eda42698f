"""Running the halcompile command as a user does."""

from __future__ import annotations

import os
import subprocess
import sys


def halcompile(*args: str, cwd: str) -> subprocess.CompletedProcess:
    """Run ``python -m halcompile`` the way a user runs the command."""
    env = dict(os.environ)
    # the packages this test imported (installed, or an editable tree):
    # never the repository root, which holds no compiled core in a clone
    import halcompile as hc
    import halsdk
    dirs = {os.path.dirname(os.path.dirname(m.__file__)) for m in (hc, halsdk)}
    env["PYTHONPATH"] = os.pathsep.join([*sorted(dirs),
                                         env.get("PYTHONPATH", "")])
    return subprocess.run([sys.executable, "-m", "halcompile", *args],
                          cwd=cwd, env=env, capture_output=True, text=True)
