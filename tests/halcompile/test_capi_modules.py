"""Hand-written C modules in the reference's style (issue 18), built and
loaded as a user does: ``halcompile --compile x.c`` (the console script),
then ``loadrt`` from a HAL file run by ``halrun -f``.

The modules and their HAL files are the runtests folders
``tests/lcnc-format/capi-*``; their output is compared with the
reference's (LinuxCNC 2.9) for the same files, kept in
``tests/data/capi/``.  Other cases check what halsdk does where the
reference has nothing to compare with: APIs that are not provided, a
missing symbol, and the halsdk additions."""

from __future__ import annotations

import itertools
import os
import shutil
import subprocess
import sys
import textwrap

import pytest
from helpers.halcompile import child_env

TESTS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOLDERS = os.path.join(TESTS, "lcnc-format")
GOLDEN = os.path.join(TESTS, "data", "capi")
_RUNS = itertools.count()


def bindir() -> str:
    """The folder of the installed commands (beside this Python)."""
    path = os.path.dirname(sys.executable)
    if not os.path.isfile(os.path.join(path, "halcompile")):
        pytest.fail("the halcompile command is not installed")
    return path


def env(**extra: str) -> dict[str, str]:
    return child_env(PATH=bindir() + os.pathsep + os.environ["PATH"],
                     HALSDK_INSTANCE=f"capi-{os.getpid()}-{next(_RUNS)}",
                     **extra)


