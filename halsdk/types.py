"""HAL types and directions (the public names).

The table lives in the core layer (:mod:`halsdk.core.types`), which the
core itself uses; this module is where users and the layers above the
public one import it from.
"""

from halsdk.core import types as _types
from halsdk.core.types import *  # noqa: F403

__all__ = _types.__all__
