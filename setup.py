"""Build of the halsdk core extension and the shipped components.

The core is Cython + C.  Shipped components live in ``components/`` and are
installed as the package ``halsdk.components``; each source becomes the
extension module ``halsdk.components.<name>``:

- ``NAME.comp`` goes through halcompile, as ``halcompile --compile`` would
  do it: a C code section becomes generated C (built with the module entry
  ``halsdk/core/src/c_module.c``), a Cython one (``option cython``) a generated
  ``.pyx``.  The generated files go to ``build/halcompile/``.
- ``NAME.pyx`` is a component written in Cython against ``halsdk/hal.pxd``.
- ``motion/MODULES`` lists the modules of the motion controller (motmod,
  homemod, tpmod, the kinematics) and their C/C++ sources in
  ``components/motion/``; C++ sources link ruckig (a build requirement)
  statically.
- ``drivers/<name>/MODULES`` lists realtime C drivers the same way
  (installed as ``halsdk.drivers.<module>``).
"""

import glob
import os
import sys

from Cython.Build import cythonize
from setuptools import Extension, setup

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)        # halcompile, from this source tree

from halcompile.parser import CompError  # noqa: E402
from halcompile.sources import generate_source  # noqa: E402

GENERATED = os.path.join("build", "halcompile")
FLAGS = ["-O2", "-std=gnu11", "-Wall", "-Wno-unused-function"]

core = Extension(
    "halsdk.core._core",
    sources=[
        "halsdk/core/_core.pyx",
        "halsdk/core/src/hal_core.c",
        "halsdk/core/src/hal_check.c",
        "halsdk/core/src/hal_thread.c",
        "halsdk/core/src/hal_api.c",
        "halsdk/core/src/hal_stream.c",
        "halsdk/core/src/hal_shmem.c",
        "halsdk/core/src/hal_symbol.c",
        "halsdk/core/src/hal_snapshot.c",
        "halsdk/core/src/hal_liveness.c",
    ],
    include_dirs=["halsdk/include", "halsdk/core/src"],
    extra_compile_args=FLAGS,
    libraries=["rt", "pthread"],
)


def comp_extension(path, package="halsdk.components"):
    """The extension module of one shipped ``.comp`` file, from the source
    that halcompile generates for it (the API the halcompile command
    builds with too)."""
    try:
        src = generate_source(path, GENERATED)
    except CompError as exc:
        sys.exit(f"error: {exc}")
    if src.userspace:
        sys.exit(f"error: {path}: shipped components are realtime ones")
    flags = FLAGS + ["-fvisibility=hidden"] + src.compile_args
    if src.language == "cython":
        return Extension(f"{package}.{src.comp.name}", sources=[src.path],
                         include_dirs=["halsdk/include", "components"],
                         extra_compile_args=flags,
                         extra_link_args=src.link_args)
    return Extension(
        f"{package}.{src.comp.name}",
        sources=["halsdk/core/src/c_module.c", src.path],
        include_dirs=["halsdk/include", "components"],
        define_macros=[("HALSDK_MODULE_NAME", src.comp.name),
                       ("HALSDK_API_EXTERN", "1"), ("RTAPI", None)],
        extra_compile_args=flags, extra_link_args=src.link_args)


components = [comp_extension(p)
              for p in sorted(glob.glob("components/*.comp"))]
# drivers: the same contract, installed as halsdk.drivers.<name>
components += [comp_extension(p, "halsdk.drivers")
               for p in sorted(glob.glob("drivers/*.comp"))]
components += [
    Extension(
        "halsdk.components." + os.path.splitext(os.path.basename(src))[0],
        sources=[src],
        include_dirs=["halsdk/include"],
        extra_compile_args=FLAGS,
    )
    for src in sorted(glob.glob("components/*.pyx"))
]


def ruckig_dirs():
    """Include folder and static library of the ruckig wheel."""
    try:
        import ruckig
    except ImportError:
        sys.exit("error: building the motion modules needs ruckig "
                 "(pip install ruckig)")
    root = os.path.dirname(ruckig.__file__)
    lib = os.path.join(root, "lib64", "libruckig.a")
    if not os.path.exists(lib):
        lib = os.path.join(root, "lib", "libruckig.a")
    return os.path.join(root, "include"), lib


MOTION = os.path.join("components", "motion")


