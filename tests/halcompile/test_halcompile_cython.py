"""halcompile: .comp files whose code section is Cython (``option cython``),
compiled into modules, loaded with loadrt and stepped."""

from __future__ import annotations

import os

import pytest
from helpers import REPO, data_path
from helpers.components import own_pins
from helpers.halcompile import check_ddt, comp_files, compiled_on_path, halcompile

from halcompile import CompError, parse
from halcompile.gen_cython import CythonSourceError, generate, split_code
from halsdk.build import extension_suffix
from halsdk.errors import InvalidError

COMPS = str(data_path("comps"))
PERIOD = 1_000_000


@pytest.fixture(scope="module")
def cy_dir(tmp_path_factory: pytest.TempPathFactory):
    with compiled_on_path(tmp_path_factory.mktemp("hc-cython"),
                          *comp_files("hccyddt", "hccymulti")) as folder:
        yield folder


def test_modules_are_built(cy_dir):
    for name in ("hccyddt", "hccymulti"):
        assert os.path.isfile(os.path.join(cy_dir, name + extension_suffix()))


def test_cython_ddt_is_exact(hal, cy_dir):
    hal.loadrt("hccyddt", "names=d")
    assert own_pins(hal, "d.*") == ["d.in", "d.out"]
    check_ddt(hal, "d", "d.in", "d.out", PERIOD)


def test_cython_multi_function_component(hal, cy_dir):
    hal.loadrt("hccymulti", "count=2", "personality=3,6", "bias=5")
    pins0 = [p.name for p in hal.pins("hccymulti.0.*")]
    pins1 = [p.name for p in hal.pins("hccymulti.1.*")]
    # array sizes and the conditional pin follow the personality
    assert [n for n in pins0 if ".x" in n] == [
        "hccymulti.0.x0", "hccymulti.0.x1", "hccymulti.0.x2"]
    assert [n for n in pins1 if ".x" in n] == [
        "hccymulti.1.x0", "hccymulti.1.x1"]
    assert "hccymulti.1.odd" in pins1 and "hccymulti.0.odd" not in pins0
    # param default, and EXTRA_SETUP with extra_arg and a modparam
    assert hal.getp("hccymulti.0.scale") == 2.0
    assert hal.getp("hccymulti.0.setup-value") == 5
    assert hal.getp("hccymulti.1.setup-value") == 105
    hal.newthread("t", PERIOD)
    for i in (0, 1):
        hal.addf(f"hccymulti.{i}.sum-up", "t")
        hal.addf(f"hccymulti.{i}.track", "t")
    hal.set({"hccymulti.0.x0": 1.0, "hccymulti.0.x1": 2.0,
             "hccymulti.0.x2": 4.0, "hccymulti.1.x0": 1.5,
             "hccymulti.1.x1": -4.0, "hccymulti.1.acc": 100.0})
    hal.setp("hccymulti.1.scale", 0.5)
    hal.step(3)
    g = hal.getp
    assert g("hccymulti.0.sum") == 14.0 and g("hccymulti.1.sum") == -1.25
    assert g("hccymulti.0.acc") == 42.0          # io pin, read and written
    assert g("hccymulti.1.acc") == 100.0 - 3 * 1.25
    assert g("hccymulti.0.steps") == 3
    assert g("hccymulti.0.big") == 7007007
    assert g("hccymulti.1.odd") is True
    assert g("hccymulti.0.peak") == 14.0 and g("hccymulti.0.last") == 14.0
    # a body that returns early still writes its outputs back
    hal.setp("hccymulti.0.hold", True)
    hal.setp("hccymulti.0.x2", 100.0)
    hal.step(2)
    assert g("hccymulti.0.held") == 2
    assert g("hccymulti.0.sum") == 206.0
    assert g("hccymulti.0.peak") == 14.0            # frozen
    hal.setp("hccymulti.0.hold", False)
    hal.step(1)
    assert g("hccymulti.0.peak") == 206.0
    assert g("hccymulti.0.big") == 7007007007007007  # s64, 6 steps
    assert g("hccymulti.0.held") == 2


def test_extra_cleanup_runs_on_unload(hal, cy_dir):
    hal.loadrt("hccymulti")
    module = hal.module("hccymulti")
    before = module.cleanup_count()
    hal.unloadrt("hccymulti")
    assert module.cleanup_count() == before + 1
    assert hal.pins("hccymulti.*") == []


def test_count_and_names_exclusive(hal, cy_dir):
    with pytest.raises(InvalidError, match="mutually exclusive"):
        hal.loadrt("hccyddt", "count=2", "names=a")
    assert [c.name for c in hal.components() if c.name == "hccyddt"] == []


