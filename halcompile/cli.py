"""The ``halcompile`` command.

Modes (one per run; ``--preprocess`` is the default):

``--preprocess``  write the C file generated from each ``.comp`` next to it
                  (or to ``-o FILE``)
``--compile``     build each ``.comp`` or hand-written ``.c`` into a
                  component module in the current folder (or the folder
                  ``-o DIR``); ``loadrt`` finds it through ``HALSDK_PATH``
``--install``     build into the user component folder, where ``loadrt``
                  finds it with no set-up
``--document``    write the manual page (``NAME.9``; ``NAME.1`` for a
                  userspace component) and the reStructuredText page
                  (``NAME.rst``) of each ``.comp`` into the current folder
                  (or the folder ``-o DIR``)
``--view-doc``    show the manual page of each ``.comp`` (with ``man``)
``--install-doc`` install the manual page of each ``.comp`` into the
                  user's manual folder (``~/.local/share/man``, or the
                  folder ``-o DIR``), where ``man`` finds it

A ``.comp`` with ``option userspace`` (or a ``.c`` program with ``-u``)
also gets an executable launcher for ``loadusr`` (see
:mod:`halcompile.gen_user`); one with ``option cython`` is built from a
generated ``.pyx`` (see :mod:`halcompile.gen_cython`).

User errors print ``file:line:col: message`` (or the compiler's messages,
which point into the ``.comp`` file) and exit with status 1.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import shlex
import sys
import tempfile
from collections.abc import Sequence
from typing import Optional

from halcompile.gen_c import MAX_PERSONALITIES, generate
from halcompile.model import Component
from halcompile.parser import CompError, parse_file
from halcompile.sources import generate_source
from halsdk import console

#: flags of every generated module: its symbols stay private to it
_PRIVATE = ["-fvisibility=hidden"]
#: lines of the build tool's traceback, not of the compiler
_NOISE = re.compile(r"^\s*raise |^(distutils|setuptools)\.|"
                    r"DistutilsExecError|CompileError|LinkError")


class UsageError(Exception):
    pass


def _arg_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="halcompile",
        description="Build HAL component modules from .comp and .c files.")
    mode = p.add_mutually_exclusive_group()
    for flag in ("compile", "install", "preprocess", "document",
                 "view-doc", "install-doc"):
        mode.add_argument(f"--{flag}", dest="mode", action="store_const",
                          const=flag.replace("-", "_"))
    p.add_argument("-o", "--of", dest="output", metavar="OUT",
                   help="--preprocess: the C file to write; --compile and "
                        "--document: the folder that receives the module or "
                        "the pages; --install-doc: the manual folder (one "
                        "input only for --preprocess)")
    p.add_argument("-u", "--userspace", action="store_true",
                   help="a .c input is a userspace program (with main()), "
                        "started by loadusr; .comp files say it with "
                        "'option userspace'")
    p.add_argument("--extra-compile-args", default="",
                   help="more C compiler arguments (one string)")
    p.add_argument("--extra-link-args", default="",
                   help="more linker arguments (one string)")
    p.add_argument("--personalities", type=int, default=MAX_PERSONALITIES,
                   help="size of the personality modparam of components "
                        "with personality (default: %(default)s)")
    p.add_argument("files", nargs="+", metavar="FILE")
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Console entry point: :func:`_main` under the broken-pipe rule
    of every halsdk program (:mod:`halsdk.console`)."""
    return console.run(_main, argv)


def _main(argv: Optional[Sequence[str]] = None) -> int:
    """Run halcompile with ``argv`` (default: ``sys.argv[1:]``); returns
    the exit status (0, or 1 after a user error)."""
    args = _arg_parser().parse_args(argv)
    mode = args.mode or "preprocess"
    try:
        if mode in ("document", "view_doc", "install_doc"):
            return _document(mode, args.files, args.output)
        if args.personalities < 1:
            raise UsageError("--personalities must be at least 1")
        if args.output and mode == "preprocess" and len(args.files) > 1:
            raise UsageError("-o takes one input file with --preprocess")
        for path in args.files:
            process(path, mode, args.output,
                    shlex.split(args.extra_compile_args),
                    shlex.split(args.extra_link_args), args.personalities,
                    userspace=args.userspace)
    except (CompError, UsageError) as exc:
        print(f"{exc}" if isinstance(exc, CompError)
              else f"halcompile: {exc}", file=sys.stderr)
        return 1
    except _Failed as exc:
        print(str(exc), file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"halcompile: {exc}", file=sys.stderr)
        return 1
    return 0


