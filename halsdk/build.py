"""Building component modules: Cython (.pyx) or C (.c) to an extension.

:func:`build_component` compiles a component source into an extension
module that ``loadrt`` can load, with the system C compiler.  Results are
cached by a hash of everything that goes into the build (sources, halsdk
headers, Python version, flags), so a second build of the same source is
a file copy.

Cache folder: ``$HALSDK_CACHE`` or ``~/.cache/halsdk/build``.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Sequence
from typing import Optional

from halsdk.errors import HalError

PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
INCLUDE_DIR = os.path.join(PACKAGE_DIR, "include")
C_ENTRY = os.path.join(PACKAGE_DIR, "src", "c_module.c")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_DIAG = re.compile(r"^\S[^:]*:\d+:(\d+:)? |^In file included|^\s+\d* *\||"
                   r"[Ee]rror")
_NOISE = re.compile(r"^\s*raise |^(distutils|setuptools)\.|Error: command|"
                    r"^Traceback|^\s+File ")
_FLAGS = ["-O2", "-std=gnu11", "-Wall", "-Wno-unused-function",
          "-Wno-unused-variable"]


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
    return importlib.machinery.EXTENSION_SUFFIXES[0]


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
    h.update(sys.version.encode())
    h.update("\0".join(extra).encode())
    return h.hexdigest()[:24]


_BUILD_SCRIPT = r"""
import json, sys
from setuptools import Distribution, Extension
spec = json.loads(sys.argv[1])
exts = [Extension(spec["name"], sources=spec["sources"],
                  include_dirs=spec["include_dirs"],
                  extra_compile_args=spec["cflags"],
                  extra_link_args=spec["ldflags"],
                  define_macros=[tuple(d) for d in spec["macros"]])]
if spec["cython"]:
    from Cython.Build import cythonize
    exts = cythonize(exts, include_path=spec["pxd_path"], quiet=True,
                     build_dir=spec["tmp"], language_level=3,
                     compiler_directives={"boundscheck": False,
                                          "wraparound": False})
dist = Distribution({"ext_modules": exts, "script_name": "build",
                     "script_args": ["build_ext", "--build-lib", spec["lib"],
                                     "--build-temp", spec["tmp"]]})
dist.parse_command_line()
dist.run_commands()
"""


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
    key = _digest([source] + extras,
                  [name, *cflags, *extra_link_args, *include_dirs],
                  [os.path.dirname(source), *include_dirs])
    target_dir = os.path.join(cache_dir(), key)
    built = os.path.join(target_dir, name + extension_suffix())
    if force or not os.path.isfile(built):
        _compile(source, extras, name, cython, cflags, list(extra_link_args),
                 list(include_dirs), target_dir)
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
             target_dir: str) -> None:
    import json

    os.makedirs(os.path.dirname(target_dir), exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="halsdk-build-") as tmp:
        work = os.path.join(tmp, "src")
        os.makedirs(work)
        macros: list[list[str]] = []
        if cython:
            # the module name comes from the file name
            src = os.path.join(work, name + ".pyx")
            shutil.copy2(source, src)
            sources = [src] + extras
        else:
            sources = [C_ENTRY, source] + extras
            # every file shares the API pointer that the entry defines
            macros += [["HALSDK_MODULE_NAME", name],
                       ["HALSDK_API_EXTERN", "1"]]
        spec = {
            "name": name, "sources": sources, "cython": cython,
            "include_dirs": [INCLUDE_DIR, os.path.dirname(source), *includes,
                             sysconfig.get_paths()["include"]],
            "cflags": cflags, "ldflags": ldflags, "macros": macros,
            "pxd_path": [os.path.dirname(PACKAGE_DIR)],
            "tmp": os.path.join(tmp, "tmp"), "lib": os.path.join(tmp, "lib"),
        }
        proc = subprocess.run(
            [sys.executable, "-c", _BUILD_SCRIPT, json.dumps(spec)],
            capture_output=True, text=True, cwd=tmp)
        out = os.path.join(tmp, "lib", name + extension_suffix())
        if proc.returncode != 0 or not os.path.isfile(out):
            lines = (proc.stdout + proc.stderr).splitlines()
            # the compiler's diagnostics with their source lines and
            # carets; not the build tools' own traceback
            relevant = [ln for ln in lines if _DIAG.search(ln)
                        and not _NOISE.search(ln)] or lines
            raise BuildError(f"{source}: build failed:\n" +
                             "\n".join(relevant[-40:]))
        staging = target_dir + f".{os.getpid()}.tmp"
        os.makedirs(staging, exist_ok=True)
        shutil.copy2(out, os.path.join(staging, os.path.basename(out)))
        try:
            os.rename(staging, target_dir)
        except OSError:
            shutil.rmtree(staging, ignore_errors=True)   # built by another
