"""halcompile corpus, second part: one small ``.comp`` per feature of the
``.comp`` language (types, defaults, names, arrays, personality, options,
module parameters, variables, code-section habits of real files), each
compiled by the command, loaded into the test's HAL, stepped and checked
with exact numbers.

The C-bodied files here also compile with the reference's halcompile
(except hc64 and hcrstring, see their descriptions).  The reference's
realtime modules cannot be loaded from a test folder (its rtapi_app only
loads from its installed module folder), so the reference is the oracle of
the code generator: tests/data/halcompile/reference_generated.json holds
what modules built from the reference's generated C do (made by
make_goldens.py there), and our builds of the same files must do the same.
The userspace comps are compared with the reference's own halrun."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time

import pytest
from helpers import data_path
from helpers.components import names, own_params, own_pins
from helpers.halcompile import (
    child_env,
    comp_files,
    compiled_on_path,
    halcompile,
    halrun_file,
)

from halcompile import parse, parse_file
from halsdk.build import extension_suffix
from halsdk.errors import InvalidError

COMPS = str(data_path("comps"))
DATA = str(data_path("halcompile"))
PERIOD = 1_000_000
FPERIOD = PERIOD * 1e-9

#: realtime comps with C code sections
C_COMPS = ["hctypes", "hc64", "hcglobal1", "hcglobal2", "hcpersona",
           "hcmodcount", "hcmodparams", "hchash", "hcunderscore",
           "hcimplicit", "hcimplicit2", "hcperiod", "hcio", "hcvars",
           "hcinclude", "hcdocdecl", "hcrstring", "hcwrite", "hcgetcount",
           "hcnoconv", "hchomemod", "hctpmod"]
#: comps with Cython code sections
CY_COMPS = ["hccytypes"]
#: userspace comps
USER_COMPS = ["hcuser3", "hcuserlink"]
ALL = C_COMPS + CY_COMPS + USER_COMPS


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory):
    """Every comp of this corpus compiled by ``halcompile --compile`` into
    one folder, which is put first on HALSDK_PATH."""
    with compiled_on_path(tmp_path_factory.mktemp("hc-corpus"),
                          *comp_files(*ALL)) as folder:
        yield folder


def run_functs(hal, *functs: str) -> None:
    hal.newthread("servo", PERIOD)
    for f in functs:
        hal.addf(f, "servo")


def get(hal, *names_: str) -> list:
    return [hal.getp(n) for n in names_]


# ------------------------------------------------------------ the files

def test_every_comp_is_built(corpus):
    for name in C_COMPS + CY_COMPS:
        assert os.path.isfile(os.path.join(corpus, name + extension_suffix()))
    for name in USER_COMPS:
        assert os.access(os.path.join(corpus, name), os.X_OK)


def test_corpus_files_parse_with_their_names():
    for name in ALL:
        comp = parse_file(os.path.join(COMPS, name + ".comp"))
        assert comp.name == name
        assert comp.license


# ------------------------------------------------------------ types

def test_types_and_default_spellings(hal, corpus):
    hal.loadrt("hctypes")
    assert hal.pin("hctypes.0.sg-in").type == 3          # signed is s32
    assert hal.pin("hctypes.0.us-in").type == 4          # unsigned is u32
    assert get(hal, "hctypes.0.b-in", "hctypes.0.f-in", "hctypes.0.s-in",
               "hctypes.0.u-in", "hctypes.0.sg-in", "hctypes.0.us-in",
               "hctypes.0.big", "hctypes.0.flag") == [
        True, 0.5, -16, 16, 7, 1000, 1e20, False]
    run_functs(hal, "hctypes.0")
    hal.step()
    assert get(hal, "hctypes.0.b-out", "hctypes.0.f-out", "hctypes.0.s-out",
               "hctypes.0.u-out", "hctypes.0.sg-out", "hctypes.0.us-out",
               "hctypes.0.calls") == [False, 2.0, -17, 17, -7, 500, 1]
    hal.set({"hctypes.0.b-in": False, "hctypes.0.flag": True,
             "hctypes.0.f-in": 1.25, "hctypes.0.big": 0,
             "hctypes.0.u-in": 0xFFFFFFFF, "hctypes.0.sg-in": -2})
    hal.step(2)
    assert get(hal, "hctypes.0.b-out", "hctypes.0.f-out", "hctypes.0.u-out",
               "hctypes.0.sg-out", "hctypes.0.calls") == [
        False, 2.5, 0, 2, 3]


def test_64_bit_types(hal, corpus):
    hal.loadrt("hc64")
    assert hal.pin("hc64.0.l-in").type == 6
    assert hal.param("hc64.0.up").type == 7
    assert get(hal, "hc64.0.l-in", "hc64.0.ul-in") == [-5000000000,
                                                       0xFFFFFFFFF]
    run_functs(hal, "hc64.0")
    hal.step()
    assert get(hal, "hc64.0.l-out", "hc64.0.ul-out", "hc64.0.up") == [
        -10000000003, 0x1000000000, 0x2000000000]


# ------------------------------------------------------------ names

def test_hash_runs_in_names(hal, corpus):
    hal.loadrt("hchash")
    assert own_pins(hal, "hchash.*") == [
        "hchash.0.out-000", "hchash.0.out-001", "hchash.0.out-002",
        "hchash.0.stage.00.value", "hchash.0.stage.01.value"]
    assert own_params(hal, "hchash.*") == ["hchash.0.k-0", "hchash.0.k-1"]
    run_functs(hal, "hchash.0")
    hal.step()
    assert get(hal, "hchash.0.out-000", "hchash.0.out-001",
               "hchash.0.out-002", "hchash.0.stage.00.value",
               "hchash.0.stage.01.value") == [5, 15, 25, 5, 10]
    hal.set({"hchash.0.k-1": 3})
    hal.step()
    assert get(hal, "hchash.0.stage.00.value",
               "hchash.0.stage.01.value") == [3, 6]


def test_trailing_underscores_dashes_and_dots(hal, corpus):
    hal.loadrt("hcunderscore")
    assert own_pins(hal, "hcunderscore.*") == [
        "hcunderscore.0.is-low", "hcunderscore.0.long-name-here",
        "hcunderscore.0.max", "hcunderscore.0.min",
        "hcunderscore.0.out.clamped", "hcunderscore.0.value"]
    assert own_params(hal, "hcunderscore.*") == ["hcunderscore.0.x-y.z"]
    assert names(hal.functions("hcunderscore.*")) == [
        "hcunderscore.0.do-it"]
    run_functs(hal, "hcunderscore.0.do-it")
    trace = hal.run(3, inputs={"hcunderscore.0.value": [5.0, -3.0, 0.25]},
                    record=["hcunderscore.0.out.clamped",
                            "hcunderscore.0.is-low",
                            "hcunderscore.0.long-name-here"])
    assert list(trace["hcunderscore.0.out.clamped"]) == [1.0, -1.0, 0.25]
    assert list(trace["hcunderscore.0.is-low"]) == [False, True, False]
    assert list(trace["hcunderscore.0.long-name-here"]) == [6, 6, 6]


def test_functions_named_read_and_write_with_option_data(hal, corpus):
    hal.loadrt("hcwrite")
    assert names(hal.functions("hcwrite.*")) == ["hcwrite.0.read",
                                                 "hcwrite.0.write"]
    assert own_pins(hal, "hcwrite.*") == ["hcwrite.0.in", "hcwrite.0.out",
                                          "hcwrite.0.stage"]
    run_functs(hal, "hcwrite.0.read", "hcwrite.0.write")
    trace = hal.run(5, inputs={"hcwrite.0.in": [1, 2, 3, 4, 10]},
                    record=["hcwrite.0.out", "hcwrite.0.stage"])
    # three slots in a ring: the sum of the last three inputs
    assert list(trace["hcwrite.0.out"]) == [1, 3, 6, 9, 17]
    assert list(trace["hcwrite.0.stage"]) == [2] * 5


def test_same_named_globals_stay_private(hal, corpus):
    """Two modules with the same global variable, struct, #define and
    exported-looking helper: each keeps its own."""
    hal.loadrt("hcglobal1")
    hal.loadrt("hcglobal2")
    run_functs(hal, "hcglobal1.0", "hcglobal2.0")
    hal.step()
    one = get(hal, "hcglobal1.0.shared", "hcglobal1.0.out")
    two = get(hal, "hcglobal2.0.shared", "hcglobal2.0.out")
    hal.step(2)
    assert get(hal, "hcglobal1.0.shared", "hcglobal1.0.out") == [
        one[0] + 6, one[1] + 2]
    assert get(hal, "hcglobal2.0.shared", "hcglobal2.0.out") == [
        two[0] + 10, two[1] + 20]
    hal.unloadrt("hcglobal2")
    hal.step()
    assert get(hal, "hcglobal1.0.shared", "hcglobal1.0.out") == [
        one[0] + 9, one[1] + 3]


def test_reload_starts_from_fresh_globals(hal, corpus):
    """unloadrt + loadrt gives the module's C globals their first values
    again, as in LinuxCNC."""
    seen = []
    for _ in range(2):
        hal.loadrt("hcglobal1")
        hal.newthread("servo", PERIOD)
        hal.addf("hcglobal1.0", "servo")
        hal.step(2)
        seen.append(get(hal, "hcglobal1.0.shared", "hcglobal1.0.out"))
        hal.unloadrt("hcglobal1")
        hal.delthread("servo")
    assert seen == [[6, 102], [6, 102]]


# ------------------------------------------------------------ arrays, personality

def test_personality_conditional_pins_and_sized_arrays(hal, corpus):
    hal.loadrt("hcpersona", "count=3", "personality=3,0x13,0x22")
    assert own_pins(hal, "hcpersona.0.*") == [
        "hcpersona.0.in-0", "hcpersona.0.in-1", "hcpersona.0.in-2",
        "hcpersona.0.pers", "hcpersona.0.sum"]
    assert own_pins(hal, "hcpersona.1.*") == [
        "hcpersona.1.in-0", "hcpersona.1.in-1", "hcpersona.1.in-2",
        "hcpersona.1.pers", "hcpersona.1.scaled", "hcpersona.1.sum"]
    assert own_pins(hal, "hcpersona.2.*") == [
        "hcpersona.2.in-0", "hcpersona.2.in-1", "hcpersona.2.neg",
        "hcpersona.2.pers", "hcpersona.2.sum"]
    assert own_params(hal, "hcpersona.*") == ["hcpersona.1.gain"]
    run_functs(hal, "hcpersona.0", "hcpersona.1", "hcpersona.2")
    hal.set({"hcpersona.0.in-0": 1.5, "hcpersona.0.in-2": 2.0,
             "hcpersona.1.in-1": 4.0, "hcpersona.1.gain": 0.5,
             "hcpersona.2.in-0": -1.0, "hcpersona.2.in-1": 0.25})
    hal.step()
    assert get(hal, "hcpersona.0.sum", "hcpersona.0.pers") == [3.5, 3]
    assert get(hal, "hcpersona.1.sum", "hcpersona.1.scaled",
               "hcpersona.1.pers") == [4.0, 2.0, 0x13]
    assert get(hal, "hcpersona.2.sum", "hcpersona.2.neg",
               "hcpersona.2.pers") == [-0.75, True, 0x22]


def test_personality_with_names(hal, corpus):
    hal.loadrt("hcpersona", "names=one,two", "personality=1")
    assert own_pins(hal, "one.*") == ["one.in-0", "one.pers", "one.sum"]
    # an instance without a personality gets 0: no inputs at all
    assert own_pins(hal, "two.*") == ["two.pers", "two.sum"]


# ------------------------------------------------------------ count and modparams

def test_default_count_and_module_level_count(hal, corpus):
    hal.loadrt("hcmodcount")
    assert names(hal.functions("hcmodcount.*")) == [
        "hcmodcount.0", "hcmodcount.1", "hcmodcount.2"]
    run_functs(hal, "hcmodcount.0", "hcmodcount.1", "hcmodcount.2")
    hal.step()
    assert get(hal, "hcmodcount.0.ninst", "hcmodcount.0.index",
               "hcmodcount.2.index") == [3, 3, 203]


def test_count_parameter_overrides_default_count(hal, corpus):
    hal.loadrt("hcmodcount", count=2)
    assert names(hal.functions("hcmodcount.*")) == ["hcmodcount.0",
                                                    "hcmodcount.1"]
    run_functs(hal, "hcmodcount.1")
    hal.step()
    assert get(hal, "hcmodcount.1.ninst", "hcmodcount.1.index") == [2, 102]


def test_names_leave_count_at_zero(hal, corpus):
    """The reference's generated loader only sets count when names= is not
    given, so code reading count sees 0 with names=."""
    hal.loadrt("hcmodcount", "names=p,q")
    run_functs(hal, "p", "q")
    hal.step()
    assert get(hal, "p.ninst", "p.index", "q.index") == [0, 0, 100]


def test_code_section_modparams_defaults(hal, corpus):
    hal.loadrt("hcmodparams")
    # singleton: no instance number in the names
    assert own_pins(hal, "hcmodparams.*") == [
        "hcmodparams.asum", "hcmodparams.ival", "hcmodparams.lval",
        "hcmodparams.slen"]
    run_functs(hal, "hcmodparams")
    hal.step()
    assert get(hal, "hcmodparams.ival", "hcmodparams.lval",
               "hcmodparams.slen", "hcmodparams.asum") == [11, 11, 4, 10]


def test_code_section_modparams_from_the_load_line(hal, corpus):
    hal.loadrt("hcmodparams", "scale=2 lv=-5 word=xy arr=5,6,7 direct=1")
    run_functs(hal, "hcmodparams")
    hal.step()
    assert get(hal, "hcmodparams.ival", "hcmodparams.lval",
               "hcmodparams.slen", "hcmodparams.asum") == [3, -5, 2, 22]


def test_singleton_has_no_count_parameter(hal, corpus):
    with pytest.raises(InvalidError, match="count"):
        hal.loadrt("hcmodparams", count=2)
    assert names(hal.components("hcmodparams")) == []


def test_count_function_with_a_modparam(hal, corpus):
    hal.loadrt("hcgetcount")
    run_functs(hal, "hcgetcount.0", "hcgetcount.1")
    hal.step()
    assert get(hal, "hcgetcount.0.id", "hcgetcount.1.id",
               "hcgetcount.1.total") == [0, 1, 2]


def test_count_function_count_from_the_load_line(hal, corpus):
    hal.loadrt("hcgetcount", how_many=4)
    assert names(hal.functions("hcgetcount.*")) == [
        f"hcgetcount.{i}" for i in range(4)]
    run_functs(hal, "hcgetcount.3")
    hal.step()
    assert get(hal, "hcgetcount.3.id", "hcgetcount.3.total") == [3, 4]


def test_count_function_has_no_count_parameter(hal, corpus):
    with pytest.raises(InvalidError, match="count"):
        hal.loadrt("hcgetcount", count=2)
    assert names(hal.components("hcgetcount")) == []


# ------------------------------------------------------------ code sections

def test_implicit_function_body(hal, corpus):
    hal.loadrt("hcimplicit")
    run_functs(hal, "hcimplicit.0")
    trace = hal.run(3, inputs={"hcimplicit.0.a": [6, -2, 0],
                               "hcimplicit.0.b": [7, 8, 9]},
                    record=["hcimplicit.0.prod", "hcimplicit.0.runs"])
    assert list(trace["hcimplicit.0.prod"]) == [42, -16, 0]
    assert list(trace["hcimplicit.0.runs"]) == [1, 2, 3]


def test_implicit_body_of_a_named_function_uses_period(hal, corpus):
    hal.loadrt("hcimplicit2")
    assert names(hal.functions("hcimplicit2.*")) == ["hcimplicit2.0.tick"]
    run_functs(hal, "hcimplicit2.0.tick")
    hal.step(4)
    t = 0.0
    for _ in range(4):
        t += FPERIOD
    assert get(hal, "hcimplicit2.0.t", "hcimplicit2.0.ns") == [t, PERIOD]


def test_period_in_fp_and_nofp_functions(hal, corpus):
    hal.loadrt("hcperiod")
    assert names(hal.functions("hcperiod.*")) == ["hcperiod.0.count-ns",
                                                  "hcperiod.0.secs"]
    run_functs(hal, "hcperiod.0.count-ns", "hcperiod.0.secs")
    hal.step(3)
    fsec = 0.0
    for _ in range(3):
        fsec += FPERIOD
    assert get(hal, "hcperiod.0.nperiod", "hcperiod.0.ticks",
               "hcperiod.0.fsec") == [PERIOD, 3, fsec]


def test_io_pin_and_param_directions(hal, corpus):
    hal.loadrt("hcio")
    assert hal.pin("hcio.0.acc").direction == 48
    assert hal.param("hcio.0.wraps").direction == 64
    assert hal.param("hcio.0.step").direction == 192
    run_functs(hal, "hcio.0")
    trace = hal.run(5, record=["hcio.0.acc", "hcio.0.toggle"])
    assert list(trace["hcio.0.acc"]) == [2, 4, 6, 8, 0]
    assert list(trace["hcio.0.toggle"]) == [True, False, True, False, True]
    assert hal.getp("hcio.0.wraps") == 1
    hal.setp("hcio.0.acc", 7)
    hal.setp("hcio.0.step", 3)
    hal.step()
    assert get(hal, "hcio.0.acc", "hcio.0.wraps") == [0, 2]


def test_variables_arrays_pointers_defaults(hal, corpus):
    hal.loadrt("hcvars", count=2)
    run_functs(hal, "hcvars.0", "hcvars.1")
    trace = hal.run(5, inputs={"hcvars.0.in": [1.0, 2.0, 3.0, 4.0, 5.0]},
                    record=["hcvars.0.avg", "hcvars.0.filled",
                            "hcvars.0.pval", "hcvars.1.pval"])
    assert list(trace["hcvars.0.avg"]) == [1.0, 1.5, 2.0, 2.5, 3.5]
    assert list(trace["hcvars.0.filled"]) == [1, 2, 3, 4, 4]
    assert list(trace["hcvars.0.pval"]) == [41, 42, 43, 44, 45]
    assert list(trace["hcvars.1.pval"]) == [42, 43, 44, 45, 46]


def test_include_declarations(hal, corpus):
    hal.loadrt("hcinclude")
    run_functs(hal, "hcinclude.0")
    hal.set({"hcinclude.0.x": -16.0})
    hal.step()
    assert get(hal, "hcinclude.0.root", "hcinclude.0.mag",
               "hcinclude.0.len") == [4.0, 16.0, 3]
    comp = parse_file(os.path.join(COMPS, "hcinclude.comp"))
    assert comp.includes == ["<rtapi_math.h>", '"rtapi_string.h"']


def test_option_fp_no(hal, corpus):
    comp = parse_file(os.path.join(COMPS, "hcnoconv.comp"))
    assert comp.option("fp") is False
    hal.loadrt("hcnoconv")
    run_functs(hal, "hcnoconv.0")
    trace = hal.run(2, inputs={"hcnoconv.0.a": [1, 0x0FFFFFFF]},
                    record=["hcnoconv.0.shifted"])
    assert list(trace["hcnoconv.0.shifted"]) == [0x1F, 0xFFFFFFFF]


def test_documentation_declarations(hal, corpus, tmp_path):
    comp = parse_file(os.path.join(COMPS, "hcdocdecl.comp"))
    assert comp.doc == "All the documentation declarations; the code is a\nlatch."
    assert comp.notes == "Written for the halsdk test corpus."
    assert comp.see_also == "hcio(9)"
    assert comp.examples == "loadrt hcdocdecl"
    assert comp.authors == ["halsdk tests", "a second author"]
    assert comp.license == "GPL v2 or later"
    assert comp.description == r"A set/reset latch: \fBset\fR wins."
    assert comp.functions[0].doc == "the only function"
    proc = halcompile("--document", *comp_files("hcdocdecl"),
                      cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    page = (tmp_path / "hcdocdecl.9").read_text()
    for text in ("Written for the halsdk test corpus.", "hcio(9)",
                 "a second author", "GPL v2 or later", "the only function",
                 "on two lines"):
        assert text in page
    hal.loadrt("hcdocdecl")
    run_functs(hal, "hcdocdecl.0")
    trace = hal.run(4, inputs={"hcdocdecl.0.set": [0, 1, 0, 1],
                               "hcdocdecl.0.reset": [0, 0, 1, 1]},
                    record=["hcdocdecl.0.out"])
    assert list(trace["hcdocdecl.0.out"]) == [False, True, False, True]


def test_raw_strings(hal, corpus):
    comp = parse_file(os.path.join(COMPS, "hcrstring.comp"))
    assert comp.doc == r"Raw strings: \fIdoc\fR with backslashes kept"
    assert comp.pins[0].doc == r"the \fBinput\fR"
    assert comp.pins[1].doc == "the \\fBoutput\\fR,\nraw over two lines"
    assert comp.functions[0].doc == r"copies \fIin\fR"
    hal.loadrt("hcrstring")
    run_functs(hal, "hcrstring.0")
    hal.set({"hcrstring.0.in": 2.5})
    hal.step()
    assert hal.getp("hcrstring.0.out") == 7.5


def test_default_before_condition_as_the_reference_writes_it():
    """The reference's parser takes '= default' before 'if condition'."""
    comp = parse('component t;\npin out bit q;\n'
                 'param rw float gain = 2.5 if personality & 16;\n'
                 'function _;\nlicense "GPL";\n;;\nq = 1;\n', "t.comp")
    assert comp.params[0].default == "2.5"
    assert comp.params[0].condition.strip() == "personality & 16"


