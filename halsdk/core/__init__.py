"""The core layer of halsdk: the keeper of the HAL rules.

- ``_core``: the C core (``src/``) and its Cython binding: the shared-memory
  segment, the objects and their rules, the thread executor, streams;
- :mod:`halsdk.core.instance`: creating, attaching to and removing an
  instance;
- :mod:`halsdk.core.channel`: the request channel from attached processes
  to the host.

Nothing here imports a module above the core layer; only the public layer
(:mod:`halsdk.hal`, :mod:`halsdk.component`, :mod:`halsdk.types`, ...)
imports this package.  ``docs/architecture.rst`` draws the layers.
"""
