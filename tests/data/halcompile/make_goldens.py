"""Remake reference_generated.json: what the modules built from the C that
the reference's halcompile generates for our C-bodied corpus files do.

    python tests/data/halcompile/make_goldens.py     # from the checkout

Needs the LinuxCNC reference (../shared/tools/reference, or the
command in $HALSDK_REFERENCE).  Its realtime
modules cannot be loaded by its own halrun from anywhere but its installed
module folder (rtapi_app refuses module names with a '/' and has that
folder built in), so the reference is used as the oracle of the code
generator: ``halcompile --preprocess`` of the reference writes X.c, our
``halcompile --compile`` builds X.c (with -DRTAPI, as LinuxCNC's module
build defines it) and drive.py runs it.  The test runs drive.py on our
builds of the .comp files and compares.

Left out: hcarrays (s64/u64, unknown to the 2.9 reference), hcnames (the
reference's output does not compile: its name macros break the libc
headers the code section includes), hcsingle2 (the reference ignores
option extra_compile_args for realtime modules), the Cython and userspace
comps, and the deliberately bad files.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
COMPS = os.path.join(os.path.dirname(HERE), "comps")
REFERENCE = os.environ.get("HALSDK_REFERENCE") or os.path.join(
    os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(HERE)))),
    "shared", "tools", "reference")

#: NAME or NAME:LOADARGS
CASES = [
    "hal_hcloop", "hcclamp", "hcdata", "hcddt", "hcdelay", "hcdocdecl",
    "hcgetcount:how_many=3", "hcglobal1", "hcglobal2", "hchash",
    "hchomemod", "hcimplicit", "hcimplicit2", "hcinclude", "hcio",
    "hclogic:count=2 personality=0x104,0x603", "hcmodcount:names=p,q",
    "hcmodparams:scale=2 lv=-5 word=xy arr=5,6,7 direct=1", "hcmux2",
    "hcnoconv", "hcperiod", "hcpersona:count=3 personality=3,0x13,0x22",
    "hcrtapp", "hcsetup:count=3 offset=7", "hcsingle",
    "hcslice:count=2 personality=3", "hctpmod", "hctypes", "hcunderscore",
    "hcvars:count=2", "hcwrite",
]


def main() -> int:
    names = sorted({c.partition(":")[0] for c in CASES})
    with tempfile.TemporaryDirectory() as work:
        for n in names:
            shutil.copy2(os.path.join(COMPS, n + ".comp"), work)
        script = "for f in *.comp; do halcompile --preprocess $f || exit 1; done"
        subprocess.run([REFERENCE, "bash", "-c", script], cwd=work,
                       check=True)
        build = os.path.join(work, "build")
        os.mkdir(build)
        subprocess.run([sys.executable, "-m", "halcompile", "--compile",
                        "--extra-compile-args=-DRTAPI",
                        *[os.path.join(work, n + ".c") for n in names]],
                       cwd=build, check=True)
        env = dict(os.environ, HALSDK_PATH=build)
        subprocess.run([sys.executable, os.path.join(HERE, "drive.py"),
                        os.path.join(HERE, "reference_generated.json"),
                        *CASES], cwd=work, env=env, check=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
