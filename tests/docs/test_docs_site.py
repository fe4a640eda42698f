"""The documentation site builds without warnings, and its examples work.

The build runs Sphinx with ``-W`` (warnings are errors), so a broken
cross-reference, a bad directive or an autodoc import failure fails this
test.  The component examples of the Cython and C pages are taken from the
pages themselves, built and run, so the documented code cannot rot.
"""

from __future__ import annotations

import glob
import os
import subprocess
import sys
import textwrap

import pytest
from helpers import REPO

import halsdk
from halsdk.build import build_component

ROOT = str(REPO)
DOCS = os.path.join(ROOT, "docs")
PAGES = ["index", "concepts", "tutorial", "components", "halcmd", "runtests",
         "halcompile", "python-api", "cython-components", "c-components",
         "motion", "running", "latency", "machine", "tooltable", "gcode", "drivers",
         "driver-realtime", "driver-sim-io", "driver-cia402", "driver-whb04b",
         "driver-mqtt", "driver-candbc", "driver-mb2hal", "driver-hm2", "homing",
         "kinematics", "architecture", "design", "compat", "benchmarks",
         "reliability", "web"]


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> str:
    out = tmp_path_factory.mktemp("docs-html")
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-j", "2",
         "-b", "html", "-d", str(out / ".doctrees"), DOCS, str(out)],
        capture_output=True, text=True, cwd=str(out))   # not the source tree
    assert proc.returncode == 0, (
        f"sphinx failed ({proc.returncode}):\n{proc.stdout[-3000:]}\n"
        f"{proc.stderr[-6000:]}")
    assert "warning" not in proc.stderr.lower(), proc.stderr
    return str(out)


def _read(site: str, page: str) -> str:
    with open(os.path.join(site, page + ".html"), encoding="utf-8") as f:
        return f.read()


def test_every_page_is_built(site: str) -> None:
    for page in PAGES:
        path = os.path.join(site, page + ".html")
        assert os.path.isfile(path), f"{page}.html is missing"
        assert os.path.getsize(path) > 1000, f"{page}.html is nearly empty"
    index = _read(site, "index")
    for page in PAGES[1:]:
        assert f'href="{page}.html"' in index, f"index does not link {page}"


def test_each_shipped_comp_has_a_generated_page(site: str) -> None:
    """The page of every ``components/*.comp`` and ``drivers/*.comp`` is
    written by halcompile's --document writer and listed on the components
    page."""
    from halcompile.parser import parse_file

    comps = sorted(glob.glob(os.path.join(ROOT, "components", "*.comp"))
                   + glob.glob(os.path.join(ROOT, "drivers", "*.comp")))
    assert len(comps) >= 4
    listing = _read(site, "components")
    for path in comps:
        comp = parse_file(path)
        assert f'href="comp/{comp.name}.html"' in listing, comp.name
        html = _read(site, f"comp/{comp.name}")
        assert f"loadrt {comp.name}" in html
        for item in comp.pins + comp.params:
            shown = item.hal_name.split("#")[0]     # arrays: the start
            where = comp.prefix if comp.option("singleton") else \
                f"{comp.prefix}.N"
            assert f"{where}.{shown}" in html, \
                (comp.name, item.name)
        if comp.description:        # its start, as plain words
            words = " ".join(comp.description.split()[:3])
            if words.isalnum() or words.replace(" ", "").isalnum():
                assert words in " ".join(html.split()), comp.name


def test_api_page_is_generated_from_the_code(site: str) -> None:
    html = _read(site, "python-api")
    # ids that only autodoc can produce, from each documented module
    for anchor in ["halsdk.Hal.loadrt", "halsdk.Hal.step", "halsdk.Hal.net",
                   "halsdk.component", "halsdk.Component.newpin",
                   "halsdk.cleanup", "halsdk.Pin.setp", "halsdk.Signal.sets",
                   "halsdk.Thread", "halsdk.Function",
                   "halsdk.core._core.Component", "halsdk.errors.NotFoundError",
                   "halsdk.types.HalType", "halsdk.testing.TestHal.run",
                   "halsdk.testing.TestHal.set", "halsdk.testing.hal",
                   "halsdk.build.build_component"]:
        assert f'id="{anchor}"' in html, f"no API entry {anchor}"
    # docstring text arrives too
    assert "deterministic" in html.lower() or "simulated" in html.lower()