def run(cmd: list[str], cwd, **extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, cwd=str(cwd), env=env(**extra),
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("name", ["capi-plc", "capi-signals", "capi-fail",
                                  "capi-modparams"])
def test_module_matches_the_reference(tmp_path, name):
    """``bash test.sh`` of the folder prints what the reference printed
    for it, byte for byte."""
    work = tmp_path / name
    shutil.copytree(os.path.join(FOLDERS, name), work)
    proc = run(["bash", "test.sh"], work)
    with open(os.path.join(GOLDEN, name + ".out"), encoding="utf-8") as f:
        golden = f.read()
    assert proc.stdout == golden, proc.stderr
    with open(work / "expected", encoding="utf-8") as f:
        assert f.read() == golden       # the runtests folder agrees
    assert "Segmentation" not in proc.stderr
    assert "Traceback" not in proc.stderr


def test_failed_rtapi_app_main_names_the_module(tmp_path):
    """The load fails with the module's name and message; its exit code,
    which needs the state a successful start makes, is not run, so the
    host lives on (halrun -k runs the rest of the file)."""
    work = tmp_path / "capi-fail"
    shutil.copytree(os.path.join(FOLDERS, "capi-fail"), work)
    assert run(["halcompile", "--compile", "capifail.c"],
               work).returncode == 0
    proc = run(["halrun", "-k", "-f", "keepgoing.hal"], work,
               HALSDK_PATH=str(work))
    assert proc.returncode == 1
    assert proc.returncode != -11
    assert "capifail: CAPIFAIL: ERROR: told to fail" in proc.stderr
    assert "keepgoing.hal:2: insmod for capifail failed" in proc.stderr
    assert "capifail.early" not in proc.stdout      # removed with it
    assert "TRUE\n42\n" in proc.stdout


def write(folder, name: str, text: str) -> None:
    (folder / name).write_text(textwrap.dedent(text).lstrip())


@pytest.mark.parametrize("call, symbol", [
    ("rtapi_task_new(0, 0, 0, 0, 0, 0)", "rtapi_task_new"),
    ("rtapi_sem_give(1)", "rtapi_sem_give"),
    ("rtapi_clock_set_period(0)", "rtapi_clock_set_period"),
    ("hal_port_clear(0)", "hal_port_clear"),
    ("rtapi_init(\"x\")", "rtapi_init"),
])
def test_unprovided_api_fails_to_compile_by_name(tmp_path, call, symbol):
    write(tmp_path, "capinot.c", f"""
        #include "rtapi.h"
        #include "rtapi_app.h"
        #include "hal.h"
        MODULE_LICENSE("GPL");
        int rtapi_app_main(void)
        {{
            int id = hal_init("capinot");
            (void){call};
            hal_ready(id);
            return 0;
        }}
        """)
    proc = run(["halcompile", "--compile", "capinot.c"], tmp_path)
    assert proc.returncode == 1
    assert symbol in proc.stdout + proc.stderr
    assert not list(tmp_path.glob("capinot*.so"))


def test_missing_symbol_fails_to_load_by_name(tmp_path):
    """A module that declares a function nothing defines builds (as C
    allows) and fails at loadrt with the symbol's name; the host goes
    on."""
    write(tmp_path, "capimiss.c", """
        #include "rtapi.h"
        #include "rtapi_app.h"
        #include "hal.h"
        MODULE_LICENSE("GPL");
        extern int rtapi_no_such_call(int x);
        int rtapi_app_main(void)
        {
            int id = hal_init("capimiss");
            if (rtapi_no_such_call(id))
                return -EINVAL;
            hal_ready(id);
            return 0;
        }
        """)
    write(tmp_path, "t.hal", """
        loadrt capimiss
        """)
    assert run(["halcompile", "--compile", "capimiss.c"],
               tmp_path).returncode == 0
    proc = run(["halrun", "-f", "t.hal"], tmp_path,
               HALSDK_PATH=str(tmp_path))
    assert proc.returncode == 1, proc.stderr
    assert "undefined symbol: rtapi_no_such_call" in proc.stderr
    assert "capimiss" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_halsdk_additions_and_userspace_getters(tmp_path):
    """hal_export_functf (LinuxCNC's later API), the getters by name in a
    realtime module, and hal_set_constructor with ``newinst``."""
    write(tmp_path, "capiplus.c", """
        #include "rtapi.h"
        #include "rtapi_app.h"
        #include "hal.h"
        MODULE_LICENSE("GPL");

        typedef struct {
            hal_float_t *in;
            hal_float_t *out;
        } inst_t;

        static int comp_id;
        static hal_bit_t **found;

        static void twice(void *arg, long period)
        {
            inst_t *ip = arg;
            *(ip->out) = 2 * *(ip->in);
        }

        static int make(char *prefix, char *arg)
        {
            inst_t *ip = hal_malloc(sizeof(inst_t));
            int r;
            if (!ip)
                return -ENOMEM;
            if (arg[0] == 'x') {
                rtapi_print_msg(RTAPI_MSG_ERR, "CAPIPLUS: bad arg %s\\n",
                                arg);
                return -EINVAL;
            }
            if ((r = hal_pin_float_newf(HAL_IN, &ip->in, comp_id, "%s.in",
                                        prefix))
                || (r = hal_pin_float_newf(HAL_OUT, &ip->out, comp_id,
                                           "%s.out", prefix)))
                return r;
            return hal_export_functf(twice, ip, 1, 0, comp_id, "%s.twice",
                                     prefix);
        }

        int rtapi_app_main(void)
        {
            hal_type_t type;
            hal_data_u *data;
            bool linked = 1;
            int r;

            comp_id = hal_init("capiplus");
            if (comp_id < 0)
                return comp_id;
            found = hal_malloc(sizeof(hal_bit_t *));
            if ((r = make("capiplus.0", "")))
                return r;
            if ((r = hal_pin_bit_new("capiplus.found", HAL_OUT, found,
                                     comp_id)))
                return r;
            r = hal_get_pin_value_by_name("capiplus.0.in", &type, &data,
                                          &linked);
            **found = r == 0 && type == HAL_FLOAT && !linked
                      && hal_get_param_value_by_name("nope", &type,
                                                     &data) < 0;
            if ((r = hal_set_constructor(comp_id, make)))
                return r;
            hal_ready(comp_id);
            return 0;
        }

        void rtapi_app_exit(void)
        {
            hal_exit(comp_id);
        }
        """)
    write(tmp_path, "t.hal", """
        loadrt capiplus
        newinst capiplus more arg=ok
        loadrt threads name1=t period1=1000000
        addf capiplus.0.twice t
        addf more.twice t
        setp capiplus.0.in 1.5
        setp more.in -2
        start
        loadusr -w sleep 0.05
        stop
        getp capiplus.0.out
        getp more.out
        getp capiplus.found
        newinst capiplus bad arg=x
        """)
    assert run(["halcompile", "--compile", "capiplus.c"],
               tmp_path).returncode == 0
    proc = run(["halrun", "-f", "t.hal"], tmp_path,
               HALSDK_PATH=str(tmp_path))
    assert proc.stdout.splitlines() == ["3", "-4", "TRUE"], proc.stderr
    assert proc.returncode == 1
    assert "CAPIPLUS: bad arg x" in proc.stderr


def test_rtapi_shmem_of_a_module_is_hal_shm_of_python(tmp_path):
    """A block a C module made with ``rtapi_shmem_new(KEY, ...)`` is the
    block a Python program attaches with ``hal.shm(comp, KEY, size)``, as
    in the reference (one key space)."""
    work = tmp_path / "capi-signals"
    shutil.copytree(os.path.join(FOLDERS, "capi-signals"), work)
    assert run(["halcompile", "--compile", "capisig.c"],
               work).returncode == 0
    (work / "reader.py").write_text(textwrap.dedent("""\
        import struct
        import hal
        c = hal.component("reader")
        c.ready()
        block = hal.shm(c, 0x43415049, 8)
        magic, cycles = struct.unpack("<II", bytes(block.getbuffer()[:8]))
        print(f"magic {magic:#x} running {cycles > 0}")
        c.exit()
        """))
    (work / "shm.hal").write_text(
        "loadrt capisig\nloadrt threads name1=t period1=1000000\n"
        "addf capisig.update t\nstart\nloadusr -w sleep 0.05\n"
        f"loadusr -w {sys.executable} reader.py\n")
    proc = run(["halrun", "-f", "shm.hal"], work, HALSDK_PATH=str(work))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == ["magic 0x1234 running True"]
