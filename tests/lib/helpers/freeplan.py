"""Building the C planners of components/motion (freeplan.c,
freeplan_jerk.cpp with ruckig, and their neighbours) into a plain shared
library for ctypes, and the ctypes mirror of ``freeplan_t``."""

from __future__ import annotations

import ctypes
import os
import subprocess

from helpers import repo_path

SRC = str(repo_path("components", "motion"))


def ruckig_paths():
    """Headers and static library of the ruckig wheel (a test
    requirement: no skip when it is missing)."""
    import ruckig
    base = os.path.dirname(ruckig.__file__)
    inc = os.path.join(base, "include")
    lib = os.path.join(base, "lib64", "libruckig.a")
    assert os.path.isfile(os.path.join(inc, "ruckig", "ruckig.hpp")), inc
    assert os.path.isfile(lib), lib
    return inc, lib


def build_library(outdir, c_sources, extra_c=""):
    """Compile C sources (and freeplan_jerk.cpp) of components/motion
    into a shared library in outdir; return its path."""
    inc, lib = ruckig_paths()
    objs = []
    sources = [os.path.join(SRC, s) for s in c_sources]
    if extra_c:
        path = os.path.join(outdir, "runner.c")
        with open(path, "w") as f:
            f.write(extra_c)
        sources.append(path)
    warn = ["-Wall", "-Wextra", "-Werror", "-Wno-unused-parameter"]
    for i, src in enumerate(sources):
        obj = os.path.join(outdir, f"o{i}.o")
        subprocess.run(["gcc", "-std=gnu11", "-O2", "-fPIC", *warn,
                        "-I" + SRC, "-c", src, "-o", obj], check=True)
        objs.append(obj)
    obj = os.path.join(outdir, "jerk.o")
    subprocess.run(["g++", "-std=c++17", "-O2", "-fPIC", "-fno-exceptions",
                    *warn, "-I" + SRC, "-I" + inc, "-c",
                    os.path.join(SRC, "freeplan_jerk.cpp"), "-o", obj],
                   check=True)
    objs.append(obj)
    so = os.path.join(outdir, "libmotplan.so")
    subprocess.run(["g++", "-shared", "-o", so, *objs, lib, "-lm"],
                   check=True)
    return so


class Freeplan(ctypes.Structure):
    _fields_ = [("target", ctypes.c_double),
                ("max_vel", ctypes.c_double),
                ("max_acc", ctypes.c_double),
                ("max_jerk", ctypes.c_double),
                ("enable", ctypes.c_int),
                ("profile", ctypes.c_int),
                ("pos", ctypes.c_double),
                ("vel", ctypes.c_double),
                ("acc", ctypes.c_double),
                ("active", ctypes.c_int),
                ("impl", ctypes.c_void_p)]


DPTR = ctypes.POINTER(ctypes.c_double)
