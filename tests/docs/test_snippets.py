"""Every Python snippet of README.md and docs/ runs (issue 22).

The collector (``helpers.snippets``) finds each ``.. code-block:: python``
and each fenced ``python`` block; the ``snippet`` comments above it say
how it runs (see that module).  A snippet runs as a script of its own, in
a new Python, in an empty folder with a private HOME and HAL instance and
without the suite's HALSDK_PATH, the way a reader who copies it runs it.
The files it needs are made here the way the pages tell the reader to
make them.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest
from helpers import REPO, find_test_module, repo_path
from helpers.docblocks import code_blocks
from helpers.running_machine import running_machine
from helpers.snippets import (
    Snippet,
    md_snippets,
    pages,
    rst_snippets,
    snippets,
    unmarked_python_blocks,
)

ALL = snippets(REPO)


def _captioned(page: str, caption: str) -> str:
    """The code block of docs/PAGE with ``:caption: CAPTION``."""
    lines = repo_path("docs", page).read_text(encoding="utf-8").splitlines()
    for n, line in enumerate(lines):
        if line.startswith(".. code-block::") and \
                lines[n + 1].strip() == f":caption: {caption}":
            body = []
            for text in lines[n + 2:]:
                if text.strip() and not text.startswith("   "):
                    break
                body.append(text)
            return textwrap.dedent("\n".join(body)).strip() + "\n"
    raise AssertionError(f"docs/{page} has no block captioned {caption}")


# ------------------------------------------------ what the pages say to make

def _clamp_pyx(cwd: Path, env: dict[str, str]) -> None:
    """The Cython page's clamp.pyx, saved as the page shows it."""
    (cwd / "clamp.pyx").write_text(
        _captioned("cython-components.rst", "clamp.pyx"))


