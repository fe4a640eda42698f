"""One ``.comp`` → the generated source a compiler builds.

The single halcompile API for turning a component into something to
compile: the ``halcompile`` command (:mod:`halcompile.cli`) builds the
result with :func:`halsdk.build.build_component`, and the package's
``setup.py`` turns it into a setuptools ``Extension`` for every shipped
component.  Both therefore agree on the generated code, the compiler and
linker options a ``.comp`` asks for (``option extra_compile_args``,
``option extra_link_args``) and how a Cython code section maps back onto
the ``.comp`` lines.
"""

from __future__ import annotations

import os
import shlex
from dataclasses import dataclass, field
from typing import Optional

from halcompile.gen_c import MAX_PERSONALITIES
from halcompile.model import Component
from halcompile.parser import CompError, parse_file


@dataclass
class GeneratedSource:
    """What :func:`generate_source` wrote for one component."""

    comp: Component
    #: the generated file: ``NAME.c`` (C code section) or ``NAME.pyx``
    path: str
    #: ``"c"`` or ``"cython"``
    language: str
    #: compiler options the .comp asks for
    compile_args: list[str] = field(default_factory=list)
    #: linker options the .comp asks for
    link_args: list[str] = field(default_factory=list)
    #: Cython only: generated line → (.comp line, column shift)
    origin: list[tuple[int, int]] = field(default_factory=list)

    @property
    def userspace(self) -> bool:
        return bool(self.comp.option("userspace"))


def write_if_changed(path: str, text: str) -> None:
    """Write ``text`` unless the file holds it already (keeps builds that
    look at file times incremental)."""
    try:
        with open(path, encoding="utf-8") as f:
            if f.read() == text:
                return
    except OSError:
        pass
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def generate_source(comp: Component | str, out_dir: str,
                    max_personalities: int = MAX_PERSONALITIES,
                    c_filename: Optional[str] = None) -> GeneratedSource:
    """Generate the source of ``comp`` (a parsed component or the path of
    a ``.comp`` file) into ``out_dir``.

    ``c_filename`` is the file name the ``#line`` directives of generated
    C parts name (default: the written file's path).  Raises
    :class:`~halcompile.parser.CompError` for a bad ``.comp`` and
    :class:`~halcompile.gen_cython.CythonSourceError` for a bad Cython
    code section.
    """
    from halcompile import gen_c, gen_cython

    if isinstance(comp, str):
        comp = parse_file(comp)
    os.makedirs(out_dir, exist_ok=True)
    compile_args = shlex.split(str(comp.option("extra_compile_args", "")))
    link_args = shlex.split(str(comp.option("extra_link_args", "")))
    if comp.option("cython"):
        text, origin = gen_cython.generate(comp)
        path = os.path.join(out_dir, comp.name + ".pyx")
        write_if_changed(path, text)
        return GeneratedSource(comp, path, "cython", compile_args,
                               link_args, origin)
    path = os.path.join(out_dir, comp.name + ".c")
    text = gen_c.generate(comp, c_filename or os.path.abspath(path),
                          max_personalities)
    write_if_changed(path, text)
    return GeneratedSource(comp, path, "c", compile_args, link_args)


__all__ = ["CompError", "GeneratedSource", "generate_source",
           "write_if_changed"]