# ------------------------------------------------------------ Cython

def test_cython_types_arrays_and_condition(hal, corpus):
    hal.loadrt("hccytypes", "count=2", "personality=1,0")
    assert "hccytypes.0.extra" in own_pins(hal, "hccytypes.0.*")
    assert "hccytypes.1.extra" not in own_pins(hal, "hccytypes.1.*")
    assert own_pins(hal, "hccytypes.0.arr-*") == [
        "hccytypes.0.arr-0", "hccytypes.0.arr-1", "hccytypes.0.arr-2"]
    run_functs(hal, "hccytypes.0", "hccytypes.1")
    hal.step()
    assert get(hal, "hccytypes.0.fo", "hccytypes.0.so", "hccytypes.0.uo",
               "hccytypes.0.lo", "hccytypes.0.ulo", "hccytypes.0.bo",
               "hccytypes.0.arr-0", "hccytypes.0.arr-1", "hccytypes.0.arr-2",
               "hccytypes.0.extra") == [
        5.0, -6, 33, -1, 1, True, 0.0, 0.5, 1.0, 42]
    hal.set({"hccytypes.1.f": -2.0, "hccytypes.1.gain": 3.0,
             "hccytypes.1.b": True, "hccytypes.1.l": -7})
    hal.step()
    assert get(hal, "hccytypes.1.fo", "hccytypes.1.bo", "hccytypes.1.lo",
               "hccytypes.1.arr-2") == [-6.0, False, -8, -4.0]


