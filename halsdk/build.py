"""Building component modules: Cython (.pyx) or C (.c) to an extension.

:func:`build_component` compiles a component source into an extension
module that ``loadrt`` can load, with the system C compiler.  Results are
cached by a hash of everything that goes into the build (sources, halsdk
headers, Python version, compiler and flags), so a second build of the
same source is a file copy.

There is no setuptools round-trip: Cython runs in this process, then the
compiler (one process per C file, in parallel) and the linker are called
directly, with the commands setuptools would use: ``CC CFLAGS CCSHARED``
and ``LDSHARED`` of :mod:`sysconfig` (and the same environment variables,
see :func:`toolchain`), the Python include folders and ``EXT_SUFFIX``.
A finished module is moved into the cache in one rename, so a failed or
interrupted build leaves nothing there.

Cache folder: ``$HALSDK_CACHE`` or ``~/.cache/halsdk/build``.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.machinery
import io
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import threading
from collections.abc import Sequence
from typing import Optional

from halsdk.errors import HalError

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
INCLUDE_DIR = os.path.join(PACKAGE_DIR, "include")
C_ENTRY = os.path.join(PACKAGE_DIR, "core", "src", "c_module.c")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_DIAG = re.compile(r"^\S[^:]*:\d+:(\d+:)? |^In file included|^\s+\d* *\||"
                   r"[Ee]rror")
_NOISE = re.compile(r"^\s*raise |^(distutils|setuptools)\.|Error: command|"
                    r"^Traceback|^\s+File ")
#: Cython keeps its error state per thread but redirects sys.stderr
_CYTHON_LOCK = threading.Lock()
#: a call of an undeclared function (an API that halsdk does not
#: provide) is an error that names it, not a module that fails to load
_FLAGS = ["-O2", "-std=gnu11", "-Wall", "-Wno-unused-function",
          "-Wno-unused-variable", "-Werror=implicit-function-declaration"]


class BuildError(HalError):
    """A component failed to compile; the message holds the compiler's
    output."""


def include_dir() -> str:
    """Folder of the C headers (hal.h, rtapi.h, ...)."""
    return INCLUDE_DIR


def cache_dir() -> str:
    return os.environ.get("HALSDK_CACHE") or os.path.join(
        os.path.expanduser("~"), ".cache", "halsdk", "build")


def extension_suffix() -> str:
    return sysconfig.get_config_var("EXT_SUFFIX") or \
        importlib.machinery.EXTENSION_SUFFIXES[0]


def _digest(paths: Sequence[str], extra: Sequence[str],
            header_dirs: Sequence[str] = ()) -> str:
    """Hash of everything a build reads: sources, the headers of halsdk
    and of the given folders, the entry code, Python and the flags."""
    h = hashlib.sha256()
    for p in paths:
        h.update(p.encode() if not os.path.isfile(p) else b"")
        if os.path.isfile(p):
            with open(p, "rb") as f:
                h.update(f.read())
    for folder in (INCLUDE_DIR, *header_dirs):
        if not os.path.isdir(folder):
            continue
        for name in sorted(os.listdir(folder)):
            path = os.path.join(folder, name)
            if name.endswith((".h", ".pxd", ".pxi")) and os.path.isfile(path):
                with open(path, "rb") as f:
                    h.update(name.encode() + f.read())
    for p in (C_ENTRY, os.path.join(PACKAGE_DIR, "hal.pxd")):
        with open(p, "rb") as f:
            h.update(f.read())
    # the realtime driver helpers that a module may cimport
    rt_dir = os.path.join(PACKAGE_DIR, "driverkit")
    for name in sorted(os.listdir(rt_dir)):
        if name.endswith(".pxd"):
            with open(os.path.join(rt_dir, name), "rb") as f:
                h.update(name.encode() + f.read())
    h.update(sys.version.encode())
    h.update("\0".join(extra).encode())
    return h.hexdigest()[:24]


def toolchain() -> tuple[list[str], list[str]]:
    """The C compiler and shared-library linker commands, as setuptools
    builds them from sysconfig (``CC CFLAGS CCSHARED`` and ``LDSHARED``)
    and the ``CC``/``CFLAGS``/``CPPFLAGS``/``LDSHARED``/``LDFLAGS``
    environment variables."""
    cc, cflags, ccshared, ldshared = (
        sysconfig.get_config_var(v) or ""
        for v in ("CC", "CFLAGS", "CCSHARED", "LDSHARED"))
    env = os.environ
    if "CC" in env:
        if "LDSHARED" not in env and ldshared.startswith(cc):
            ldshared = env["CC"] + ldshared[len(cc):]
        cc = env["CC"]
    if "LDSHARED" in env:
        ldshared = env["LDSHARED"]
    if "LDFLAGS" in env:
        ldshared += " " + env["LDFLAGS"]
    for var in ("CFLAGS", "CPPFLAGS"):
        if var in env:
            cflags += " " + env[var]
            ldshared += " " + env[var]
    return (shlex.split(f"{cc} {cflags} {ccshared}"), shlex.split(ldshared))


def _python_includes() -> list[str]:
    paths = sysconfig.get_paths()
    return list(dict.fromkeys([paths["include"], paths["platinclude"]]))


def _library_dirs() -> list[str]:
    # setuptools adds it when Python is a shared library
    libdir = sysconfig.get_config_var("LIBDIR")
    return [libdir] if sysconfig.get_config_var("Py_ENABLE_SHARED") \
        and libdir else []


def build_component(source: str, out_dir: Optional[str] = None,
                    name: Optional[str] = None,
                    extra_sources: Sequence[str] = (),
                    include_dirs: Sequence[str] = (),
                    extra_compile_args: Sequence[str] = (),
                    extra_link_args: Sequence[str] = (),
                    force: bool = False) -> str:
    """Compile a component and return the path of its extension module.

    :param source: a ``.pyx`` (Cython component) or ``.c`` (C component
        with ``rtapi_app_main``) file; the module name is its stem unless
        ``name`` is given.
    :param out_dir: copy the module there (e.g. a ``HALSDK_PATH`` folder);
        default: leave it in the cache.
    :param extra_sources: more C files of the same component.
    """
    source = os.path.abspath(source)
    if not os.path.isfile(source):
        raise BuildError(f"{source}: no such file")
    stem, ext = os.path.splitext(os.path.basename(source))
    name = name or stem
    if not _NAME.match(name):
        raise BuildError(f"{source}: '{name}' is not a valid module name "
                         "(letters, digits and '_')")
    if ext not in (".pyx", ".c"):
        raise BuildError(f"{source}: expected a .pyx or .c file")
    cython = ext == ".pyx"
    extras = [os.path.abspath(s) for s in extra_sources]
    cflags = _FLAGS + list(extra_compile_args)
    compiler, linker = toolchain()
    key = _digest([source] + extras,
                  [name, *cflags, *extra_link_args, *include_dirs, "\1",
                   *compiler, "\2", *linker],
                  [os.path.dirname(source), *include_dirs])
    target_dir = os.path.join(cache_dir(), key)
    built = os.path.join(target_dir, name + extension_suffix())
    if force or not os.path.isfile(built):
        _compile(source, extras, name, cython, cflags, list(extra_link_args),
                 list(include_dirs), target_dir, compiler, linker)
    if out_dir is None:
        return built
    os.makedirs(out_dir, exist_ok=True)
    dest = os.path.join(out_dir, name + extension_suffix())
    tmp = dest + ".tmp"
    shutil.copy2(built, tmp)
    os.replace(tmp, dest)
    return dest


def _compile(source: str, extras: list[str], name: str, cython: bool,
             cflags: list[str], ldflags: list[str], includes: list[str],
             target_dir: str, compiler: list[str],
             linker: list[str]) -> None:
    """Build the module into ``target_dir`` (made atomically): Cython (in
    this process) for a .pyx, then one compiler process per C file (run
    in parallel) and the linker."""
    os.makedirs(os.path.dirname(target_dir), exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="halsdk-build-") as tmp:
        macros: list[str] = []
        if cython:
            # the module name comes from the file name
            src = os.path.join(tmp, name + ".pyx")
            shutil.copy2(source, src)
            c_file = os.path.join(tmp, name + ".c")
            _cythonize(source, src, c_file, name)
            sources = [c_file] + extras
        else:
            sources = [C_ENTRY, source] + extras
            # every file shares the API pointer that the entry defines
            macros += [f"-DHALSDK_MODULE_NAME={name}",
                       "-DHALSDK_API_EXTERN=1"]
        incs = [f"-I{d}" for d in [INCLUDE_DIR, os.path.dirname(source),
                                   *includes, *_python_includes()]]
        objects = [os.path.join(tmp, f"{i}-{os.path.basename(src)}.o")
                   for i, src in enumerate(sources)]
        results = _run_all([compiler + macros + incs +
                            ["-c", src, "-o", obj] + cflags
                            for src, obj in zip(sources, objects)], tmp)
        failed = [out for rc, out in results if rc != 0]
        if failed:
            _fail(source, "\n".join(failed))
        staging = target_dir + \
            f".{os.getpid()}.{threading.get_ident()}.tmp"
        shutil.rmtree(staging, ignore_errors=True)
        os.makedirs(staging)
        try:
            out = os.path.join(staging, name + extension_suffix())
            (rc, text), = _run_all(
                [linker + objects + ["-o", out]
                 + [f"-L{d}" for d in _library_dirs()] + ldflags], tmp)
            if rc != 0 or not os.path.isfile(out):
                _fail(source, text)
            try:
                os.rename(staging, target_dir)
            except OSError:
                # built meanwhile by another process, or a broken entry
                if not os.path.isfile(os.path.join(target_dir,
                                                   os.path.basename(out))):
                    shutil.rmtree(target_dir, ignore_errors=True)
                    os.rename(staging, target_dir)
        finally:
            shutil.rmtree(staging, ignore_errors=True)


def _fail(source: str, output: str) -> None:
    lines = output.splitlines()
    # the compiler's diagnostics with their source lines and carets
    relevant = [ln for ln in lines if _DIAG.search(ln)
                and not _NOISE.search(ln)] or lines
    raise BuildError(f"{source}: build failed:\n" +
                     "\n".join(relevant[-40:]))


def _run_all(commands: list[list[str]], cwd: str) -> list[tuple[int, str]]:
    """Run the commands, as many at a time as there are CPUs; return each
    one's exit status and output (stdout and stderr merged)."""
    jobs = max(1, os.cpu_count() or 1)
    results: list[tuple[int, str]] = []
    running: list[subprocess.Popen[str]] = []
    try:
        for i, cmd in enumerate(commands):
            try:
                running.append(subprocess.Popen(
                    cmd, cwd=cwd, stdin=subprocess.DEVNULL,
                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                    text=True, errors="replace"))
            except OSError as exc:
                raise BuildError(f"cannot run the C compiler or linker "
                                 f"'{cmd[0]}': {exc}") from None
            if len(running) >= jobs or i == len(commands) - 1:
                for proc in running:
                    out, _ = proc.communicate()
                    results.append((proc.returncode, out))
                running = []
    finally:
        for proc in running:
            proc.kill()
            proc.wait()
    return results


def _cythonize(source: str, pyx: str, c_file: str, name: str) -> None:
    """Translate ``pyx`` to ``c_file`` with Cython, in this process; its
    messages are captured and raised as a BuildError naming ``source``."""
    from Cython.Compiler import Errors, Main

    options = Main.CompilationOptions(
        Main.default_options, include_path=[os.path.dirname(PACKAGE_DIR)],
        output_file=c_file, language_level=3,
        compiler_directives={"boundscheck": False, "wraparound": False})
    messages = io.StringIO()
    errors = 1
    with _CYTHON_LOCK, contextlib.redirect_stderr(messages), \
            contextlib.redirect_stdout(messages):
        try:
            errors = Main.compile_single(pyx, options, full_module_name=name) \
                .num_errors
        except (Errors.PyrexError, OSError) as exc:
            messages.write(f"{exc}\n")
        finally:
            Errors.close_listing_file()
    if errors or not os.path.isfile(c_file):
        # name the caller's file, not the private copy
        # (Cython names it relative to the working folder when it can)
        text = messages.getvalue().replace(pyx, source) \
            .replace(os.path.relpath(pyx), source)
        _fail(source, text or "Cython failed")
