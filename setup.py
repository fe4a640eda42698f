"""Build of the halsdk core extension (Cython + C)."""

from Cython.Build import cythonize
from setuptools import Extension, setup

core = Extension(
    "halsdk._core",
    sources=[
        "halsdk/_core.pyx",
        "halsdk/src/hal_core.c",
        "halsdk/src/hal_thread.c",
        "halsdk/src/hal_api.c",
    ],
    include_dirs=["halsdk/include", "halsdk/src"],
    extra_compile_args=["-O2", "-std=gnu11", "-Wall", "-Wno-unused-function"],
    libraries=["rt", "pthread"],
)

setup(ext_modules=cythonize([core], language_level=3, quiet=True))
