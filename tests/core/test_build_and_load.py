"""Compiled components: three written in Cython and one in C, loaded by
name through the module entry convention and run in threads."""

from __future__ import annotations

import os
import sys
import time

import pytest
from helpers import data_path

import halsdk
from halsdk.build import BuildError, build_component
from halsdk.core import _core
from halsdk.loader import import_component


def test_cython_gate_by_name_in_a_thread(hal):
    assert hal.loadrt("tand2", count=3) == ["tand2"]
    hal.newthread("servo", 1_000_000, fp=False)
    for k in range(3):
        hal.addf(f"tand2.{k}", "servo")
    hal.net("chain", "tand2.0.out", "tand2.1.in0")
    hal.setp("tand2.1.in1", 1)
    table = [(0, 0, False), (0, 1, False), (1, 0, False), (1, 1, True)]
    for a, b, want in table:
        hal.set({"tand2.0.in0": a, "tand2.0.in1": b})
        hal.step(1)
        assert hal.getp("tand2.0.out") is want
        assert hal.getp("tand2.1.out") is want
    names = [p.name for p in hal.pins("tand2.0.*")]
    assert names == ["tand2.0.in0", "tand2.0.in1", "tand2.0.out",
                     "tand2.0.time"]
    assert [p.name for p in hal.params("tand2.0.*")] == [
        "tand2.0.tmax", "tand2.0.tmax-increased"]


def test_c_component_with_modparams(hal):
    assert hal.loadrt("cscale", "count=2 prefix=sc") == ["cscale"]
    hal.newthread("servo", 1_000_000)
    hal.addf("sc.0", "servo")
    hal.addf("sc.1", "servo")
    assert hal.getp("sc.0.gain") == 1.0          # set by rtapi_app_main
    hal.set({"sc.0.in": 2.0, "sc.0.gain": 3.0, "sc.0.offset": -1.0,
             "sc.1.in": 4.0})
    hal.step(10)
    assert hal.getp("sc.0.out") == 5.0
    assert hal.getp("sc.1.out") == 4.0
    assert hal.getp("sc.0.calls") == 10
    module = import_component("cscale")
    assert module.modparams["count"][0] == "i"
    assert module.modparams["limits"][0] == "I"
    assert "scalers" in module.modparams["count"][2]


def test_c_component_runs_in_realtime(hal):
    hal.loadrt("cscale")
    hal.newthread("servo", 500_000)
    hal.addf("cscale.0", "servo")
    hal.setp("cscale.0.in", 1.5)
    hal.start()
    deadline = time.monotonic() + 5
    while hal.getp("cscale.0.calls") < 50 and time.monotonic() < deadline:
        time.sleep(0.01)
    hal.stop()
    assert hal.getp("cscale.0.calls") >= 50
    assert hal.getp("cscale.0.out") == 1.5


def test_c_component_reload_starts_afresh(hal):
    """As in the reference, every load starts from the module's initial
    state: module parameters and other static variables alike."""
    hal.loadrt("cscale", count=3, prefix="x")
    assert len(hal.functions("x.*")) == 3
    assert hal.getp("x.0.loads") == 1
    hal.unloadrt("cscale")
    assert hal.pins("x.*") == [] and hal.components("cscale") == []
    hal.loadrt("cscale")
    assert [f.name for f in hal.functions()] == ["cscale.0"]
    assert hal.getp("cscale.0.loads") == 1


def test_failed_setup_leaves_nothing(hal):
    before = hal.info()["counts"]
    # the module's message, its errno as the class, no doubled name
    with pytest.raises(halsdk.InvalidError,
                       match=r"^cscale: count=100 is not 1\.\.64$"):
        hal.loadrt("cscale", count=100)
    assert hal.info()["counts"] == before
    with pytest.raises(halsdk.InvalidError, match="count=0"):
        hal.loadrt("tand2", count=0)
    assert hal.components() == []
    hal.loadrt("cscale")          # and it can be loaded afterwards
    hal.check()


def test_modparam_errors(hal):
    with pytest.raises(halsdk.InvalidError, match="Unknown parameter `cnt=2'"):
        hal.loadrt("tand2", cnt=2)
    with pytest.raises(halsdk.InvalidError, match="not an integer"):
        hal.loadrt("tand2 count=two")
    with pytest.raises(halsdk.InvalidError, match="not name=value"):
        hal.loadrt("tand2 count")
    with pytest.raises(halsdk.NotFoundError, match="'nosuchcomp' not found"):
        hal.loadrt("nosuchcomp")
    with pytest.raises(halsdk.InvalidError, match="module name"):
        hal.loadrt("../etc")
    with pytest.raises(halsdk.ExistsError, match="already loaded"):
        hal.loadrt("tand2")
        hal.loadrt("tand2")
    assert hal.components() == [hal.component("tand2")]


