"""Exceptions of halsdk (the public names).

The classes live in the core layer (:mod:`halsdk.core.errors`), which
raises them; this module is where users and the layers above the public
one import them from.
"""

from halsdk.core.errors import (
    CapacityError,
    ConflictError,
    ExistsError,
    HalError,
    HalTypeError,
    InstanceError,
    InvalidError,
    LoadError,
    NotFoundError,
    NotPermittedError,
    StaleError,
)

__all__ = [
    "CapacityError", "ConflictError", "ExistsError", "HalError",
    "HalTypeError", "InstanceError", "InvalidError", "LoadError",
    "NotFoundError", "NotPermittedError", "StaleError",
]
