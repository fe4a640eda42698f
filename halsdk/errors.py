"""Exceptions of halsdk (the public names).

The classes live in the core layer (:mod:`halsdk.core.errors`), which
raises them; this module is where users and the layers above the public
one import them from.
"""

from halsdk.core import errors as _errors
from halsdk.core.errors import *  # noqa: F403

__all__ = _errors.__all__