def test_concepts_page_states_the_rules(site: str) -> None:
    html = _read(site, "concepts")
    for fact in ["127", "timing_every", "first pin gives the signal its value",
                 "keep their last value", "newinst", "SCHED_FIFO"]:
        assert fact in html, f"concepts page lacks {fact!r}"


# ---------------------------------------------------------------- examples

def code_block(page: str, caption: str) -> str:
    """The body of the ``code-block`` with ``:caption: <caption>``."""
    with open(os.path.join(DOCS, page), encoding="utf-8") as f:
        lines = f.read().splitlines()
    for i, line in enumerate(lines):
        if not line.startswith(".. code-block::"):
            continue
        k = i + 1
        options = []
        while k < len(lines) and lines[k].startswith("   :"):
            options.append(lines[k].strip())
            k += 1
        if f":caption: {caption}" not in options:
            continue
        body = []
        for text in lines[k:]:
            if text.strip() and not text.startswith("   "):
                break
            body.append(text)
        return textwrap.dedent("\n".join(body)).strip("\n") + "\n"
    raise AssertionError(f"{page} has no code block captioned {caption}")


def _on_path(monkeypatch: pytest.MonkeyPatch, folder: str) -> None:
    old = os.environ.get("HALSDK_PATH")
    monkeypatch.setenv("HALSDK_PATH",
                       folder + (os.pathsep + old if old else ""))


def test_cython_example_builds_and_works(hal, tmp_path, monkeypatch) -> None:
    source = tmp_path / "clamp.pyx"
    source.write_text(code_block("cython-components.rst", "clamp.pyx"))
    build_component(str(source), out_dir=str(tmp_path / "path"))
    _on_path(monkeypatch, str(tmp_path / "path"))

    assert hal.loadrt("clamp", count=2) == ["clamp"]
    assert [p.name for p in hal.pins("clamp.1.*")] == [
        "clamp.1.clipped", "clamp.1.in", "clamp.1.out", "clamp.1.time"]
    hal.newthread("servo", 1_000_000)
    hal.addf("clamp.0", "servo")
    trace = hal.run(4, inputs={"clamp.0.in": [0.5, 2.0, -3.0, 1.0]},
                    record=["clamp.0.out", "clamp.0.clipped"])
    assert list(trace["clamp.0.out"]) == [0.5, 1.0, -1.0, 1.0]
    assert list(trace["clamp.0.clipped"]) == [False, True, True, False]
    hal.setp("clamp.0.max", 5.0)
    hal.set({"clamp.0.in": 2.0})
    hal.step()
    assert hal.getp("clamp.0.out") == 2.0

    hal.unloadrt("clamp")
    with pytest.raises(halsdk.InvalidError, match="count=0 is not"):
        hal.loadrt("clamp", count=0)        # the example's own check
    assert hal.components("clamp") == []


def test_c_example_builds_and_works(hal, tmp_path, monkeypatch) -> None:
    source = tmp_path / "wsum.c"
    source.write_text(code_block("c-components.rst", "wsum.c"))
    build_component(str(source), out_dir=str(tmp_path / "path"))
    _on_path(monkeypatch, str(tmp_path / "path"))

    assert hal.loadrt("wsum", "count=2") == ["wsum"]
    hal.newthread("servo", 1_000_000)
    hal.addf("wsum.1", "servo")
    hal.set({"wsum.1.a": 2.0, "wsum.1.b": 3.0, "wsum.1.wb": 0.5})
    hal.step()
    assert hal.getp("wsum.1.out") == 3.5
    assert hal.pins("wsum.2.*") == []

    hal.unloadrt("wsum")
    with pytest.raises(halsdk.InvalidError,
                       match="^wsum: count=99 is not 1..32$") as err:
        hal.loadrt("wsum", count=99)        # rtapi_app_main refuses
    assert err.value.status == -22
    assert hal.components("wsum") == []



def test_rules_example_runs(hal) -> None:
    exec(compile(code_block("python-api.rst", "rules.py"), "rules.py",
                 "exec"), {})