class _Failed(Exception):
    """A build failed; the message is what the user needs to see."""


def _document(mode: str, files: Sequence[str],
              output: Optional[str]) -> int:
    """--document, --view-doc and --install-doc: the pages of each
    ``.comp`` (raises :class:`UsageError` or
    :class:`~halcompile.parser.CompError` for bad input)."""
    from halcompile.gen_doc import document, install_doc, view_doc

    for path in files:
        if not os.path.isfile(path):
            raise UsageError(f"{path}: no such file")
        if not path.endswith(".comp"):
            raise UsageError(f"{path}: only .comp files have documentation")
    status = 0
    for path in files:
        if mode == "document":
            for written in document(path, output or os.getcwd()):
                print(written)
        elif mode == "install_doc":
            print(install_doc(path, output))
        else:
            status = view_doc(path) or status
    return status


def process(path: str, mode: str, output: Optional[str] = None,
            cflags: Sequence[str] = (), ldflags: Sequence[str] = (),
            personalities: int = MAX_PERSONALITIES,
            userspace: bool = False) -> str:
    """Preprocess, compile or install one file; returns what was
    written.  ``userspace``: a ``.c`` file is a userspace program."""
    if not os.path.isfile(path):
        raise UsageError(f"{path}: no such file")
    ext = os.path.splitext(path)[1]
    if ext == ".c":
        if mode == "preprocess":
            raise UsageError(f"{path}: a .c file needs --compile or "
                             "--install")
        return _build(path, None, mode, output, cflags, ldflags,
                      userspace=userspace)
    if ext != ".comp":
        raise UsageError(f"{path}: expected a .comp or .c file")
    comp = parse_file(path)
    if comp.option("cython"):
        return _cython(path, comp, mode, output, cflags, ldflags)
    if mode == "preprocess":
        out = output or os.path.splitext(path)[0] + ".c"
        text = generate(comp, os.path.basename(out), personalities)
        with open(out, "w", encoding="utf-8") as f:
            f.write(text)
        return out
    return _build(path, comp, mode, output, cflags, ldflags, personalities)


def _build(path: str, comp: Optional[Component], mode: str,
           output: Optional[str], cflags: Sequence[str],
           ldflags: Sequence[str],
           personalities: int = MAX_PERSONALITIES,
           userspace: bool = False) -> str:
    from halsdk.build import BuildError, build_component
    from halsdk.loader import user_component_dir

    out_dir = user_component_dir() if mode == "install" else \
        (output or os.getcwd())
    includes = [os.path.dirname(os.path.abspath(path))]
    # as LinuxCNC's module builds do: RTAPI for realtime code, ULAPI for
    # userspace programs (real sources test them around their includes)
    user = userspace if comp is None else bool(comp.option("userspace"))
    flags = _PRIVATE + ["-DULAPI" if user else "-DRTAPI"] + list(cflags)
    try:
        if comp is None and userspace:
            name = os.path.splitext(os.path.basename(path))[0]
            dest = _build_program(path, name, out_dir, includes, flags,
                                  list(ldflags))
        elif comp is None:
            name = os.path.splitext(os.path.basename(path))[0]
            dest = build_component(path, out_dir=out_dir, name=name,
                                   include_dirs=includes,
                                   extra_compile_args=flags,
                                   extra_link_args=list(ldflags))
        else:
            deps = _local_headers_digest(comp, includes[0])
            if deps:
                flags.append(f"-DHALCOMPILE_DEPS=0x{deps}")
            with tempfile.TemporaryDirectory(prefix="halcompile-") as tmp:
                src = generate_source(comp, tmp, personalities,
                                      c_filename=comp.name + ".c")
                dest = build_component(src.path, out_dir=out_dir,
                                       name=comp.name,
                                       include_dirs=includes,
                                       extra_compile_args=flags
                                       + src.compile_args,
                                       extra_link_args=list(ldflags)
                                       + src.link_args)
    except BuildError as exc:
        lines = str(exc).splitlines()
        body = "\n".join(ln for ln in lines[1:] if not _NOISE.search(ln)) \
            if len(lines) > 1 else str(exc)
        raise _Failed(f"{path}: compilation failed:\n{body}") from None
    if userspace or (comp is not None and comp.option("userspace")):
        dest = _launchers(dest, mode)
    print(dest)
    return dest