def _clamp(cwd: Path, env: dict[str, str]) -> None:
    """clamp.pyx built and installed as the Cython page does it
    (``build_component(..., out_dir=user_component_dir())``)."""
    _clamp_pyx(cwd, env)
    proc = subprocess.run(
        [sys.executable, "-c",
         "from halsdk.build import build_component\n"
         "from halsdk.loader import user_component_dir\n"
         "build_component('clamp.pyx', out_dir=user_component_dir())\n"],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _wsum_c(cwd: Path, env: dict[str, str]) -> None:
    """The C page's wsum.c, saved as the page shows it."""
    (cwd / "wsum.c").write_text(_captioned("c-components.rst", "wsum.c"))


def _mill(cwd: Path, env: dict[str, str]) -> None:
    """The demo mill's files in the current folder (``cp
    halsdk/demo/mill/* .``, as the pages say)."""
    for path in repo_path("halsdk", "demo", "mill").iterdir():
        if path.is_file():
            shutil.copy(path, cwd / path.name)


SETUPS: dict[str, Callable[[Path, dict[str, str]], None]] = {
    "clamp.pyx": _clamp_pyx, "clamp": _clamp, "wsum.c": _wsum_c,
    "mill": _mill,
}

#: ``needs running-demo``: the snippet runs while ``halsdk run`` runs the
#: demo mill (a copy of halsdk/demo/mill), as the tutorial starts it
RUNNING = "running-demo"

#: ``needs hal``: the snippet runs inside ``with halsdk.Hal() as hal:``,
#: the instance its page has set up before it
HAL_PRELUDE = "import halsdk\n\nwith halsdk.Hal() as hal:\n"


# ------------------------------------------------ the collector's rules

def test_the_collector_sees_the_pages() -> None:
    assert repo_path("README.md") in pages(REPO)
    assert repo_path("docs", "index.rst") in pages(REPO)
    assert len(ALL) >= 25
    assert any(s.page.name == "README.md" for s in ALL)


@pytest.mark.parametrize("page", pages(REPO), ids=lambda p: p.name)
def test_no_python_block_escapes_the_collector(page: Path) -> None:
    assert unmarked_python_blocks(page) == [], (
        f"{page.name}: write Python blocks as '.. code-block:: python' "
        "(or a ```python fence) so that the suite runs them")


def test_marks_are_understood(tmp_path: Path) -> None:
    page = tmp_path / "p.rst"
    page.write_text("Text\n\n.. snippet: needs clamp\n.. snippet: prints 1.0"
                    "\n\n.. code-block:: python\n\n   print(1.0)\n\nEnd\n\n"
                    ".. code-block:: python\n\n   x = 1\n")
    first, second = rst_snippets(page)
    assert first.marks == {"needs": "clamp", "prints": "1.0"}
    assert first.code == "print(1.0)\n" and first.line == 6
    assert second.marks == {}
    md = tmp_path / "p.md"
    md.write_text("<!-- snippet: not-run needs a lathe -->\n```python\n"
                  "x = 1\n```\n")
    [only] = md_snippets(md)
    assert only.marks == {"not-run": "needs a lathe"}
    page.write_text(".. snippet: perhaps\n\n.. code-block:: python\n\n"
                    "   x = 1\n")
    with pytest.raises(ValueError, match="unknown snippet mark 'perhaps'"):
        rst_snippets(page)


def test_every_mark_is_valid() -> None:
    for s in ALL:
        for kind in ("fragment", "not-run"):
            if kind in s.marks:
                assert len(s.marks[kind].split()) >= 3, \
                    f"{s.id}: '{kind}' needs its reason"
        for name in s.marks.get("needs", "").split():
            assert name in ("hal", RUNNING) or name in SETUPS, \
                f"{s.id}: no setup {name!r}"
        if "continues" in s.marks:
            before = [o for o in ALL if o.page == s.page and o.line < s.line]
            assert before, f"{s.id}: continues nothing"


# ------------------------------------------------ running them

def _chain(s: Snippet) -> list[Snippet]:
    """The snippet and those it continues, in page order."""
    same = [o for o in ALL if o.page == s.page]
    k = same.index(s)
    chain = [s]
    while "continues" in chain[0].marks:
        k -= 1
        chain.insert(0, same[k])
    return chain


def _continued(s: Snippet) -> bool:
    same = [o for o in ALL if o.page == s.page]
    k = same.index(s)
    return k + 1 < len(same) and "continues" in same[k + 1].marks


def _runs(s: Snippet) -> bool:
    return not ({"fragment", "not-run", "tested-by"} & set(s.marks)) \
        and not _continued(s)


RUN = [s for s in ALL if _runs(s)]
CHECKED = [s for s in ALL if not _runs(s)]


@pytest.mark.parametrize("s", CHECKED, ids=lambda s: s.id)
def test_a_snippet_that_does_not_run_alone_compiles(s: Snippet) -> None:
    if "tested-by" in s.marks:
        where, _, test = s.marks["tested-by"].partition("::")
        module = find_test_module(Path(where).name)
        text = module.read_text(encoding="utf-8")
        assert f"def {test}(" in text, f"{s.id}: no {test} in {where}"
        assert s.page.name in text, f"{s.id}: {where} does not read it"
    if "fragment" in s.marks and "needs" in s.marks:
        pytest.fail(f"{s.id}: a fragment does not run; 'needs' is moot")
    compile(s.code, s.id, "exec")


def _run_bounded(args: list[str], cwd: Path, env: dict[str, str],
                 bound: float = 300) -> subprocess.CompletedProcess:
    """Run ``args``; a snippet that does not end within ``bound`` seconds
    (a loop meant for a real machine) is ended with SIGTERM, so that it
    removes its HAL instance, and the test fails."""
    with subprocess.Popen(args, cwd=cwd, env=env, text=True,
                          stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE) as proc:
        try:
            out, err = proc.communicate(timeout=bound)
        except subprocess.TimeoutExpired:
            proc.terminate()
            try:
                out, err = proc.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                out, err = proc.communicate()
            pytest.fail(f"{' '.join(args)} did not end within {bound} s "
                        f"(a loop? mark it not-run):\n{out}\n{err}")
    return subprocess.CompletedProcess(args, proc.returncode, out, err)


def test_a_snippet_that_never_ends_is_ended(tmp_path: Path) -> None:
    code = ("import signal, sys, time\n"
            "signal.signal(signal.SIGTERM, lambda *a: sys.exit(3))\n"
            "print('looping', flush=True)\n"
            "time.sleep(60)\n")
    with pytest.raises(pytest.fail.Exception, match="did not end within"):
        _run_bounded([sys.executable, "-c", code], tmp_path,
                     dict(os.environ), bound=2)


@pytest.mark.slow
@pytest.mark.parametrize("s", RUN, ids=lambda s: s.id)
def test_the_snippet_runs(s: Snippet, tmp_path: Path) -> None:
    chain = _chain(s)
    cwd = tmp_path / "work"
    home = tmp_path / "home"
    cwd.mkdir()
    home.mkdir()
    instance = f"snip-{os.getpid()}-{s.page.stem}-{s.line}"
    env = dict(os.environ, HALSDK_INSTANCE=instance, HOME=str(home),
               XDG_DATA_HOME=str(home / ".local" / "share"),
               MPLBACKEND="Agg")
    env.pop("HALSDK_PATH", None)        # a reader's machine has none
    needs = [n for c in chain for n in c.marks.get("needs", "").split()]
    for name in needs:
        if name not in ("hal", RUNNING):
            SETUPS[name](cwd, env)
    code = "\n".join(c.code for c in chain)
    if "hal" in needs:
        code = HAL_PRELUDE + textwrap.indent(code, "    ")
    (cwd / "snippet.py").write_text(code)
    if RUNNING in needs:
        demo = tmp_path / "demo"
        shutil.copytree(repo_path("halsdk", "demo", "mill"), demo)
        with running_machine(demo, ini=demo / "mill.ini") as machine:
            env["HALSDK_INSTANCE"] = instance = machine.instance
            proc = _run_bounded([sys.executable, "snippet.py"], cwd, env)
    else:
        proc = _run_bounded([sys.executable, "snippet.py"], cwd, env)
    assert proc.returncode == 0, (
        f"{s.id} failed ({proc.returncode}):\n{code}\n{proc.stdout}\n"
        f"{proc.stderr[-4000:]}")
    assert "Traceback" not in proc.stderr, proc.stderr
    if "prints" in s.marks:
        assert proc.stdout.strip() == s.marks["prints"], (s.id, proc.stdout)
    left = [n for n in os.listdir("/dev/shm") if instance in n]
    assert left == [], f"{s.id} left {left}"


def test_the_readme_taste_prints_what_it_says() -> None:
    """The README's first snippet states its output, and it is not the
    0.0 of an unconnected pin."""
    [taste] = [s for s in ALL if s.page.name == "README.md"][:1]
    assert _runs(taste) and "prints" in taste.marks
    assert float(taste.marks["prints"]) != 0.0
    index = [s for s in ALL if s.page.name == "index.rst"][0]
    assert _runs(index) and "needs" not in index.marks, \
        "the front page's snippet needs nothing built first"


def _docstring_example(doc: str) -> str:
    """The first literal block (after ``::``) of a docstring."""
    start = doc.index("::\n") + 3
    body = []
    for line in doc[start:].splitlines():
        if line.strip() and not line.startswith("    "):
            break
        body.append(line)
    return textwrap.dedent("\n".join(body)).strip() + "\n"


def test_the_packages_docstring_example_runs(tmp_path: Path) -> None:
    """``help(halsdk)`` shows an example: it uses shipped components and
    prints what its comment says."""
    import halsdk
    code = _docstring_example(halsdk.__doc__ or "")
    (tmp_path / "example.py").write_text(code)
    env = dict(os.environ, HALSDK_INSTANCE=f"snip-{os.getpid()}-pkgdoc")
    env.pop("HALSDK_PATH", None)
    proc = _run_bounded([sys.executable, "example.py"], tmp_path, env)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "3.0", proc.stdout


def test_captioned_examples_are_still_there() -> None:
    """The setups read these captions; the pages keep them."""
    assert "cdef" in _captioned("cython-components.rst", "clamp.pyx")
    assert "rtapi_app_main" in _captioned("c-components.rst", "wsum.c")
    assert code_blocks(repo_path("docs", "python-api.rst"), "python")


# ------------------------------------------------ examples that are pytest files

def _pytest(cwd: Path, tmp_path: Path) -> subprocess.CompletedProcess:
    """pytest in ``cwd`` as a reader runs it: a private HOME, no
    HALSDK_PATH, halsdk's plugin from the installed entry point."""
    home = tmp_path / "home"
    home.mkdir(exist_ok=True)
    env = dict(os.environ, HOME=str(home),
               XDG_DATA_HOME=str(home / ".local" / "share"))
    env.pop("HALSDK_PATH", None)
    env.pop("HALSDK_INSTANCE", None)
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
         "-W", "error::pytest.PytestUnknownMarkWarning", "."],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


