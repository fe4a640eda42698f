"""Errors of the task controller's channels (status, error and command).

Both channels raise these: :class:`ChannelError` when a channel cannot be
used (bad header, wrong version, a refused handshake, a garbled reply) and
:class:`ChannelGone` when the task at the other end has stopped.
"""

from halsdk.errors import HalError

__all__ = ["ChannelError", "ChannelGone"]


class ChannelError(HalError):
    """A task channel cannot be used; the message says why and what to do."""


class ChannelGone(ChannelError):
    """The task at the other end of a channel stopped (the machine is gone)."""
