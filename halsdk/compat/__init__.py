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

__all__ = ["pythonpath"]


def pythonpath() -> str:
    """The folder holding a ``hal`` module that stands for
    :mod:`halsdk.compat.hal` and a ``linuxcnc`` module that stands for
    :mod:`halsdk.compat.linuxcnc` (put it on ``PYTHONPATH``)."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "pypath")
