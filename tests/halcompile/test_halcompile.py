"""halcompile: .comp files with C code sections, compiled into component
modules, loaded with loadrt and stepped; and the errors of bad files."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from helpers import data_path
from helpers.components import names, own_pins
from helpers.halcompile import check_ddt, comp_files, compiled_on_path, halcompile

import halsdk
from halcompile import CompError, parse, parse_file
from halcompile.cli import main
from halcompile.model import c_identifier, hal_format, hal_identifier
from halsdk.build import extension_suffix

COMPS = str(data_path("comps"))
GOOD = ["hcddt", "hcmux2", "hcarrays", "hcsetup", "hcsingle", "hcsingle2",
        "hclogic", "hcdata", "hal_hcloop", "hcrtapp", "hcnames", "hcdelay",
        "hcslice", "hcclamp"]
PERIOD = 1_000_000


@pytest.fixture(scope="module")
def comp_dir(tmp_path_factory: pytest.TempPathFactory):
    """All the good test comps, compiled by the command into a folder that
    is put first on HALSDK_PATH."""
    with compiled_on_path(tmp_path_factory.mktemp("hc-modules"),
                          *comp_files(*GOOD)) as folder:
        yield folder


# ------------------------------------------------------------ the modules

def test_compile_writes_one_module_per_comp(comp_dir):
    for name in GOOD:
        assert os.path.isfile(os.path.join(comp_dir,
                                           name + extension_suffix()))


def test_ddt_derivative_is_exact(hal, comp_dir):
    assert hal.loadrt("hcddt") == ["hcddt"]
    assert own_pins(hal, "hcddt.*") == ["hcddt.0.in", "hcddt.0.out"]
    check_ddt(hal, "hcddt.0", "hcddt.0.in", "hcddt.0.out", PERIOD)


def test_delay_times_its_edges(hal, comp_dir):
    hal.loadrt("hcdelay")
    assert names(hal.params("hcdelay.0.*-delay")) == [
        "hcdelay.0.off-delay", "hcdelay.0.on-delay"]
    hal.newthread("servo", PERIOD)
    hal.addf("hcdelay.0", "servo")
    hal.set({"hcdelay.0.on-delay": 0.0035, "hcdelay.0.off-delay": 0.0015})
    inputs = [0, 1, 1, 1, 1, 1, 0, 0, 1, 0, 0, 0]
    trace = hal.run(len(inputs), inputs={"hcdelay.0.in": inputs},
                    record=["hcdelay.0.out", "hcdelay.0.elapsed"])
    # the same arithmetic as the C code
    out, timer, want_out, want_elapsed = 0, 0.0, [], []
    for x in inputs:
        if x == out:
            timer = 0.0
        else:
            timer += PERIOD * 1e-9
            if timer >= (0.0035 if x else 0.0015):
                out, timer = x, 0.0
        want_out.append(bool(out))
        want_elapsed.append(timer)
    assert list(trace["hcdelay.0.out"]) == want_out
    assert list(trace["hcdelay.0.elapsed"]) == want_elapsed
    assert True in want_out and want_out[-1] is False


def test_slice_and_clamp(hal, comp_dir):
    hal.loadrt("hcslice", "count=2 personality=3")
    assert own_pins(hal, "hcslice.0.out-*") == [
        "hcslice.0.out-00", "hcslice.0.out-01", "hcslice.0.out-02"]
    assert len(own_pins(hal, "hcslice.1.out-*")) == 8   # the default
    hal.loadrt("hcclamp")
    assert names(hal.params("hcclamp.0.m*")) == ["hcclamp.0.max",
                                                 "hcclamp.0.min"]
    hal.newthread("servo", PERIOD)
    for f in ("hcslice.0", "hcslice.1", "hcclamp.0"):
        hal.addf(f, "servo")
    hal.set({"hcslice.0.in": 0b101, "hcslice.1.in": 0xFFFFFFF0,
             "hcclamp.0.max": 2.5})
    trace = hal.run(3, inputs={"hcclamp.0.in": [1.0, 3.0, -1e30]},
                    record=["hcclamp.0.out"])
    assert list(trace["hcclamp.0.out"]) == [1.0, 2.5, -1e20]
    assert [hal.getp(f"hcslice.0.out-0{i}") for i in range(3)] == [
        True, False, True]
    assert [hal.getp(f"hcslice.1.out-0{i}") for i in range(8)] == [
        False] * 4 + [True] * 4


def test_mux2_selects(hal, comp_dir):
    hal.loadrt("hcmux2", count=2)
    assert own_pins(hal, "hcmux2.1.*") == [
        "hcmux2.1.in0", "hcmux2.1.in1", "hcmux2.1.out", "hcmux2.1.sel"]
    assert hal.pin("hcmux2.0.sel").direction == halsdk.core._core.IN
    assert hal.pin("hcmux2.0.out").direction == halsdk.core._core.OUT
    hal.newthread("servo", PERIOD)
    hal.addf("hcmux2.0", "servo")
    hal.set({"hcmux2.0.in0": 1.5, "hcmux2.0.in1": -2.0})
    trace = hal.run(4, inputs={"hcmux2.0.sel": [0, 1, 1, 0]},
                    record=["hcmux2.0.out"])
    assert list(trace["hcmux2.0.out"]) == [1.5, -2.0, -2.0, 1.5]
    assert hal.getp("hcmux2.1.out") == 0.0        # not in a thread


def test_arrays_types_and_defaults(hal, comp_dir):
    hal.loadrt("hcarrays")
    assert own_pins(hal, "hcarrays.0.*") == [
        "hcarrays.0.big", "hcarrays.0.count", "hcarrays.0.flag",
        "hcarrays.0.idx.00.v", "hcarrays.0.idx.01.v", "hcarrays.0.idx.02.v",
        "hcarrays.0.in", "hcarrays.0.in-0", "hcarrays.0.in-1",
        "hcarrays.0.in-2", "hcarrays.0.in-3", "hcarrays.0.sum",
        "hcarrays.0.ubig"]
    params = [n for n in names(hal.params("hcarrays.0.*"))
              if ".tmax" not in n]
    assert params == [
        "hcarrays.0.big-param", "hcarrays.0.calls", "hcarrays.0.gain-0",
        "hcarrays.0.gain-1", "hcarrays.0.gain-2", "hcarrays.0.gain-3",
        "hcarrays.0.half"]
    assert names(hal.functions("hcarrays.*")) == [
        "hcarrays.0", "hcarrays.0.count-calls"]
    c = halsdk.core._core
    types = {n: hal.pin("hcarrays.0." + n).type for n in
             ("big", "ubig", "flag", "count", "sum", "idx.01.v")}
    assert types == {"big": c.S64, "ubig": c.U64, "flag": c.BIT,
                     "count": c.U32, "sum": c.FLOAT, "idx.01.v": c.S32}
    assert hal.pin("hcarrays.0.count").direction == c.IO
    assert hal.param("hcarrays.0.calls").direction == c.RO
    assert hal.param("hcarrays.0.gain-2").direction == c.RW
    # defaults: negative, hex, 64-bit, TRUE, 1e20, .5
    assert hal.getp("hcarrays.0.sum") == -1.5
    assert hal.getp("hcarrays.0.idx.02.v") == 7
    assert hal.getp("hcarrays.0.count") == 16
    assert hal.getp("hcarrays.0.big") == -5_000_000_000
    assert hal.getp("hcarrays.0.ubig") == 0xFFFFFFFFFFFF
    assert hal.getp("hcarrays.0.flag") is True
    assert hal.getp("hcarrays.0.gain-3") == 1.0
    assert hal.getp("hcarrays.0.big-param") == 1e20
    assert hal.getp("hcarrays.0.half") == 0.5

    hal.newthread("servo", PERIOD)
    hal.addf("hcarrays.0", "servo")
    hal.addf("hcarrays.0.count-calls", "servo")
    hal.set({"hcarrays.0.in-0": 1.0, "hcarrays.0.in-1": 2.0,
             "hcarrays.0.in-2": 3.0, "hcarrays.0.in-3": 4.0,
             "hcarrays.0.gain-1": 10.0, "hcarrays.0.in": 0.25})
    hal.step(3)
    assert hal.getp("hcarrays.0.sum") == 1 + 20 + 3 + 4 + 0.25
    assert hal.getp("hcarrays.0.idx.00.v") == 10
    assert hal.getp("hcarrays.0.big") == -5_000_000_003
    assert hal.getp("hcarrays.0.ubig") == 0xFFFFFFFFFFFF + 3
    assert hal.getp("hcarrays.0.flag") is False
    assert hal.getp("hcarrays.0.count") == 19
    assert hal.getp("hcarrays.0.calls") == 3


def test_extra_setup_and_modparam(hal, comp_dir):
    # default_count 2; EXTRA_SETUP gets the instance number as extra_arg
    assert hal.loadrt("hcsetup") == ["hcsetup"]
    assert [hal.getp(f"hcsetup.{i}.base") for i in range(3)
            if hal.params(f"hcsetup.{i}.base")] == [100, 110]
    hal.newthread("servo", PERIOD, fp=False)
    hal.addf("hcsetup.1.update", "servo")
    hal.setp("hcsetup.1.step", 3)
    hal.step(1)
    assert hal.getp("hcsetup.1.out") == 110 + 3 * 2
    assert hal.getp("hcsetup.1.ninst") == 2     # count = default_count
    hal.unloadrt("hcsetup")
    assert hal.components("hcsetup") == []
    # the modparam, on the load line; EXTRA_CLEANUP reset the counter
    hal.loadrt("hcsetup", "offset=5 count=3")
    assert [hal.getp(f"hcsetup.{i}.base") for i in range(3)] == [5, 15, 25]
    hal.addf("hcsetup.2.update", "servo")
    hal.step(1)
    assert hal.getp("hcsetup.2.out") == 25 + 1 * 3
    assert hal.getp("hcsetup.2.ninst") == 3


def test_count_and_names(hal, comp_dir, capfd):
    hal.loadrt("hcmux2", "names=first,second.one")
    assert names(hal.functions("*")) == ["first", "second.one"]
    assert "second.one.sel" in own_pins(hal, "second.one.*")
    hal.unloadrt("hcmux2")
    hal.loadrt("hcmux2", count=3)
    assert names(hal.functions("hcmux2.*")) == [
        "hcmux2.0", "hcmux2.1", "hcmux2.2"]
    hal.unloadrt("hcmux2")
    capfd.readouterr()
    # the module's message is the error (of the class its errno means),
    # not a separate line on stderr
    with pytest.raises(halsdk.InvalidError,
                       match="^hcmux2: count= and names= are mutually "
                             "exclusive$"):
        hal.loadrt("hcmux2", "count=2 names=a")
    assert capfd.readouterr().err == ""
    assert hal.components("hcmux2") == []
    assert hal.pins("*") == []
    hal.loadrt("hcmux2", count=-1)       # a negative count makes none
    assert hal.functions("*") == []
    hal.unloadrt("hcmux2")
    capfd.readouterr()
    with pytest.raises(halsdk.InvalidError,
                       match=f'names: "{"x" * 127}" too long'):
        hal.loadrt("hcmux2", "names=ok," + "x" * 200)
    assert hal.components("hcmux2") == [] and hal.pins("ok.*") == []


def test_singleton_and_private_globals(hal, comp_dir):
    hal.loadrt("hcsingle")
    hal.loadrt("hcsingle2")
    assert own_pins(hal, "hcsingle.*") == ["hcsingle.in", "hcsingle.value"]
    assert names(hal.functions("*")) == ["hcsingle", "hcsingle2"]
    with pytest.raises(halsdk.InvalidError):
        hal.loadrt("hcdata", "count=2")  # count_function: no count param
    hal.newthread("servo", PERIOD, fp=False)
    hal.addf("hcsingle", "servo")
    hal.addf("hcsingle2", "servo")
    hal.set({"hcsingle.in": 3, "hcsingle2.in": 1})
    hal.step(2)
    # each module has its own 'shared_total' (and 'read' helper); SCALE
    # comes from the option extra_compile_args
    assert hal.getp("hcsingle.value") == 2 * 6
    assert hal.getp("hcsingle2.value") == 2000


def test_singleton_has_no_count_param(hal, comp_dir):
    with pytest.raises(halsdk.InvalidError, match="count"):
        hal.loadrt("hcsingle", "count=2")


def test_personality(hal, comp_dir):
    hal.loadrt("hclogic", "count=3 personality=0x102,0x305,0x503")
    assert own_pins(hal, "hclogic.0.*") == [
        "hclogic.0.and", "hclogic.0.in-00", "hclogic.0.in-01"]
    assert own_pins(hal, "hclogic.1.*") == [
        "hclogic.1.and", "hclogic.1.in-00", "hclogic.1.in-01",
        "hclogic.1.in-02", "hclogic.1.in-03", "hclogic.1.in-04",
        "hclogic.1.or"]
    assert own_pins(hal, "hclogic.2.*") == [
        "hclogic.2.and", "hclogic.2.in-00", "hclogic.2.in-01",
        "hclogic.2.in-02", "hclogic.2.xor"]
    hal.newthread("servo", PERIOD, fp=False)
    for i in range(3):
        hal.addf(f"hclogic.{i}", "servo")
    hal.set({"hclogic.1.in-02": 1, "hclogic.2.in-00": 1,
             "hclogic.2.in-01": 1})
    hal.step(1)
    assert hal.getp("hclogic.0.and") is False
    assert hal.getp("hclogic.1.or") is True
    assert hal.getp("hclogic.1.and") is False
    assert hal.getp("hclogic.2.xor") is False
    hal.setp("hclogic.2.in-02", 1)
    hal.step(1)
    assert hal.getp("hclogic.2.xor") is True
    assert hal.getp("hclogic.2.and") is True


def test_default_personality(hal, comp_dir):
    hal.loadrt("hclogic", "count=2 personality=0x202")
    assert own_pins(hal, "hclogic.0.*") == [
        "hclogic.0.in-00", "hclogic.0.in-01", "hclogic.0.or"]
    assert own_pins(hal, "hclogic.1.*") == [
        "hclogic.1.and", "hclogic.1.in-00", "hclogic.1.in-01",
        "hclogic.1.in-02"]


def test_more_instances_than_personalities_wrap_around(hal, comp_dir,
                                                      capfd):
    hal.loadrt("hclogic", "count=66 personality=0x102,0x201")
    assert own_pins(hal, "hclogic.65.*") == [
        "hclogic.65.in-00", "hclogic.65.or"]      # personality[65 % 64]
    err = capfd.readouterr().err
    assert "hclogic: hclogic.64 got personality=258(=0x102)" in err
    assert "hclogic.63 got" not in err


def test_personality_size_over_the_maximum_fails(hal, comp_dir, capfd):
    with pytest.raises(halsdk.HalError, match="Requested size 17 exceeds max size 16"):
        hal.loadrt("hclogic", "personality=17")
    assert hal.components("hclogic") == []


def test_data_and_count_function(hal, comp_dir):
    hal.loadrt("hcdata")
    assert names(hal.functions("*")) == ["hcdata.0", "hcdata.1", "hcdata.2"]
    hal.newthread("servo", PERIOD, fp=False)
    hal.addf("hcdata.0", "servo")
    hal.addf("hcdata.2", "servo")
    hal.step(2)
    hal.delf("hcdata.0", "servo")
    hal.step(1)
    # each instance counts in its own data block
    assert [hal.getp(f"hcdata.{i}.n") for i in range(3)] == [2, 0, 3]


def test_hal_prefix_and_implicit_function(hal, comp_dir):
    assert hal.loadrt("hal_hcloop") == ["hal_hcloop"]
    assert own_pins(hal, "*") == ["hcloop.0.example"]
    assert hal.getp("hcloop.0.example") == 4.25
    hal.newthread("servo", PERIOD)
    hal.addf("hcloop.0", "servo")
    hal.step(2)
    assert hal.getp("hcloop.0.example") == 17.0


def test_load_again_starts_afresh(hal, comp_dir):
    hal.newthread("servo", PERIOD)
    for _ in range(2):
        hal.loadrt("hcddt", "names=d")
        hal.addf("d", "servo")
        hal.setp("d.in", 1.0)
        hal.step(1)
        assert hal.getp("d.out") == 1.0 / (PERIOD * 1e-9)
        hal.unloadrt("hcddt")
        assert hal.pins("d.*") == []


def test_rtapi_app_no_uses_export(hal, comp_dir):
    hal.loadrt("hcrtapp", "n_inst=3")
    assert names(hal.functions("*")) == ["rt-a", "rt-b", "rt-c"]
    assert hal.getp("rt-c.k") == 2
    hal.newthread("servo", PERIOD, fp=False)
    hal.addf("rt-b", "servo")
    hal.setp("rt-b.k", 5)
    hal.step(1)
    assert hal.getp("rt-b.out") == 5 * (PERIOD // 1000)


def test_names_that_clash_elsewhere(hal, comp_dir):
    hal.loadrt("hcnames")
    assert own_pins(hal, "hcnames.0.*") == [
        "hcnames.0.and", "hcnames.0.in", "hcnames.0.in00-copy",
        "hcnames.0.in01-copy", "hcnames.0.index", "hcnames.0.open",
        "hcnames.0.or", "hcnames.0.select"]
    assert names(hal.functions("*")) == ["hcnames.0.read", "hcnames.0.write"]
    hal.newthread("servo", PERIOD, fp=False)
    hal.addf("hcnames.0.read", "servo")
    hal.addf("hcnames.0.write", "servo")
    hal.set({"hcnames.0.in": 21, "hcnames.0.and": 1, "hcnames.0.or": 1})
    hal.step(1)
    assert [hal.getp("hcnames.0." + n) for n in
            ("index", "select", "open", "in00-copy", "in01-copy")] == [
        21, 1, 45, 3, 4]


# ------------------------------------------------------------ the command

def test_preprocess_writes_c_with_line_directives(tmp_path):
    src = tmp_path / "hcddt.comp"
    src.write_text(open(os.path.join(COMPS, "hcddt.comp")).read())
    proc = halcompile("hcddt.comp", cwd=str(tmp_path))     # the default
    assert proc.returncode == 0, proc.stderr
    text = (tmp_path / "hcddt.c").read_text()
    assert '#line 9 "hcddt.comp"' in text
    assert "FUNCTION(_) {" in text
    assert 'hal_init("hcddt")' in text
    proc = halcompile("--preprocess", "-o", "sub.c", "hcddt.comp",
                      cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "sub.c").read_text() == text.replace('"hcddt.c"',
                                                            '"sub.c"')


def test_personalities_option(tmp_path):
    src = os.path.join(COMPS, "hclogic.comp")
    out = tmp_path / "hclogic.c"
    assert main(["--personalities=4", "-o", str(out), src]) == 0
    text = out.read_text()
    assert "static int personality[4] = {259, 259, 259, 259};" in text
    assert "personality[idx % 4]" in text
    assert main(["--personalities=0", "-o", str(out), src]) == 1


def test_compile_c_file_and_install(tmp_path, monkeypatch, hal):
    data = tmp_path / "data"
    monkeypatch.setenv("XDG_DATA_HOME", str(data))
    proc = halcompile("--install",
                      str(data_path("components", "cscale.c")),
                      cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    installed = data / "halsdk" / "components" / ("cscale" +
                                                  extension_suffix())
    assert installed.is_file()
    proc = halcompile("--install", os.path.join(COMPS, "hcmux2.comp"),
                      cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert (data / "halsdk" / "components" /
            ("hcmux2" + extension_suffix())).is_file()
    monkeypatch.delenv("HALSDK_PATH", raising=False)
    hal.loadrt("hcmux2", "names=m")         # found in the user folder
    assert "m.sel" in own_pins(hal, "m.*")


def test_compile_to_a_folder_with_extra_args(tmp_path):
    src = tmp_path / "hcflags.comp"
    src.write_text("component hcflags;\npin out s32 out;\nfunction _ nofp;\n"
                   'license "GPL";\n;;\nout = FROM_THE_COMMAND_LINE;\n')
    proc = halcompile("--compile", "-o", "out", "hcflags.comp",
                      cwd=str(tmp_path))
    assert proc.returncode == 1
    assert "hcflags.comp:6:7: error" in proc.stderr
    proc = halcompile("--compile", "-o", "out",
                      "--extra-compile-args=-DFROM_THE_COMMAND_LINE=42 -O1",
                      "hcflags.comp", cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    module = tmp_path / "out" / ("hcflags" + extension_suffix())
    assert proc.stdout.strip() == os.path.join("out", module.name)
    assert module.is_file()


def test_bad_syntax_reports_file_line_col(tmp_path):
    path = os.path.join(COMPS, "hcbadsyntax.comp")
    proc = halcompile("--compile", path, cwd=str(tmp_path))
    assert proc.returncode == 1
    lines = proc.stderr.splitlines()
    assert lines[0].startswith(f"{path}:3:9: expected a HAL type")
    assert lines[1].strip() == "pin out flaot other;"
    assert lines[2].index("^") == lines[1].index("flaot")
    assert "Traceback" not in proc.stderr
    assert os.listdir(tmp_path) == []


def test_c_error_points_into_the_comp(tmp_path):
    path = os.path.join(COMPS, "hcbadc.comp")
    proc = halcompile("--compile", path, cwd=str(tmp_path))
    assert proc.returncode == 1
    assert f"{path}:8:11: error:" in proc.stderr
    assert "undefined_thing" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert os.listdir(tmp_path) == []        # nothing half-built


def test_c_errors_in_declarations_point_at_their_column(tmp_path):
    (tmp_path / "hcdecl.comp").write_text(
        "component hcdecl;\n"
        "pin out float out = NOT_DEFINED;\n"
        "pin out float x if no_such_thing;\n"
        "pin in bit y-#[3 : bad_size] = 1;\n"
        "variable int v = nope;\n"
        "function _;\n"
        'license "GPL";\n;;\nout = 1;\n')
    proc = halcompile("--compile", "hcdecl.comp", cwd=str(tmp_path))
    assert proc.returncode == 1
    for where, name in [("2:21", "NOT_DEFINED"), ("3:20", "no_such_thing"),
                        ("4:20", "bad_size"), ("5:18", "nope")]:
        assert f"hcdecl.comp:{where}: error: \u2018{name}\u2019" in \
            proc.stderr or f"hcdecl.comp:{where}: error: '{name}'" in \
            proc.stderr, proc.stderr
    (tmp_path / "hcinc.comp").write_text(
        'component hcinc;\n  include "nothere.h";\npin in bit b;\n'
        'function _;\nlicense "GPL";\n;;\n')
    proc = halcompile("--compile", "hcinc.comp", cwd=str(tmp_path))
    assert proc.returncode == 1
    assert "hcinc.comp:2:11: fatal error: nothere.h" in proc.stderr
    assert sorted(os.listdir(tmp_path)) == ["hcdecl.comp", "hcinc.comp"]


def test_missing_file_and_bad_mode(tmp_path):
    proc = halcompile("--compile", "nothere.comp", cwd=str(tmp_path))
    assert proc.returncode == 1
    assert proc.stderr.strip() == "halcompile: nothere.comp: no such file"
    assert main(["--document", "-o", str(tmp_path / "doc"),
                 os.path.join(COMPS, "hcddt.comp")]) == 0
    assert sorted(os.listdir(tmp_path / "doc")) == ["hcddt.9", "hcddt.rst"]


# ------------------------------------------------------------ the language

def check_error(text: str, where: str, message: str) -> None:
    with pytest.raises(CompError) as info:
        parse(text, "x.comp")
    assert str(info.value.loc) == where
    assert message in info.value.message


HEAD = 'component x;\nlicense "GPL";\nfunction _;\n'
PIN = "pin in bit the_pin;\n"


@pytest.mark.parametrize("body, where, message", [
    ("pin out float a;\npin in float a;\n", "x.comp:5:14",
     "duplicate item name 'a'"),
    ("pin out float a-#;\n", "x.comp:4:15", "not an array"),
    ("pin out float a[2];\n", "x.comp:4:15", "has no '#'"),
    ("pin out float a#[0];\n", "x.comp:4:15", "at least one item"),
    ("pin up float a;\n", "x.comp:4:5", "expected a pin direction"),
    ("param rw bits a;\n", "x.comp:4:10", "expected a HAL type"),
    ("param w float a;\n", "x.comp:4:7", "expected a param direction"),
    ("option bogus yes;\n", "x.comp:4:8", "unknown option 'bogus'"),
    ("option singleton maybe;\n", "x.comp:4:18", "takes yes or no"),
    ("option default_count x;\n", "x.comp:4:22", "takes an integer"),
    ("pin out float fperiod;\n", "x.comp:4:15", "is reserved"),
    ("variable int _comp_x;\n", "x.comp:4:14", "is reserved"),
    ('pin out float a "doc;\n', "x.comp:4:17", "unterminated string"),
    ("pin out float a\n", "x.comp:5:1", "expected ';'"),
    ("frobnicate;\n", "x.comp:4:1", "unknown declaration 'frobnicate'"),
    ("variable int* p;\n", "x.comp:4:13", "next to its name"),
    ("function _;\n", "x.comp:4:10", "duplicate item name '_'"),
    ("modparam float f;\n", "x.comp:4:10", "expected a modparam type"),
    ("/* open comment\n", "x.comp:4:1", "unterminated comment"),
    ("option userspace yes;\n", "x.comp:4:8", "may not have functions"),
    ("option singleton;\noption count_function;\n", "x.comp:5:8",
     "cannot go with option singleton"),
    ("pin out bit a if ;\n", "x.comp:4:18", "expected a condition"),
    ("pin out bit a = ;\n", "x.comp:4:17", "expected a value"),
    ("pin out bit a#.b#[2];\n", "x.comp:4:13", "more than one run"),
    ("option fp;\noption fp no;\n", "x.comp:5:8", "given twice"),
    ("pin out bit a;\nmodparam int a;\n", "x.comp:5:14",
     "duplicate item name 'a'"),
])
def test_semantic_and_syntax_errors(body, where, message):
    check_error(HEAD + body + PIN + ";;\n", where, message)


def test_undefined_functions_are_caught_before_building():
    text = ('component x;\npin out s32 out;\nfunction _ nofp;\n'
            'function other;\noption extra_setup;\nlicense "GPL";\n;;\n'
            'FUNCTION(_) { out = 1; }\n')
    check_error(text, "x.comp:4:10", "function 'other' has no definition")
    check_error(text.replace("function other;\n", ""), "x.comp:4:8",
                "option extra_setup needs EXTRA_SETUP()")
    comp = parse(text.replace("function other;\n", "") +
                 "EXTRA_SETUP() { return 0; }\n", "x.comp")
    assert comp.option("extra_setup") is True


def test_license_and_component_name_are_checked(tmp_path):
    check_error('component x;\npin in bit b;\n;;\n', "x.comp:1:11",
                "license not specified")
    check_error('component x;\nlicense "GPL";\n;;\n', "x.comp:1:11",
                "at least one pin")
    check_error('pin out float a;\n', "x.comp:1:1",
                "must start with 'component NAME;'")
    path = tmp_path / "other.comp"
    path.write_text('component x;\npin in bit b;\nlicense "GPL";\n;;\n')
    with pytest.raises(CompError, match="does not match the file name"):
        parse_file(str(path))


def test_the_model_of_a_full_file():
    comp = parse_file(os.path.join(COMPS, "hcarrays.comp"))
    assert comp.name == "hcarrays" and comp.doc == "Arrays and defaults"
    pin = comp.pins[0]
    assert (pin.kind, pin.direction, pin.type, pin.name, pin.doc) == (
        "pin", "in", "float", "in-#", "inputs")
    assert pin.array is not None and pin.array.size == 4
    assert [p.default for p in comp.pins[1:7]] == [
        "-1.5", "7", "0x10", "-5000000000", "0xFFFFFFFFFFFF", "TRUE"]
    assert [(f.name, f.fp) for f in comp.functions] == [
        ("_", True), ("count_calls", False)]
    assert [(v.ctype, v.stars, v.name, v.size, v.default)
            for v in comp.variables] == [
        ("double", "", "hist", 4, "2.5"), ("int", "*", "unused_ptr", None,
                                           None),
        ("unsigned int", "", "ticks", None, None)]
    assert comp.code_line == 22 and comp.code.startswith("FUNCTION(_) {")
    mux = parse_file(os.path.join(COMPS, "hcmux2.comp"))
    assert mux.description == ("A two-input multiplexer,\n"
                               "written as a test of halcompile.")
    assert mux.see_also == "mux4(9)" and mux.license == "GPL"
    setup = parse_file(os.path.join(COMPS, "hcsetup.comp"))
    assert [(m.type, m.name, m.default, m.doc) for m in setup.modparams] == [
        ("int", "offset", "100", "added to each instance's base"),
        ("dummy", "unused", None,
         "a documented parameter the code does not read")]
    assert setup.options == {"extra_setup": True, "extra_cleanup": True,
                             "default_count": 2}


def test_strings_and_includes():
    comp = parse('component x "a \\"quoted\\" word\\n";\n'
                 'description r"\\fBbold\\fR";\n'
                 'notes """two\n"lines" """;\n'
                 'include <stdlib.h>;\ninclude "local.h";\n'
                 'pin in bit b;\nlicense "GPL";\n;;\n', "x.comp")
    assert comp.doc == 'a "quoted" word\n'
    assert comp.description == r"\fBbold\fR"
    assert comp.notes == 'two\n"lines" '
    assert comp.includes == ["<stdlib.h>", '"local.h"']


@pytest.mark.parametrize("halname, c_name, hal_name, fmt", [
    ("x_y_z", "x_y_z", "x-y-z", "x-y-z"),
    ("x-y.z", "x_y_z", "x-y.z", "x-y.z"),
    ("x_y_z_", "x_y_z_", "x-y-z", "x-y-z"),
    ("x.##.y", "x_y", "x.##.y", "x.%02d.y"),
    ("x.##", "x", "x.##", "x.%02d"),
    ("in-#", "in", "in-#", "in-%01d"),
    ("in##", "in", "in##", "in%02d"),
    ("in_", "in_", "in", "in"),
    ("_", "_", "", ""),
])
def test_name_rules(halname, c_name, hal_name, fmt):
    assert c_identifier(halname) == c_name
    assert hal_identifier(halname) == hal_name
    assert hal_format(halname) == fmt


def test_install_then_halrun_from_a_fresh_account(tmp_path):
    """The issue's promise, with the installed commands and nothing set
    up: an empty home (so an empty build cache and user folder), no
    HALSDK_PATH; ``halcompile --install x.comp && halrun -f uses-x.hal``."""
    bindir = os.path.dirname(sys.executable)
    if not os.path.isfile(os.path.join(bindir, "halcompile")):
        pytest.fail(f"the halcompile command is not installed in {bindir}")
    home = tmp_path / "home"
    home.mkdir()
    (tmp_path / "hcdouble.comp").write_text(
        'component hcdouble "twice the input";\n'
        "pin in float in;\npin out float out;\nfunction _;\n"
        'license "GPL";\n;;\nFUNCTION(_) { out = 2 * in; }\n')
    (tmp_path / "uses-hcdouble.hal").write_text(
        "loadrt hcdouble names=d\n"
        "loadrt threads name1=t period1=1000000\n"
        "addf d t\nsetp d.in 21.25\nstart\n"
        "loadusr -w sleep 0.2\nstop\ngetp d.out\nshow pin d.*\n")
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("HALSDK_", "XDG_", "PYTHON"))}
    env.update(HOME=str(home), PATH=bindir + os.pathsep + env["PATH"],
               HALSDK_INSTANCE=f"fresh{os.getpid()}")
    proc = subprocess.run(
        ["sh", "-c", "halcompile --install hcdouble.comp && "
                     "halrun -f uses-hcdouble.hal"],
        cwd=str(tmp_path), env=env, capture_output=True, text=True,
        timeout=120)
    assert proc.returncode == 0, proc.stderr
    module = home / ".local" / "share" / "halsdk" / "components" / \
        ("hcdouble" + extension_suffix())
    lines = proc.stdout.splitlines()
    assert lines[0] == str(module)
    assert lines[1] == "42.5"
    assert any(line.split()[-1:] == ["d.out"] and "42.5" in line
               for line in lines[2:])
    assert (home / ".cache" / "halsdk" / "build").is_dir()


def test_hash_run_is_a_minimum_width():
    """As in the reference, '#' is a minimum width: a#[12] numbers its
    pins a0 ... a9, a10, a11 (a .comp that relies on it compiles)."""
    comp = parse("component x;\npin out float a#[12];\nfunction _;\n"
                 'license "GPL";\n;;\n', "x.comp")
    assert comp.pins[0].array.size == 12
    assert hal_format(comp.pins[0].name) == "a%01d"
    assert hal_format(comp.pins[0].name) % 11 == "a11"
