"""halcompile: the ``.comp`` component compiler of halsdk.

``parse``/``parse_file`` read a ``.comp`` file into a
:class:`~halcompile.model.Component`; :func:`~halcompile.gen_c.generate`
turns a component with a C code section into C source that
:func:`halsdk.build.build_component` compiles; :func:`halcompile.cli.main`
is the ``halcompile`` command.
"""

from halcompile.model import Component
from halcompile.parser import CompError, parse, parse_file

__all__ = ["Component", "CompError", "parse", "parse_file"]