def motion_extensions(folder=MOTION, package="halsdk.components"):
    """The modules listed in FOLDER/MODULES (components/motion/MODULES,
    and drivers/<name>/MODULES for the realtime C drivers)."""
    exts = []
    with open(os.path.join(folder, "MODULES"), encoding="utf-8") as f:
        lines = f.read().splitlines()
    for number, line in enumerate(lines, 1):
        line = line.split("#")[0].strip()
        if not line:
            continue
        name, sep, files = line.partition(":")
        if not sep or not files.split():
            sys.exit(f"error: {folder}/MODULES:{number}: expected "
                     "'module: source...'")
        sources = [os.path.join(folder, f) for f in files.split()]
        cxx = any(f.endswith(".cpp") for f in sources)
        extra = {}
        if cxx:
            include, lib = ruckig_dirs()
            # ruckig's headers need no exceptions; a realtime call must
            # not throw
            extra = {"extra_objects": [lib], "language": "c++"}
        exts.append(Extension(
            f"{package}.{name.strip()}",
            sources=["halsdk/core/src/c_module.c"] + sources,
            include_dirs=["halsdk/include", folder]
            + ([include] if cxx else []),
            define_macros=[("HALSDK_MODULE_NAME", name.strip()),
                           ("HALSDK_API_EXTERN", "1"), ("RTAPI", None)],
            extra_compile_args=["-O2", "-Wall", "-Wno-unused-function",
                                "-fvisibility=hidden"]
            + (["-fno-exceptions"] if cxx else []),
            **extra))
    return exts


components += motion_extensions()
# realtime drivers in C: drivers/<name>/MODULES, installed as
# halsdk.drivers.<module>
for modules in sorted(glob.glob(os.path.join("drivers", "*", "MODULES"))):
    components += motion_extensions(os.path.dirname(modules),
                                    "halsdk.drivers")
components.append(Extension(
    "halsdk.motion._channel", sources=["halsdk/motion/_channel.pyx"],
    include_dirs=["components/motion", "halsdk/include"],
    extra_compile_args=FLAGS))
components.append(Extension(
    "halsdk.channels._shm", sources=["halsdk/channels/_shm.pyx"],
    extra_compile_args=FLAGS))
# the hot path of the G-code reader (halsdk/gcode/_fast.pyx)
components.append(Extension(
    "halsdk.gcode._fast", sources=["halsdk/gcode/_fast.pyx"],
    # no fused multiply-add: the same rounding as Python's arithmetic
    extra_compile_args=FLAGS + ["-ffp-contract=off"]))
# the compiled lexer and expression evaluator (halsdk/gcode/_lex.pyx,
# _eval.pyx); the Python lexer and trees stay the reference of behaviour
components.append(Extension(
    "halsdk.gcode._lex", sources=["halsdk/gcode/_lex.pyx"],
    extra_compile_args=FLAGS))
components.append(Extension(
    "halsdk.gcode._eval", sources=["halsdk/gcode/_eval.pyx"],
    extra_compile_args=FLAGS + ["-ffp-contract=off"]))
# the control flow of a program (halsdk/gcode/_flow.pyx: Program._run)
components.append(Extension(
    "halsdk.gcode._flow", sources=["halsdk/gcode/_flow.pyx"],
    extra_compile_args=FLAGS))
names = [e.name for e in components]
if len(set(names)) != len(names):
    sys.exit("error: two sources in components/ make the same module")

def python_drivers() -> list:
    """The userspace drivers written in Python: drivers/<name>/ packages."""
    return ["halsdk.drivers." + name for name in sorted(os.listdir("drivers"))
            if os.path.isfile(os.path.join("drivers", name, "__init__.py"))]


setup(
    packages=["halsdk", "halsdk.core", "halsdk.compat", "halsdk.demo", "halsdk.halcmd",
              "halsdk.components", "halsdk.gcode", "halsdk.machine",
              "halsdk.motion", "halsdk.tools", "halsdk.channels", "halcompile",
              "halsdk.driverkit", "halsdk.drivers", "halsdk.web",
              *python_drivers()],
    package_dir={"halsdk.components": "components",
                 "halsdk.drivers": "drivers"},
    ext_modules=cythonize([core] + components, language_level=3, quiet=True,
                          include_path=["."]),
)
