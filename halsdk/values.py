"""Turning words and Python values into HAL values (the public names).

The table lives in the core layer (:mod:`halsdk.core.values`), which the
core itself uses; this module is where users and the layers above the
public one import it from.
"""

from halsdk.core import values as _values
from halsdk.core.values import *  # noqa: F403

__all__ = _values.__all__
