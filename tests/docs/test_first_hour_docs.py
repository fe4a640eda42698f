"""What a newcomer reads first says what is true (issue 22): the README's
install notes, the plot of the quick start, halcmd.rst's list of what
exists, the HAL name of a Cython pin ``in_``, which halrun runs."""

from __future__ import annotations

import re

from helpers import repo_path
from helpers.docblocks import code_blocks

from halcompile.parser import parse


def _readme() -> str:
    return " ".join(repo_path("README.md").read_text(encoding="utf-8")
                    .split())


def _section(text: str, name: str) -> str:
    """The lines of pyproject.toml's ``[name]`` table."""
    return text.split(f"[{name}]\n", 1)[1].split("\n[", 1)[0]


def test_the_readme_says_what_the_machine_needs_and_how_long() -> None:
    text = _readme()
    assert "C compiler" in text and "python3-dev" in text, \
        "what must be on the machine before pip install"
    assert re.search(r"takes .{0,20}minutes", text), \
        "how long the first install compiles"
    assert "pip install -v ." in text, "how to see its progress"


def test_the_readme_says_how_to_work_from_a_checkout() -> None:
    text = _readme()
    assert 'pip install -e ".[test]"' in text
    assert "cannot import name '_core'" in text    # the symptom, named
    conf = repo_path("docs", "conf.py").read_text(encoding="utf-8")
    [build] = re.findall(r"Build: ``(python -m sphinx [^`]+)``", conf)
    assert build in text, "the README gives the docs build of conf.py"
    assert 'pip install -e ".[test]"' in " ".join(conf.split())
    for guide in ("CONTRIBUTING.md", "tests/README.md"):
        words = " ".join(repo_path(guide).read_text().split())
        assert 'pip install -e ".[test]"' in words, guide


def test_the_quick_starts_plot_comes_with_the_default_install() -> None:
    """halsdk-demo's plot is its main output: matplotlib is a dependency
    of the default install, not only of [test]."""
    text = repo_path("pyproject.toml").read_text(encoding="utf-8")
    project = _section(text, "project")
    deps = project.split("dependencies = [", 1)[1].split("]", 1)[0]
    assert '"matplotlib' in deps, deps
    assert "needs matplotlib" not in _readme()


def test_the_readme_says_when_mqtt_tests_are_skipped() -> None:
    text = _readme()
    assert "skipped" in text and "apt-get install mosquitto" in text
    assert "(`CI` set)" in text


def test_halcmd_page_calls_nothing_missing_that_exists() -> None:
    """No paragraph of docs/halcmd.rst says "not yet" about a program
    that is installed (halsampler, halstreamer, halmeter...)."""
    scripts = _section(repo_path("pyproject.toml").read_text(),
                       "project.scripts")
    names = re.findall(r"^([\w-]+) = ", scripts, re.MULTILINE)
    assert {"halsampler", "halstreamer", "halmeter"} <= set(names)
    page = repo_path("docs", "halcmd.rst").read_text(encoding="utf-8")
    for paragraph in re.split(r"\n\s*\n", page):
        if re.search(r"not yet", paragraph, re.IGNORECASE):
            for name in names:
                assert f"``{name}``" not in paragraph, paragraph
    for name in ("halsampler", "halstreamer", "halmeter"):
        assert f"``{name}``" in page


def test_halcmd_page_says_the_prompts_exit_status() -> None:
    page = " ".join(repo_path("docs", "halcmd.rst").read_text().split())
    assert "does not change the exit status" in page


def test_which_halrun_runs_is_said() -> None:
    """With LinuxCNC installed too, PATH picks a halrun; the docs say so
    and name the commands that always reach halsdk's."""
    for text in (_readme(), " ".join(
            repo_path("docs", "halcmd.rst").read_text().split())):
        assert "PATH" in text
        assert "halsdk halrun" in text
        assert "python -m halsdk.halcmd" in text


def test_the_cython_comp_says_the_hal_name_of_in_() -> None:
    """docs/halcompile.rst declares ``pin in float in_``: the page says
    that the HAL pin is ``...in``, as halcompile names it."""
    page = repo_path("docs", "halcompile.rst")
    [comp] = [b for b in code_blocks(page, "none")
              if b.startswith("component lowpass2")]
    parsed = parse(comp, "lowpass2.comp")
    [pin] = [p for p in parsed.pins if p.name == "in_"]
    assert pin.hal_name == "in"
    text = " ".join(page.read_text(encoding="utf-8").split())
    assert f"``lowpass2.N.{pin.hal_name}``" in text
    assert "trailing underscore" in text
    assert f"setp lowpass2.0.{pin.hal_name} " in text