@pytest.mark.slow
def test_the_cython_pages_pytest_example_passes(tmp_path: Path) -> None:
    """docs/cython-components.rst: its conftest.py and test_clamp.py,
    split where the page's comments say, with the page's clamp.pyx."""
    [block] = [s for s in ALL if s.page.name == "cython-components.rst"
               and s.code.startswith("# conftest.py")]
    conftest, _, test = block.code.partition("# test_clamp.py\n")
    cwd = tmp_path / "project"
    cwd.mkdir()
    (cwd / "conftest.py").write_text(conftest)
    (cwd / "test_clamp.py").write_text(test)
    _clamp_pyx(cwd, {})
    proc = _pytest(cwd, tmp_path)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    assert "1 passed" in proc.stdout, proc.stdout


@pytest.mark.slow
def test_the_pytest_plugins_example_passes(tmp_path: Path) -> None:
    """The example at the top of halsdk.testing's docstring (the plugin's
    page in the API docs) runs as a test file of a new project."""
    import halsdk.testing
    code = _docstring_example(halsdk.testing.__doc__ or "")
    assert "def test_" in code
    cwd = tmp_path / "project"
    cwd.mkdir()
    (cwd / "test_example.py").write_text(code)
    proc = _pytest(cwd, tmp_path)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    assert "1 passed" in proc.stdout, proc.stdout
