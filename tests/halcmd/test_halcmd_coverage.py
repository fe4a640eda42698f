"""Coverage of the halcmd(1) and halrun(1) manuals by the tests.

Every command, command form and option of the two reference manuals is
listed below as data.  Each must be used by at least one HAL file of the
differential corpus (``tests/data/halfiles/*.hal`` and
``tests/data/streams/*.hal`` that have a golden ``.out``), or be exercised
by a named test (whose source must contain the given text), or be listed
in ``UNSUPPORTED`` with the reason.  The test fails when a golden or a
named test that was the only one to cover an item goes away.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path
from typing import Callable

import pytest
from helpers import data_path, find_test_module

from halsdk.halcmd import logical_lines
from halsdk.halcmd.commands import ARG_COUNTS

CORPUS_DIRS = (data_path("halfiles"), data_path("streams"))

# Every command of halcmd(1), plus the ones of the issue
# (echo/unecho/quit/exit/newinst/delinst/setexact_for_test_suite_only).
COMMANDS = [
    "loadrt", "unloadrt", "loadusr", "waitusr", "unloadusr", "unload",
    "newsig", "delsig", "sets", "stype", "gets", "linkps", "linksp",
    "linkpp", "net", "unlinkp", "setp", "ptype", "getp", "addf", "delf",
    "start", "stop", "show", "save", "source", "alias", "unalias", "list",
    "print", "lock", "unlock", "status", "debug", "help", "echo", "unecho",
    "quit", "exit", "newinst", "delinst", "setexact_for_test_suite_only",
]

# Forms of the commands named in the manual: (command, argument words).
# An argument "*" matches any word; the number of words must match
# exactly, except that a trailing "..." allows more.
FORMS = [
    ("loadusr", "-w", "..."), ("loadusr", "-w", "-i", "..."),
    ("loadusr", "-W", "..."), ("loadusr", "-Wn", "..."),
    ("unloadrt", "all"), ("unload", "all"), ("unloadusr", "all"),
    ("linkps", "*", "=>", "*"), ("linkps", "*", "*"),
    ("linksp", "*", "=>", "*"), ("linksp", "*", "*"),
    ("linkpp", "*", "*"),
    ("net", "*", "*", "=>", "*", "..."), ("net", "*", "*", "<=", "*"),
    ("net", "*", "*", "<=>", "*"), ("net", "*", "*", "*", "*", "..."),
    ("addf", "*", "*"), ("addf", "*", "*", "*"),
    ("delf", "*", "*"),
    ("show",), ("show", "*", "*"),
    ("save",), ("save", "*", "*"),
    ("print",), ("print", "*"),
    ("lock",), ("unlock",),
    ("status",),
    ("help",), ("help", "*"),
    ("debug", "*"),
    ("list", "*", "*"), ("list", "*", "*", "*", "..."),
]
for _item in ("comp", "pin", "sig", "param", "funct", "thread", "alias",
              "all"):
    FORMS.append(("show", _item, "..."))
for _item in ("comp", "alias", "sig", "signal", "sigu", "link", "linka",
              "net", "neta", "netl", "netla", "netal", "param", "parameter",
              "thread", "unconnectedinpins", "allu", "all"):
    FORMS.append(("save", _item, "..."))
for _item in ("comp", "pin", "sig", "param", "funct", "thread"):
    FORMS.append(("list", _item, "..."))
for _item in ("pin", "sig", "param"):
    FORMS.append(("list", _item, "-t*", "..."))
for _item in ("all", "tune", "none"):
    FORMS.append(("lock", _item))
for _item in ("all", "tune"):
    FORMS.append(("unlock", _item))
for _item in ("lock", "mem", "all"):
    FORMS.append(("status", _item))
for _item in ("pin", "param"):
    FORMS.append(("alias", _item, "*", "*"))
    FORMS.append(("unalias", _item, "*"))

# Language features of the manual (SUBSTITUTION, LINE CONTINUATION,
# comments, ``name = value``), as patterns over the text of a HAL file.
LANGUAGE = {
    "comment": re.compile(r"^\s*#|\s#", re.M),
    "line continuation": re.compile(r"\\\n"),
    "$ENVVAR": re.compile(r"\$[A-Za-z_]\w*"),
    "$(ENVVAR)": re.compile(r"\$\([A-Za-z_]\w*\)"),
    "[SECTION]VAR": re.compile(r"\[\w+\]\w"),
    "[SECTION](VAR)": re.compile(r"\[\w+\]\(\w+\)"),
    "name = value": re.compile(r"^\s*[\w.-]+\s*=\s*\S", re.M),
}

# Options of halcmd(1) and halrun(1).  Options given on a ``# options:``
# line of a golden are covered by it.
HALCMD_OPTIONS = ["-I", "-f", "-i", "-k", "-q", "-Q", "-s", "-R", "-v",
                  "-V", "-h", "-e"]
HALRUN_OPTIONS = ["-h", "-I", "-T", "-U", "-f", "halcmd_opts", "filename"]

# Items exercised by named tests: item -> (file, test function, text the
# test's source must contain).
NAMED = {
    "command waitusr": ("test_halcmd_corpus.py",
                        "test_waitusr_waits_for_exit", "waitusr wcomp"),
    "command newinst": ("test_halcmd_corpus.py", "test_newinst_delinst",
                        "newinst tcounter"),
    "command delinst": ("test_halcmd_corpus.py", "test_newinst_delinst",
                        "delinst extra"),
    "command unloadusr": ("test_halcmd.py",
                          "test_loadusr_waits_for_ready_and_unloadusr",
                          "unloadusr ucomp"),
    "form loadusr -W ...": ("test_halcmd.py",
                            "test_loadusr_waits_for_ready_and_unloadusr",
                            "loadusr -W {"),
    "form loadusr -Wn ...": ("test_halcmd.py",
                             "test_loadusr_waits_for_ready_and_unloadusr",
                             "loadusr -Wn ucomp"),
    "form unloadusr all": ("test_halcmd_corpus.py",
                           "test_unload_all_and_unloadusr_all",
                           "unloadusr all"),
    "form unload all": ("test_halcmd_corpus.py",
                        "test_unload_all_and_unloadusr_all", "unload all"),
    "form status": ("test_halcmd_corpus.py", "test_status_all_and_default",
                    'run_line("status")'),
    "form status mem": ("test_halcmd.py", "test_status_mem_counts",
                        "status mem"),
    "form status all": ("test_halcmd_corpus.py",
                        "test_status_all_and_default", "status all"),
    "form help": ("test_halcmd.py", "test_help_lists_every_command",
                  'run_line("help")'),
    "halcmd -I": ("test_halcmd.py", "test_halrun_interactive_and_cleanup",
                  '"-I"'),
    "halcmd -R": ("test_halcmd_corpus.py", "test_release_mutex_option",
                  '"-R"'),
    "halcmd -V": ("test_halcmd_corpus.py", "test_very_verbose_option",
                  '"-V"'),
    "halcmd -h": ("test_halcmd_corpus.py", "test_help_options", '"-h"'),
    "halrun -h": ("test_halcmd_corpus.py", "test_help_options",
                  '_halrun(["-h"]'),
    "halrun -I": ("test_halcmd.py", "test_halrun_interactive_and_cleanup",
                  '"-I"'),
    "halrun -U": ("test_halcmd.py", "test_halrun_interactive_and_cleanup",
                  '"-U"'),
    "halrun -T": ("test_halcmd.py", "test_tcl_is_not_supported", '"-T"'),
    "halrun filename": ("test_halcmd.py",
                        "test_halrun_interactive_and_cleanup",
                        '"halrun", "i.hal"'),
    "halcmd -f (stdin)": ("test_halcmd.py", "test_halcmd_reads_stdin",
                          '"-f"]'),
    "halcmd COMMAND ARGS": ("test_halcmd.py",
                            "test_halcmd_attaches_to_running_instance",
                            '"halcmd", "loadrt", "and2"'),
    "save ITEM FILE then source": ("test_halcmd_corpus.py",
                                   "test_save_to_file_then_source",
                                   "source {tmp_path}/n.hal"),
}

# Items of the manuals that halsdk does not provide, with the reason.
# They must not be covered elsewhere (so the list stays true).
UNSUPPORTED = {
    "halrun -T (interactive haltcl)":
        "no Tcl interpreter in halsdk; halrun -T prints 'not supported' "
        "and fails (test_halcmd.py::test_tcl_is_not_supported)",
    "halrun FILE.tcl":
        "Tcl HAL files need haltcl, which halsdk does not provide",
    "halrun -f FILE.tcl with -i INI (Tcl options)":
        "same reason: only .hal files are run",
}

# Extra items a test only can cover: not in a golden by nature.
EXTRA_ITEMS = ["halcmd -f (stdin)", "halcmd COMMAND ARGS",
               "save ITEM FILE then source"]


# ---------------------------------------------------------------- corpus

class Corpus:
    """The commands, options and texts of the golden HAL files."""

    def __init__(self) -> None:
        self.files: list[Path] = []
        self.lines: list[list[str]] = []
        self.options: set[str] = set()
        self.texts: list[str] = []
        for folder in CORPUS_DIRS:
            for path in sorted(folder.glob("*.hal")):
                if path.with_suffix(".out").exists():
                    self._add(path)

    def _add(self, path: Path) -> None:
        self.files.append(path)
        text = path.read_text()
        self.texts.append(text)
        first = text.splitlines()[:1]
        if first and first[0].startswith("# options:"):
            self.options.update(first[0].split(":", 1)[1].split())
        for _, line in logical_lines(text.splitlines(True)):
            words = line.split("#", 1)[0].split()
            if words:
                self.lines.append(words)

    def has_command(self, name: str) -> bool:
        return any(w[0] == name for w in self.lines)

    def has_form(self, form: tuple[str, ...]) -> bool:
        return any(_form_matches(form, w) for w in self.lines)

    def has_text(self, pattern: re.Pattern) -> bool:
        return any(pattern.search(t) for t in self.texts)


def _word_matches(pattern: str, word: str) -> bool:
    if pattern == "*":
        return True
    if pattern.endswith("*"):
        return word.startswith(pattern[:-1])
    return word == pattern


def _form_matches(form: tuple[str, ...], words: list[str]) -> bool:
    more = form[-1] == "..."
    fixed = form[:-1] if more else form
    if len(words) < len(fixed) or (not more and len(words) != len(fixed)):
        return False
    return all(_word_matches(p, w) for p, w in zip(fixed, words))


@pytest.fixture(scope="module")
def corpus() -> Corpus:
    return Corpus()


def _test_source(file: str, func: str) -> str:
    """Source text of test function ``func`` of ``tests/file``."""
    text = find_test_module(file).read_text()
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.FunctionDef) and node.name == func:
            return ast.get_source_segment(text, node) or ""
    raise AssertionError(f"{file}::{func} does not exist")


def _named_covers(item: str) -> bool:
    if item not in NAMED:
        return False
    file, func, needle = NAMED[item]
    assert needle in _test_source(file, func), (
        f"{file}::{func} no longer contains {needle!r} (for {item})")
    return True


def _items() -> list[tuple[str, Callable[[Corpus], bool]]]:
    items: list[tuple[str, Callable[[Corpus], bool]]] = []
    for cmd in COMMANDS:
        items.append((f"command {cmd}",
                      lambda c, cmd=cmd: c.has_command(cmd)))
    for form in FORMS:
        items.append((f"form {' '.join(form)}",
                      lambda c, form=form: c.has_form(form)))
    for feature, pattern in LANGUAGE.items():
        items.append((f"language {feature}",
                      lambda c, p=pattern: c.has_text(p)))
    for opt in HALCMD_OPTIONS:
        if opt == "-f":     # every golden runs with -f FILE
            items.append(("halcmd -f", lambda c: bool(c.files)))
        else:
            items.append((f"halcmd {opt}", lambda c, o=opt: o in c.options))
    for opt in HALRUN_OPTIONS:
        if opt == "-f":
            items.append(("halrun -f", lambda c: bool(c.files)))
        elif opt == "halcmd_opts":
            items.append(("halrun halcmd_opts", lambda c: bool(c.options)))
        else:
            items.append((f"halrun {opt}", lambda c: False))
    for item in EXTRA_ITEMS:
        items.append((item, lambda c: False))
    return items


ITEMS = _items()


# ---------------------------------------------------------------- tests

def test_corpus_size(corpus: Corpus):
    halfiles = [p for p in corpus.files if p.parent.name == "halfiles"]
    assert len(halfiles) >= 65
    assert len(corpus.files) - len(halfiles) >= 4     # streams goldens


@pytest.mark.parametrize("item, in_corpus", ITEMS, ids=[i for i, _ in ITEMS])
def test_item_is_covered(item: str, in_corpus, corpus: Corpus):
    assert in_corpus(corpus) or _named_covers(item), (
        f"'{item}' of the halcmd/halrun manuals has no golden and no named "
        "test")


def test_named_tests_exist():
    for item, (file, func, needle) in NAMED.items():
        assert needle in _test_source(file, func), item


def test_commands_list_is_complete():
    """Every command the executor knows is in the data above."""
    assert set(ARG_COUNTS) <= set(COMMANDS)


def test_unsupported_items_are_not_claimed():
    claimed = {i for i, _ in ITEMS} | set(NAMED)
    for item, reason in UNSUPPORTED.items():
        assert item not in claimed and reason


def test_form_matching():
    assert _form_matches(("show",), ["show"])
    assert not _form_matches(("show",), ["show", "pin"])
    assert _form_matches(("list", "pin", "-t*", "..."),
                         ["list", "pin", "-tfloat"])
    assert not _form_matches(("addf", "*", "*", "*"), ["addf", "a", "b"])
    assert _form_matches(("net", "*", "*", "=>", "*", "..."),
                         ["net", "s", "a.out", "=>", "b.in", "c.in"])
