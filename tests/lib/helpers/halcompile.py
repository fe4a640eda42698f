"""Running the halcompile command as a user does, and loading what it
built."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import Iterator

from helpers import data_path
from helpers.environment import on_halsdk_path


def child_env(**extra: str) -> dict[str, str]:
    """The environment of a child process: this one's, with ``extra`` set
    and the packages this test imported (installed, or an editable tree)
    first on PYTHONPATH; never the repository root, which holds no
    compiled core in a clone."""
    import halcompile as hc
    import halsdk
    env = dict(os.environ)
    dirs = {os.path.dirname(os.path.dirname(m.__file__)) for m in (hc, halsdk)}
    env["PYTHONPATH"] = os.pathsep.join([*sorted(dirs),
                                         env.get("PYTHONPATH", "")])
    env.update(extra)
    return env


def halcompile(*args: str, cwd: str, **env: str) -> subprocess.CompletedProcess:
    """Run ``python -m halcompile`` the way a user runs the command (with
    the variables ``env`` set for it)."""
    return subprocess.run([sys.executable, "-m", "halcompile", *args],
                          cwd=cwd, env=child_env(**env), capture_output=True,
                          text=True)


def halrun_file(path, cwd, **env: str) -> subprocess.CompletedProcess:
    """Our ``halrun -f PATH`` run in ``cwd`` as a user runs it (with the
    variables ``env`` set for it), as the command halcompile's programs
    are loaded by."""
    return subprocess.run([sys.executable, "-m", "halsdk.halcmd.cli",
                           "halrun", "-f", str(path)], cwd=str(cwd),
                          env=child_env(**env), capture_output=True,
                          text=True, timeout=60)


def comp_files(*names: str) -> list[str]:
    """The test comps ``tests/data/comps/NAME.comp``."""
    return [str(data_path("comps", name + ".comp")) for name in names]


@contextlib.contextmanager
def compiled_on_path(folder, *args: str) -> Iterator[str]:
    """``halcompile --compile ARGS`` run in ``folder`` (it must succeed),
    then ``folder`` first on HALSDK_PATH while the block runs, so that
    loadrt finds what was built."""
    folder = str(folder)
    proc = halcompile("--compile", *args, cwd=folder)
    assert proc.returncode == 0, proc.stderr
    with on_halsdk_path(folder):
        yield folder


def check_ddt(hal, funct: str, pin_in: str, pin_out: str,
              period: int = 1_000_000) -> None:
    """A derivative comp (the test comps hcddt, hccyddt) in a thread of
    ``period`` ns: its output is the exact difference quotient of its
    input, cycle by cycle."""
    hal.newthread("servo", period)
    hal.addf(funct, "servo")
    inputs = [0.0, 0.5, 2.0, 1.25, -3.0, -3.0, 7.75]
    trace = hal.run(len(inputs), inputs={pin_in: inputs}, record=[pin_out])
    old, want = 0.0, []
    for x in inputs:
        want.append((x - old) / (period * 1e-9))
        old = x
    assert list(trace[pin_out]) == want