def test_64_bit_counter_and_instances(hal):
    hal.loadrt("tcounter", names="c1")
    hal.newthread("servo", 1_000_000, fp=False)
    hal.addf("c1", "servo")
    hal.setp("c1.step", 1 << 40)
    for level in (1, 0, 1, 0, 1):
        hal.setp("c1.in", level)
        hal.step(1)
    assert hal.getp("c1.count") == 3 << 40
    assert hal.getp("c1.cycles") == 5
    hal.newinst("tcounter", "extra", step=7)
    assert hal.instances()[0].name == "extra"
    assert hal.instances()[0].owner == "tcounter"
    hal.addf("extra", "servo")
    hal.setp("extra.in", 1)
    hal.step(1)
    assert hal.getp("extra.count") == 7
    hal.delinst("extra")
    assert hal.pins("extra.*") == [] and hal.functions("extra") == []
    assert hal.thread("servo").functions == ["c1"]
    assert hal.module("tcounter").deleted == ["extra"]
    hal.step(1)                  # the thread runs on without it
    with pytest.raises(halsdk.NotPermittedError, match="instances"):
        hal.loadrt("tand2")
        hal.newinst("tand2", "x")
    with pytest.raises(halsdk.NotFoundError):
        hal.delinst("extra")
    hal.check()


def test_unload_all(hal):
    hal.loadrt("tand2")
    hal.loadrt("tlowpass")
    hal.newthread("servo", 1_000_000)
    hal.addf("tand2.0", "servo")
    hal.unloadrt("all")
    assert hal.components() == [hal.component("__servo")]
    assert hal.thread("servo").functions == []


def test_build_errors_name_the_file(tmp_path):
    bad = tmp_path / "broken.pyx"
    bad.write_text("def setup(:\n")
    with pytest.raises(BuildError, match="broken.pyx"):
        build_component(str(bad), out_dir=str(tmp_path / "out"))
    cbad = tmp_path / "cbroken.c"
    cbad.write_text('#include "hal.h"\nint rtapi_app_main(void) '
                    '{ return undefined_thing; }\n')
    with pytest.raises(BuildError, match="undefined_thing"):
        build_component(str(cbad), out_dir=str(tmp_path / "out"))
    with pytest.raises(BuildError, match="valid module name"):
        build_component(str(bad), name="bad-name")


def test_build_is_cached(tmp_path):
    src = str(data_path("components", "tand2.pyx"))
    first = build_component(src)
    mtime = os.path.getmtime(first)
    assert build_component(src) == first
    assert os.path.getmtime(first) == mtime


def _fresh_cache(tmp_path, monkeypatch) -> str:
    cache = tmp_path / "cache"
    monkeypatch.setenv("HALSDK_CACHE", str(cache))
    return str(cache)


def test_build_calls_compiler_and_linker_directly(tmp_path, monkeypatch):
    """A cold C build runs only the sysconfig compiler (once per file,
    with the C entry and -DHALSDK_API_EXTERN) and LDSHARED, no Python
    subprocess; the module lands in the cache under EXT_SUFFIX."""
    import subprocess
    import sysconfig

    from halsdk import build

    _fresh_cache(tmp_path, monkeypatch)
    src = tmp_path / "cdirect.c"
    src.write_text('#include "hal.h"\n'
                   'int rtapi_app_main(void) { return 0; }\n'
                   'void rtapi_app_exit(void) {}\n')
    seen: list[list[str]] = []
    real = subprocess.Popen

    def spy(cmd, *args, **kwargs):
        seen.append(list(cmd))
        return real(cmd, *args, **kwargs)

    monkeypatch.setattr(subprocess, "Popen", spy)
    path = build_component(str(src))
    assert path.endswith("cdirect" + sysconfig.get_config_var("EXT_SUFFIX"))
    assert os.path.isfile(path)
    compiler, linker = build.toolchain()
    assert compiler[0] == sysconfig.get_config_var("CC").split()[0]
    assert sysconfig.get_config_var("CCSHARED").split()[0] in compiler
    assert linker == sysconfig.get_config_var("LDSHARED").split()
    assert all(sys.executable not in cmd for cmd in seen)
    compiles = [c for c in seen if "-c" in c]
    assert sorted(c[c.index("-c") + 1] for c in compiles) == sorted(
        [build.C_ENTRY, str(src)])
    assert all("-DHALSDK_API_EXTERN=1" in c and
               "-DHALSDK_MODULE_NAME=cdirect" in c for c in compiles)
    links = [c for c in seen if "-c" not in c]
    assert len(links) == 1 and links[0][:len(linker)] == linker
    # cached: no process at all the second time
    seen.clear()
    assert build_component(str(src)) == path
    assert seen == []


