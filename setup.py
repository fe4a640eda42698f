"""Build of the halsdk core extension and the shipped components.

The core is Cython + C.  Shipped components live in ``components/`` (Python
modules and Cython ``.pyx`` sources) and are installed as the package
``halsdk.components``; each ``.pyx`` becomes the extension module
``halsdk.components.<name>``.
"""

import glob
import os

from Cython.Build import cythonize
from setuptools import Extension, setup

core = Extension(
    "halsdk._core",
    sources=[
        "halsdk/_core.pyx",
        "halsdk/src/hal_core.c",
        "halsdk/src/hal_thread.c",
        "halsdk/src/hal_api.c",
        "halsdk/src/hal_stream.c",
    ],
    include_dirs=["halsdk/include", "halsdk/src"],
    extra_compile_args=["-O2", "-std=gnu11", "-Wall", "-Wno-unused-function"],
    libraries=["rt", "pthread"],
)

components = [
    Extension(
        "halsdk.components." + os.path.splitext(os.path.basename(src))[0],
        sources=[src],
        include_dirs=["halsdk/include"],
        extra_compile_args=["-O2", "-std=gnu11", "-Wno-unused-function"],
    )
    for src in sorted(glob.glob("components/*.pyx"))
]

setup(
    packages=["halsdk", "halsdk.compat", "halsdk.demo", "halsdk.halcmd",
              "halsdk.components", "halsdk.tools", "halcompile"],
    package_dir={"halsdk.components": "components"},
    ext_modules=cythonize([core] + components, language_level=3, quiet=True,
                          include_path=["."]),
)