def _cython(path: str, comp: Component, mode: str, output: Optional[str],
            cflags: Sequence[str], ldflags: Sequence[str]) -> str:
    """A .comp whose code section is Cython: write its .pyx
    (--preprocess) or build it."""
    from halcompile import gen_cython
    from halcompile.model import Loc
    from halsdk.build import BuildError, build_component
    from halsdk.loader import user_component_dir

    out_dir = user_component_dir() if mode == "install" else \
        (output or os.getcwd())
    with tempfile.TemporaryDirectory(prefix="halcompile-") as tmp:
        try:
            src = generate_source(comp, tmp)
        except gen_cython.CythonSourceError as exc:
            with open(path, encoding="utf-8") as f:
                lines = f.read().split("\n")
            shown = lines[exc.line - 1] if 0 < exc.line <= len(lines) \
                else None
            raise CompError(Loc(comp.file, exc.line, 1), exc.message,
                            shown) from None
        if mode == "preprocess":
            out = output or os.path.splitext(path)[0] + ".pyx"
            with open(src.path, encoding="utf-8") as f:
                text = f.read()
            with open(out, "w", encoding="utf-8") as f:
                f.write(text)
            return out
        try:
            dest = build_component(
                src.path, out_dir=out_dir, name=comp.name,
                include_dirs=[os.path.dirname(os.path.abspath(path))],
                extra_compile_args=_PRIVATE + list(cflags)
                + src.compile_args,
                extra_link_args=list(ldflags) + src.link_args)
        except BuildError as exc:
            raise _Failed(f"{path}: compilation failed:\n"
                          + _map_pyx_lines(str(exc), comp, src.origin)
                          ) from None
    print(dest)
    return dest


def _map_pyx_lines(message: str, comp: Component,
                   origin: list[tuple[int, int]]) -> str:
    """Point Cython's ``x.pyx:LINE:COL:`` messages at the .comp line (and
    column) the text came from; generated lines keep the .pyx place."""
    out = []
    for line in message.splitlines()[1:] or message.splitlines():
        if _NOISE.search(line) or line.startswith("Error compiling Cython"):
            continue

        def repl(m: re.Match[str]) -> str:
            n, col = int(m.group(2)), int(m.group(3))
            src, shift = origin[n - 1] if 0 < n <= len(origin) else (0, 0)
            if not src:
                return f"{comp.name}.pyx (generated):{n}:{col}"
            # Cython counts columns from 0
            return f"{comp.file}:{src}:{max(1, col - shift + 1)}"
        out.append(re.sub(r"(\S*\.pyx):(\d+):(\d+)", repl, line))
    return "\n".join(out)


def _build_program(path: str, name: str, out_dir: str,
                   includes: list[str], flags: list[str],
                   ldflags: list[str]) -> str:
    """Build a hand-written userspace program (``main()``) into a
    component module (see :mod:`halcompile.gen_user`)."""
    from halcompile.gen_user import program_wrapper
    from halsdk.build import build_component

    with tempfile.TemporaryDirectory(prefix="halcompile-") as tmp:
        wrapper = os.path.join(tmp, "halsdk_user_main.c")
        with open(wrapper, "w", encoding="utf-8") as f:
            f.write(program_wrapper())
        # the program's main() becomes a plain function of the module
        return build_component(path, out_dir=out_dir, name=name,
                               extra_sources=[wrapper],
                               include_dirs=includes,
                               extra_compile_args=flags
                               + ["-Dmain=halsdk_user_main"],
                               extra_link_args=ldflags)


def _launchers(module: str, mode: str) -> str:
    """Write the launcher script of a userspace module next to it (and,
    for --install, into the user's bin folder); returns the script
    next to the module."""
    from halcompile.gen_user import user_bin_dir, write_launcher

    name = os.path.basename(module).split(".")[0]
    script = write_launcher(os.path.dirname(module), name, module)
    if mode == "install":
        print(write_launcher(user_bin_dir(), name, module))
    return script


def _local_headers_digest(comp: Component, folder: str) -> str:
    """A hash of the quoted headers found next to the .comp, so that a
    changed header makes a new build (the build cache hashes only the
    generated C file)."""
    names = [inc[1:-1] for inc in comp.includes if inc.startswith('"')]
    names += re.findall(r'#\s*include\s*"([^"]+)"', comp.code)
    h = hashlib.sha256()
    found = False
    for name in sorted(set(names)):
        p = os.path.join(folder, name)
        if os.path.isfile(p):
            found = True
            h.update(name.encode())
            with open(p, "rb") as f:
                h.update(f.read())
    return h.hexdigest()[:16] if found else ""


if __name__ == "__main__":      # pragma: no cover
    sys.exit(main())
