"""halcompile and the C API as files written for LinuxCNC 2.9 use them
(issue 18): option spellings, MODULE_* declarations in the code section,
``hal_data_u`` and ``rtapi_math64.h``.  Each case is run the way a user
runs it: ``halcompile --compile x.comp``, then ``loadrt`` from a HAL file
through ``halrun -f``."""

from __future__ import annotations

import itertools
import os
import subprocess
import sys
import textwrap

import pytest
from helpers.halcompile import child_env

_RUNS = itertools.count()


def comp(folder, name: str, body: str) -> None:
    (folder / f"{name}.comp").write_text(textwrap.dedent(body).lstrip())


def command(name: str) -> str:
    """The installed command NAME (beside this Python)."""
    path = os.path.join(os.path.dirname(sys.executable), name)
    if not os.path.isfile(path):
        pytest.fail(f"the {name} command is not installed")
    return path


def build(folder, *names: str) -> subprocess.CompletedProcess:
    """``halcompile --compile NAME.comp ...`` in ``folder``."""
    return subprocess.run([command("halcompile"), "--compile",
                           *[f"{n}.comp" for n in names]], cwd=str(folder),
                          env=child_env(), capture_output=True, text=True,
                          timeout=300)


def build_and_run(folder, names: list[str], hal: str) -> list[str]:
    """Compile ``names`` with the command, run ``hal`` with ``halrun -f``
    (the modules found through HALSDK_PATH); halrun's output lines."""
    proc = build(folder, *names)
    assert proc.returncode == 0, proc.stderr
    (folder / "run.hal").write_text(textwrap.dedent(hal).lstrip())
    proc = subprocess.run(
        [command("halrun"), "-f", "run.hal"], cwd=str(folder),
        env=child_env(HALSDK_PATH=str(folder),
                      HALSDK_INSTANCE=f"hc18-{os.getpid()}-{next(_RUNS)}"),
        capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc.stdout.splitlines()


def run_once(names: str, setp: str, getp: str) -> str:
    """A HAL file that runs the functions ``names`` once in a thread."""
    addf = "".join(f"addf {n} t\n" for n in names.split())
    return (f"loadrt threads name1=t period1=1000000\n{addf}{setp}"
            "start\nloadusr -w sleep 0.1\nstop\n" + getp)


# -------------------------------------------------- option personality

def test_option_personality_old_spellings(tmp_path):
    """``option personality yes;`` and the bare ``option personality;``
    compile (they change nothing, as in the reference): the personality
    comes from the conditional pins."""
    comp(tmp_path, "hcpers1", """
        component hcpers1 "option personality yes";
        pin in float in;
        pin out float out;
        option personality yes;
        function _;
        license "GPL";
        ;;
        FUNCTION(_) { out = 3 * in; }
        """)
    comp(tmp_path, "hcpers2", """
        component hcpers2 "bare option personality";
        pin in float in-#[4 : personality];
        pin out float out;
        option personality;
        function _;
        license "GPL";
        ;;
        FUNCTION(_) {
            int i; double s = 0;
            for (i = 0; i < personality; i++) s += in(i);
            out = s;
        }
        """)
    lines = build_and_run(tmp_path, ["hcpers1", "hcpers2"], """
        loadrt hcpers1
        loadrt hcpers2 personality=2
        loadrt threads name1=t period1=1000000
        addf hcpers1.0 t
        addf hcpers2.0 t
        setp hcpers1.0.in 1.5
        setp hcpers2.0.in-0 2
        setp hcpers2.0.in-1 5
        start
        loadusr -w sleep 0.1
        stop
        getp hcpers1.0.out
        getp hcpers2.0.out
        show pin hcpers2.0.in
        """)
    assert lines[:2] == ["4.5", "7"]
    shown = " ".join(lines[2:])
    assert "hcpers2.0.in-1" in shown and "hcpers2.0.in-2" not in shown


# ------------------------------------------------------ boolean options

SPELLINGS = [("", True), ("yes", True), ("no", False), ("1", True),
             ("0", False), ("true", True), ("false", False),
             ("TRUE", True), ("FALSE", False), ("0x1", True),
             ("-1", True), ("1.0", True), ("0.0", False)]


def test_boolean_options_take_the_reference_spellings(tmp_path):
    """``option singleton VALUE;`` with every spelling the reference
    reads: a singleton's pins have no instance number."""
    names = []
    for i, (spelling, _) in enumerate(SPELLINGS):
        name = f"hcbool{i}"
        names.append(name)
        comp(tmp_path, name, f"""
            component {name};
            pin out s32 out;
            option singleton {spelling};
            function _;
            license "GPL";
            ;;
            FUNCTION(_) {{ out = {i}; }}
            """)
    hal = "".join(f"loadrt {n}\n" for n in names) + "show pin hcbool\n"
    shown = "\n".join(build_and_run(tmp_path, names, hal))
    for name, (spelling, single) in zip(names, SPELLINGS):
        pin = f"{name}.out" if single else f"{name}.0.out"
        assert pin in shown.split(), (spelling, shown)


def test_numeric_extra_setup_option(tmp_path):
    """``option extra_setup 1;`` runs EXTRA_SETUP (it is on)."""
    comp(tmp_path, "hcsetup1", """
        component hcsetup1;
        pin out s32 out;
        variable int base;
        option extra_setup 1;
        option extra_cleanup 0;
        function _;
        license "GPL";
        ;;
        EXTRA_SETUP() { base = 40 + extra_arg; return 0; }
        FUNCTION(_) { out = base + 2; }
        """)
    lines = build_and_run(tmp_path, ["hcsetup1"], """
        loadrt hcsetup1
        """ + run_once("hcsetup1.0", "", "getp hcsetup1.0.out\n"))
    assert lines == ["42"]


@pytest.mark.parametrize("value", ["on", "maybe", '"no"'])
def test_boolean_options_refuse_other_words(tmp_path, value):
    """The reference reads any other word (even ``off`` or ``"no"``) as
    yes; halsdk refuses it (docs/compat.md)."""
    comp(tmp_path, "hcboolbad", f"""
        component hcboolbad;
        pin out s32 out;
        option singleton {value};
        function _;
        license "GPL";
        ;;
        FUNCTION(_) {{ out = 1; }}
        """)
    proc = build(tmp_path, "hcboolbad")
    assert proc.returncode == 1
    assert "hcboolbad.comp:3:18: option singleton takes yes or no" \
        in proc.stderr


# ------------------------------------------ MODULE_* in the code section

def test_module_info_in_the_code_section(tmp_path):
    """MODULE_AUTHOR, MODULE_DESCRIPTION (and MODULE_LICENSE) written in
    the code section of a comp that also declares author, description
    and license."""
    comp(tmp_path, "hcmodinfo", """
        component hcmodinfo "a described component";
        author "A. Author";
        description "the long description";
        pin in s32 in;
        pin out s32 out;
        function _;
        license "GPL";
        ;;
        MODULE_AUTHOR("Someone Else");
        MODULE_DESCRIPTION("described twice");
        MODULE_LICENSE("GPL v2");
        MODULE_INFO(linuxcnc, "component:hcmodinfo");
        FUNCTION(_) { out = in + 1; }
        """)
    lines = build_and_run(tmp_path, ["hcmodinfo"], "loadrt hcmodinfo\n"
                          + run_once("hcmodinfo.0", "setp hcmodinfo.0.in 41\n",
                                     "getp hcmodinfo.0.out\n"))
    assert lines == ["42"]


# ---------------------------------------------------------- hal_data_u

def test_hal_data_u_members_for_generic_code(tmp_path):
    """Pins made with hal_pin_new() of any type, read and written through
    ``hal_data_u`` pointers, as generic components (a type-converting
    mux) do: members b, s, u, f and the 64-bit ls, lu."""
    comp(tmp_path, "hcunion", """
        component hcunion "converts through hal_data_u";
        pin out bit ok;
        variable hal_data_u *g[6];
        option extra_setup yes;
        function _;
        license "GPL";
        ;;
        static const hal_type_t types[6] = {
            HAL_FLOAT, HAL_S32, HAL_U32, HAL_BIT, HAL_S64, HAL_U64};
        static const char *pnames[6] = {"in", "s", "u", "b", "ls", "lu"};
        EXTRA_SETUP() {
            int i, r;
            char buf[HAL_NAME_LEN + 1];
            for (i = 0; i < 6; i++) {
                rtapi_snprintf(buf, sizeof(buf), "%s.%s", prefix, pnames[i]);
                r = hal_pin_new(buf, types[i], i ? HAL_OUT : HAL_IN,
                                (void **)&g[i], comp_id);
                if (r) return r;
            }
            return 0;
        }
        FUNCTION(_) {
            double x = g[0]->f;
            double m = x < 0 ? -x : x;
            g[1]->s = (rtapi_s32)x;
            g[2]->u = (rtapi_u32)m;
            g[3]->b = x != 0;
            g[4]->ls = (rtapi_s64)x * 1000000000LL;
            g[5]->lu = (rtapi_u64)m * 1000000000ULL;
            ok = sizeof(hal_data_u) == 8;
        }
        """)
    lines = build_and_run(tmp_path, ["hcunion"], "loadrt hcunion\n" + run_once(
        "hcunion.0", "setp hcunion.0.in -7.75\n",
        "".join(f"getp hcunion.0.{p}\n" for p in ("s", "u", "b", "ls",
                                                  "lu", "ok"))))
    assert lines == ["-7", "7", "TRUE", "-7000000000", "7000000000", "TRUE"]


# ------------------------------------------------------- rtapi_math64.h

def test_rtapi_math64_divisions(tmp_path):
    """rtapi_div_u64, rtapi_div_u64_rem, rtapi_div_s64 and
    rtapi_div_s64_rem divide a 64-bit dividend by a 32-bit divisor (C's
    truncation: the remainder has the dividend's sign)."""
    comp(tmp_path, "hcdiv64", """
        component hcdiv64 "64-bit divisions";
        pin in u32 hi;
        pin in u32 lo;
        pin in u32 d;
        pin out u64 q;
        pin out u32 r;
        pin out u64 q2;
        pin out s64 sq;
        pin out s32 sr;
        pin out s64 sq2;
        function _;
        license "GPL";
        ;;
        #include "rtapi_math64.h"
        FUNCTION(_) {
            rtapi_u64 n = ((rtapi_u64)hi << 32) | lo;
            rtapi_u32 rem;
            rtapi_s32 srem;
            q = rtapi_div_u64_rem(n, d, &rem);
            r = rem;
            q2 = rtapi_div_u64(n, d);
            sq = rtapi_div_s64_rem(-(rtapi_s64)n, (rtapi_s32)d, &srem);
            sr = srem;
            sq2 = rtapi_div_s64(-(rtapi_s64)n, -(rtapi_s32)d);
        }
        """)
    hi, lo, d = 3, 5, 7
    n = (hi << 32) | lo
    lines = build_and_run(tmp_path, ["hcdiv64"], "loadrt hcdiv64\n" + run_once(
        "hcdiv64.0",
        f"setp hcdiv64.0.hi {hi}\nsetp hcdiv64.0.lo {lo}\n"
        f"setp hcdiv64.0.d {d}\n",
        "".join(f"getp hcdiv64.0.{p}\n" for p in ("q", "r", "q2", "sq", "sr",
                                                  "sq2"))))
    assert lines == [str(n // d), str(n % d), str(n // d), str(-(n // d)),
                     str(-(n % d)), str(n // d)]
