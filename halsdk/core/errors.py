"""Exceptions of halsdk.

Every rule violation raises a subclass of :class:`HalError` whose message
names the object concerned.  The subclasses also derive from the closest
built-in exception, so ``except LookupError`` catches an unknown name.

An error raised by the core also says which rule was broken
(:attr:`HalError.rule`, a :class:`Rule`), the kind of the first object
involved (:attr:`HalError.kind`, e.g. ``"pin"``) and the names of the
objects (:attr:`HalError.names`), so that a front end can say it in its
own words: halcmd maps them to the reference's messages.
"""

from __future__ import annotations

from enum import Enum
from typing import Callable, Optional


class Rule(str, Enum):
    """The HAL rules the core enforces (``enum hal_rule`` in hal_core.h;
    the order of :attr:`HalError.names` is documented there)."""

    NONE = "NONE"
    NOT_FOUND = "NOT_FOUND"             # object
    EXISTS = "EXISTS"                   # name
    BAD_NAME = "BAD_NAME"               # name
    LOCKED = "LOCKED"                   # object
    PIN_LINKED = "PIN_LINKED"           # pin, its signal, signal asked for
    TYPE_MISMATCH = "TYPE_MISMATCH"     # signal, pin
    SECOND_WRITER = "SECOND_WRITER"     # signal, out pin, the writer there
    WRITER_AND_IO = "WRITER_AND_IO"     # signal, pin, the conflicting pin
    NAME_IS_PIN = "NAME_IS_PIN"         # signal
    NO_PINS = "NO_PINS"                 # signal
    SIG_HAS_WRITER = "SIG_HAS_WRITER"   # signal
    WRITE_OUTPUT = "WRITE_OUTPUT"       # pin
    PIN_CONNECTED = "PIN_CONNECTED"     # pin, signal
    RO_PARAM = "RO_PARAM"               # param
    NOT_REENTRANT = "NOT_REENTRANT"     # function, thread
    NEEDS_FP = "NEEDS_FP"               # function, thread
    BAD_POSITION = "BAD_POSITION"       # function, thread
    FUNCT_UNUSED = "FUNCT_UNUSED"       # function
    NOT_IN_THREAD = "NOT_IN_THREAD"     # function, thread
    HOST_ONLY = "HOST_ONLY"             # object
    NOT_OWNER = "NOT_OWNER"             # component
    FULL = "FULL"                       # object
    BAD_ARG = "BAD_ARG"                 # object
    BAD_VALUE = "BAD_VALUE"             # object (a value it cannot hold)

    def __str__(self) -> str:
        return self.value


class HalError(Exception):
    """Base class of every halsdk error.

    :param rule: the rule broken (:class:`Rule`), ``Rule.NONE`` if none.
    :param kind: kind of the first object named ("pin", "signal", ...),
        or ``None``.
    :param names: names of the objects involved, in the rule's order.
    """

    def __init__(self, *args: object, rule: Rule = Rule.NONE,
                 kind: Optional[str] = None, names: tuple[str, ...] = ()):
        super().__init__(*args)
        self.rule = Rule(rule)
        self.kind = kind
        self.names = tuple(names)


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


class TrustError(InstanceError):
    """A shared-memory segment, socket or runtime folder that this process
    does not trust: not owned by the effective user, the wrong mode, more
    than one hard link, or a symbolic link.  The message names the check
    that failed, the file and its owner."""


class LockTimeoutError(InstanceError, TimeoutError):
    """The instance lock could not be taken within the lock timeout
    (``HALSDK_LOCK_TIMEOUT``, default 5 s): the message names the
    instance and the pid holding the lock (a stopped or stuck process)."""


class HostGoneError(InstanceError, ConnectionError):
    """The host of the instance cannot be reached or went away during a
    request (refused, reset or closed channel, no answer in time); the
    message names the instance."""


class DamagedError(InstanceError):
    """The instance's shared memory holds an offset, count or list link
    that cannot be right (a stray write from a buggy component): the
    message says "instance NAME is damaged:" and what was found where.
    The process that finds it gets this error instead of a crash; the
    instance should be stopped and started again."""


class StaleError(HalError):
    """A handle whose object has been deleted."""


class LoadError(HalError):
    """A component module fails to import or to set up (a module that is
    not found at all raises :class:`NotFoundError`)."""


#: errno of a failed core call -> the exception class it raises
ERRNO_CLASS: dict[int, Callable[..., HalError]] = {
    2: NotFoundError,           # ENOENT
    17: ExistsError,            # EEXIST
    91: HalTypeError,           # EPROTOTYPE
    16: ConflictError,          # EBUSY
    1: NotPermittedError,       # EPERM
    12: CapacityError,          # ENOMEM
    28: CapacityError,          # ENOSPC
    22: InvalidError,           # EINVAL
    71: InstanceError,          # EPROTO
    19: InstanceError,          # ENODEV
    13: TrustError,             # EACCES: the trust checks of a segment
    110: LockTimeoutError,      # ETIMEDOUT
    117: DamagedError,          # EUCLEAN
}


def error_for_errno(code: int, message: str, **kw: object) -> HalError:
    """The exception of a core call that returned ``code`` (a negative
    errno, as the C API returns it) with ``message``."""
    return ERRNO_CLASS.get(-code, HalError)(message, **kw)


__all__ = [
    "CapacityError",
    "ConflictError",
    "DamagedError",
    "ExistsError",
    "HalError",
    "HalTypeError",
    "HostGoneError",
    "InstanceError",
    "InvalidError",
    "LoadError",
    "LockTimeoutError",
    "NotFoundError",
    "NotPermittedError",
    "Rule",
    "StaleError",
    "TrustError",
    "error_for_errno",
]