def test_preprocess_writes_pyx(tmp_path):
    out = tmp_path / "m.pyx"
    proc = halcompile("--preprocess", "-o", str(out),
                      os.path.join(COMPS, "hccymulti.comp"),
                      cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    text = out.read_text()
    assert "cdef void sum_up(void *__arg, long period) noexcept nogil:" in text
    assert "cdef void track(void *__arg, long period) noexcept nogil:" in text
    assert "    finally:" in text


def test_cython_error_points_into_the_comp(tmp_path):
    src = tmp_path / "hccybad.comp"
    src.write_text('component hccybad;\npin out float out;\nfunction _;\n'
                   'option cython yes;\nlicense "GPL";\n;;\n'
                   'out = 1.0\nout = undefined_name + 1\n')
    proc = halcompile("--compile", str(src), cwd=str(tmp_path))
    assert proc.returncode == 1
    assert f"{src}:8:7: undeclared name" in proc.stderr
    assert "undefined_name" in proc.stderr or "undeclared" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not list(tmp_path.glob("hccybad*.so"))


HEAD = ('component x;\nlicense "GPL";\npin out float o;\n'
        'option cython yes;\n')


def test_structure_errors():
    with pytest.raises(CompError) as cinfo:
        parse(HEAD + "function f;\n;;\nFUNCTION(g):\n    o = 1\n", "x.comp")
    assert str(cinfo.value.loc) == "x.comp:5:10"
    assert "FUNCTION(f)" in cinfo.value.message
    comp = parse(HEAD + "function f;\nfunction h;\n;;\nFUNCTION(f):\n"
                 "    o = 1\nFUNCTION(h):\n    pass\nFUNCTION(z):\n"
                 "    pass\n", "x.comp")
    with pytest.raises(CythonSourceError) as info:
        generate(comp)
    assert info.value.line == 12 and "no such function" in info.value.message
    with pytest.raises(CompError) as cinfo:
        parse(HEAD + "function f;\noption data T;\n;;\no = 1\n", "x.comp")
    assert "not supported with option cython" in cinfo.value.message
    with pytest.raises(CompError) as cinfo:
        parse(HEAD + "option userspace yes;\n;;\nuser_mainloop\n", "x.comp")
    assert str(cinfo.value.loc) == "x.comp:5:8"
    comp = parse(HEAD + "pin in float in;\nfunction f;\n;;\no = in\n",
                 "x.comp")
    with pytest.raises(CythonSourceError) as info:
        generate(comp)
    assert info.value.line == 5 and "'in_'" in info.value.message


def test_split_code_blocks():
    comp = parse(HEAD + "function f;\nfunction g;\noption extra_setup;\n;;\n"
                 "cdef int k = 3\n\nFUNCTION(f):\n    o = k\n\n"
                 "    o += 1\nFUNCTION(g):\n    o = 2\nEXTRA_SETUP():\n"
                 "    return 0\n", "x.comp")
    module, blocks = split_code(comp)
    assert [t for _, t in module if t] == ["cdef int k = 3"]
    assert [t.strip() for _, t in blocks["f"].lines if t.strip()] == [
        "o = k", "o += 1"]
    assert blocks["f"].lines[0][0] == 12       # line numbers of the .comp
    assert set(blocks) == {"f", "g", "extra_setup"}


def test_the_documented_example_works(hal, tmp_path, monkeypatch):
    with open(os.path.join(REPO, "docs", "halcompile.rst"),
              encoding="utf-8") as f:
        rst = f.read()
    start = rst.index("   component lowpass2")
    end = rst.index("\n\n", rst.index(";;", start))
    src = tmp_path / "lowpass2.comp"
    src.write_text("\n".join(ln[3:] for ln in rst[start:end].split("\n"))
                   + "\n")
    proc = halcompile("--compile", str(src), cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    monkeypatch.setenv("HALSDK_PATH", str(tmp_path))
    hal.loadrt("lowpass2")
    hal.newthread("t", PERIOD)
    hal.addf("lowpass2.0", "t")
    hal.setp("lowpass2.0.in", 8.0)
    trace = hal.run(3, record=["lowpass2.0.out"])
    assert list(trace["lowpass2.0.out"]) == [4.0, 6.0, 7.0]


def test_count_function_string_modparam_and_variable_defaults(
        hal, tmp_path, monkeypatch):
    proc = halcompile("--compile", os.path.join(COMPS, "hccycount.comp"),
                      cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    monkeypatch.setenv("HALSDK_PATH", str(tmp_path))
    hal.loadrt("hccycount", "label=hello")
    # get_count() makes three instances; no count/names parameters
    assert [f.name for f in hal.functions()] == [
        "hccycount.0", "hccycount.1", "hccycount.2"]
    hal.newthread("t", PERIOD, fp=False)
    hal.addf("hccycount.1", "t")
    hal.step(2)
    assert hal.getp("hccycount.1.len") == 5
    assert hal.getp("hccycount.1.ramp") == 0.5
    assert hal.getp("hccycount.1.total") == 3005
    assert hal.getp("hccycount.0.total") == 0       # not run
    hal.unloadrt("hccycount")
    hal.loadrt("hccycount")                         # the default label
    hal.addf("hccycount.2", "t")
    hal.step(1)
    assert hal.getp("hccycount.2.len") == 3
    hal.delf("hccycount.2", "t")
    hal.unloadrt("hccycount")
    with pytest.raises(InvalidError, match="Unknown parameter `count=2'"):
        hal.loadrt("hccycount", "count=2")
