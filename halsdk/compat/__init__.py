"""Compatibility layers for programs written for LinuxCNC.

:mod:`halsdk.compat.hal` implements the documented API of LinuxCNC's
Python ``hal`` module on top of halsdk, so that userspace components
written for LinuxCNC run unchanged.  To let such a program keep its
``import hal``, put :func:`pythonpath` on ``PYTHONPATH``::

    PYTHONPATH=$(python -c 'import halsdk.compat as c; print(c.pythonpath())') \\
        python3 mycomponent.py

The same folder holds ``linuxcnc``: ``import linuxcnc`` then gives
:mod:`halsdk.compat.linuxcnc`, the reference's ``linuxcnc`` module on the
channels of a machine started with ``halsdk run`` (it lives in the machine
layer, whose channels it reads).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Optional

__all__ = ["program_env", "pythonpath"]


def pythonpath() -> str:
    """The folder holding a ``hal`` module that stands for
    :mod:`halsdk.compat.hal` and a ``linuxcnc`` module that stands for
    :mod:`halsdk.compat.linuxcnc` (put it on ``PYTHONPATH``)."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "pypath")


def program_env(env: Optional[Mapping[str, str]] = None) -> dict[str, str]:
    """``env`` (default: this process's environment) with
    :func:`pythonpath` first on ``PYTHONPATH`` and the user's
    ``PYTHONPATH`` after it: the environment ``halrun``, ``halcmd`` and
    ``halsdk run`` give the programs they start with ``loadusr``, so that
    a Python program written for LinuxCNC can ``import hal`` and
    ``import linuxcnc``, as under the reference's halrun."""
    out = dict(os.environ if env is None else env)
    first = pythonpath()
    rest = [p for p in out.get("PYTHONPATH", "").split(os.pathsep)
            if p and p != first]
    out["PYTHONPATH"] = os.pathsep.join([first, *rest])
    return out
