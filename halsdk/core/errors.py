"""Exceptions of halsdk.

Every rule violation raises a subclass of :class:`HalError` whose message
names the object concerned.  The subclasses also derive from the closest
built-in exception, so ``except LookupError`` catches an unknown name.
"""


class HalError(Exception):
    """Base class of every halsdk error."""


class NotFoundError(HalError, LookupError):
    """No object of that name (pin, signal, component, ...)."""


class ExistsError(HalError):
    """An object of that name exists already."""


class HalTypeError(HalError, TypeError):
    """Types do not match (e.g. linking a bit pin to a float signal)."""


class ConflictError(HalError):
    """The operation conflicts with the current state: a second writer on a
    signal, a pin linked elsewhere, setting a driven signal, threads
    running while stepping."""


class NotPermittedError(HalError, PermissionError):
    """Not allowed: writing an output pin or a read-only param, a locked
    instance, an operation only the host may do."""


class InvalidError(HalError, ValueError):
    """A bad argument: a badly formed name, an out-of-range value."""


class CapacityError(HalError):
    """The instance (shared-memory segment) is full."""


class InstanceError(HalError):
    """No instance, an incompatible one (ABI version), or a dead host."""


class StaleError(HalError):
    """A handle whose object has been deleted."""


class LoadError(HalError):
    """A component module fails to import or to set up (a module that is
    not found at all raises :class:`NotFoundError`)."""


__all__ = [
    "CapacityError", "ConflictError", "ExistsError", "HalError",
    "HalTypeError", "InstanceError", "InvalidError", "LoadError",
    "NotFoundError", "NotPermittedError", "StaleError",
]