# ------------------------------------------------------------ reference

with open(os.path.join(DATA, "reference_generated.json"),
          encoding="utf-8") as _f:
    REFERENCE_GENERATED = json.load(_f)


@pytest.fixture(scope="module")
def driven(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """Our builds of the .comp files of the reference goldens, driven by
    tests/data/halcompile/drive.py in a child process."""
    folder = tmp_path_factory.mktemp("hc-driven")
    build = folder / "build"
    build.mkdir()
    comps = sorted({c.partition(":")[0] for c in REFERENCE_GENERATED})
    proc = halcompile("--compile", *comp_files(*comps), cwd=str(build))
    assert proc.returncode == 0, proc.stderr
    proc = subprocess.run(
        [sys.executable, os.path.join(DATA, "drive.py"), "out.json",
         *REFERENCE_GENERATED],
        cwd=str(folder), env=child_env(HALSDK_PATH=str(build)),
        capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    with open(folder / "out.json", encoding="utf-8") as f:
        return json.load(f)


def test_reference_goldens_cover_the_c_corpus():
    comps = {c.partition(":")[0] for c in REFERENCE_GENERATED}
    assert len(comps) >= 30
    assert set(C_COMPS) - comps == {"hc64", "hcrstring"}


@pytest.mark.parametrize("case", sorted(REFERENCE_GENERATED))
def test_same_as_the_reference_generated_module(driven, case):
    """Pins, params and functions (names, types, directions, values after
    the load) and the values after three steps with the same inputs."""
    want, got = REFERENCE_GENERATED[case], driven[case]
    assert got["functions"] == want["functions"]
    assert got["pins"] == want["pins"]
    assert got["params"] == want["params"]
    assert got["steps"] == want["steps"]
    assert want["steps"][0], "the golden records values"


RTAPI_GUARDED_C = """\
#include "rtapi.h"
#ifdef RTAPI
#include "rtapi_app.h"
#endif
#include "hal.h"

static int comp_id;
static int k = 1;
RTAPI_MP_INT(k, "a parameter");

int rtapi_app_main(void)
{
    comp_id = hal_init("hcguard");
    if (comp_id < 0)
        return comp_id;
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
"""


def test_realtime_c_module_sees_rtapi_defined(tmp_path):
    """Realtime builds define RTAPI, as LinuxCNC's module build does: real
    modules include rtapi_app.h under #ifdef RTAPI."""
    (tmp_path / "hcguard.c").write_text(RTAPI_GUARDED_C)
    proc = halcompile("--compile", "hcguard.c", cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr


def test_realtime_c_module_with_rtapi_given(tmp_path):
    """The same file builds when RTAPI is given on the command line."""
    (tmp_path / "hcguard.c").write_text(RTAPI_GUARDED_C)
    proc = halcompile("--compile", "--extra-compile-args=-DRTAPI",
                      "hcguard.c", cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert os.path.isfile(tmp_path / ("hcguard" + extension_suffix()))


# ------------------------------------------------------------ userspace

def test_userspace_extra_compile_and_link_args(hal, corpus):
    """The launcher, started as a child attached to the test's instance:
    -DGAIN=3 reached the compiler and -lm the linker (pow)."""
    proc = subprocess.Popen([os.path.join(corpus, "hcuserlink")],
                            cwd=corpus, env=child_env(),
                            stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 20
        while not any(c.name == "hcuserlink" and c.ready
                      for c in hal.components()):
            assert time.monotonic() < deadline, "not ready"
            time.sleep(0.01)
        hal.setp("hcuserlink.0.x", 1.5)
        while hal.getp("hcuserlink.0.y") != 3.375:
            assert time.monotonic() < deadline, hal.getp("hcuserlink.0.y")
            time.sleep(0.01)
        hal.setp("hcuserlink.0.quit", True)
        assert proc.wait(timeout=20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert not any(c.name == "hcuserlink" for c in hal.components())



@pytest.mark.parametrize("name", USER_COMPS)
def test_userspace_against_the_reference(corpus, tmp_path, name):
    """NAME.hal run by our halrun prints what the reference's halrun
    printed for the reference's build of the same .comp (NAME.out)."""
    from helpers.halrun import normalize
    for file in (name, name + extension_suffix()):
        shutil.copy2(os.path.join(corpus, file), tmp_path / file)
    shutil.copy2(os.path.join(DATA, name + ".hal"), tmp_path / "run.hal")
    with open(os.path.join(DATA, name + ".out"), encoding="utf-8") as f:
        golden = f.read()
    proc = halrun_file("run.hal", tmp_path,
                       HALSDK_INSTANCE=f"hcu{os.getpid()}")
    assert proc.returncode == 0, proc.stderr
    assert normalize(proc.stdout) == normalize(golden)