def test_build_follows_cflags_environment(tmp_path, monkeypatch):
    """CFLAGS from the environment reach the compiler (as with
    setuptools) and are part of the cache key."""
    _fresh_cache(tmp_path, monkeypatch)
    src = tmp_path / "cflagged.c"
    src.write_text('#include "hal.h"\n'
                   '#if HALSDK_TEST_FLAG != 42\n'
                   '#error flag_not_seen\n'
                   '#endif\n'
                   'int rtapi_app_main(void) { return 0; }\n'
                   'void rtapi_app_exit(void) {}\n')
    monkeypatch.delenv("CFLAGS", raising=False)
    with pytest.raises(BuildError, match="flag_not_seen"):
        build_component(str(src))
    monkeypatch.setenv("CFLAGS", "-DHALSDK_TEST_FLAG=42")
    assert os.path.isfile(build_component(str(src)))


def test_failed_build_leaves_nothing(tmp_path, monkeypatch):
    """A failed compile or link installs nothing: no module in out_dir,
    no cache entry, no half-built folder."""
    cache = _fresh_cache(tmp_path, monkeypatch)
    bad = tmp_path / "nolink.c"
    # compiles, but the link fails (the symbol exists nowhere)
    bad.write_text('#include "hal.h"\n'
                   'extern int halsdk_no_such_symbol_anywhere(void);\n'
                   'int rtapi_app_main(void) '
                   '{ return halsdk_no_such_symbol_anywhere(); }\n'
                   'void rtapi_app_exit(void) {}\n')
    out = tmp_path / "out"
    monkeypatch.setenv("LDFLAGS", "-Wl,--no-undefined")
    with pytest.raises(BuildError, match="nolink.c.*\n(.|\n)*"
                       "halsdk_no_such_symbol_anywhere"):
        build_component(str(bad), out_dir=str(out))
    assert not out.exists() or os.listdir(out) == []
    assert not os.path.isdir(cache) or os.listdir(cache) == []
    syntax = tmp_path / "nocompile.c"
    syntax.write_text("int rtapi_app_main(void) { return 0 }\n")
    with pytest.raises(BuildError, match="nocompile.c:1:"):
        build_component(str(syntax), out_dir=str(out))
    assert not os.path.isdir(cache) or os.listdir(cache) == []


def test_cython_build_in_process_names_the_source(tmp_path, monkeypatch):
    """Cython runs in this process: its messages name the caller's file
    and line, and a good module cimports halsdk/hal.pxd and loads."""
    _fresh_cache(tmp_path, monkeypatch)
    bad = tmp_path / "cybad.pyx"
    bad.write_text("x = 1\ncdef int y = undefined_name_here\n")
    with pytest.raises(BuildError) as info:
        build_component(str(bad))
    assert f"{bad}:2:" in str(info.value)
    assert "halsdk-build-" not in str(info.value)
    src = str(data_path("components", "tand2.pyx"))
    path = build_component(src, name="tand2copy")
    assert os.path.basename(path).startswith("tand2copy.")
    with open(path, "rb") as f:
        assert b"PyInit_tand2copy" in f.read()


def test_component_from_entry_point_group(hal, tmp_path, monkeypatch):
    """Third-party packages ship components under the entry-point group
    'halsdk.components'."""
    pkg = tmp_path / "thirdparty_comp"
    pkg.mkdir()
    (pkg / "__init__.py").write_text(
        "import halsdk\n"
        "modparams = {'gain': (float, 1.0, 'gain')}\n"
        "made = []\n"
        "def setup(gain=1.0):\n"
        "    from halsdk.core import _core\n"
        "    cid = _core.comp_new('tpy', _core.COMP_RT)\n"
        "    made.append(gain)\n"
        "    _core.comp_ready(cid)\n")
    dist = tmp_path / "thirdparty_comp-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Name: thirdparty-comp\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(
        "[halsdk.components]\ntpy = thirdparty_comp\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert hal.loadrt("tpy", gain="2.5") == ["tpy"]
    assert sys.modules["thirdparty_comp"].made == [2.5]
    assert hal.component("tpy").realtime
    _core_items = [c.name for c in hal.components()]
    assert "tpy" in _core_items
    hal.unloadrt("tpy")
    assert _core.find("component", "tpy") is None


@pytest.mark.parametrize("text,value", [("10", 10), ("0x1f", 31),
                                        ("010", 8), ("-0x10", -16),
                                        ("0", 0), ("+7", 7)])
def test_load_line_integers_read_as_c_does(text, value):
    assert _core.c_integer(text) == value
