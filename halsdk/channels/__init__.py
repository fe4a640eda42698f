"""The task channels of a machine: how any process talks to the task
controller that ``halsdk run`` hosts (docs/machine.rst, "The task
controller and its channels").

* :mod:`halsdk.channels.statusfields`: the status fields (the reference's
  ``linuxcnc.stat`` names) and :mod:`halsdk.channels.statuslayout`, their
  binary layout;
* :mod:`halsdk.channels.shmchannel`: the status snapshot (seqlock) and the
  error ring in a shared block of the instance;
* :mod:`halsdk.channels.cmdproto`, :mod:`~halsdk.channels.cmdserver`,
  :mod:`~halsdk.channels.cmdclient`: the command channel, a Unix socket;
* :mod:`halsdk.channels.errors`: :class:`ChannelError`, :class:`ChannelGone`.

An adapter package: it uses only the public layer, so both the task
(``halsdk.machine``) and the compat ``linuxcnc`` module build on it.
"""
