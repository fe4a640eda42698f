"""Coverage audit of the halcompile corpus: every declaration, option,
type and naming rule of the reference's ``.comp`` manual (and the habits of
real files the issue lists) appears in at least one ``tests/data/comps/*.comp``
that a test compiles and loads, or is listed here as unsupported with the
reason."""

from __future__ import annotations

import glob
import os
import re
from typing import Callable

import pytest
from helpers import data_path, find_test_module

from halcompile import CompError, parse_file
from halcompile.model import Component

COMPS = str(data_path("comps"))
#: test modules that compile (and load) corpus files; the documentation
#: tests only document them, so they do not count
#: files that exist to fail (syntax error, C error)
BAD = {"hcbadc", "hcbadsyntax"}
COMPILING_TESTS = ["test_halcompile.py", "test_halcompile_cython.py",
                   "test_halcompile_user.py", "test_halcompile_corpus.py"]


def _compiled() -> dict[str, Component]:
    """The good corpus files a compiling test names, parsed."""
    text = ""
    for name in COMPILING_TESTS:
        with open(find_test_module(name), encoding="utf-8") as f:
            text += f.read()
    out = {}
    for path in sorted(glob.glob(os.path.join(COMPS, "*.comp"))):
        stem = os.path.splitext(os.path.basename(path))[0]
        if stem in BAD:
            continue
        if f'"{stem}"' not in text and f"{stem}.comp" not in text:
            continue
        try:
            out[stem] = parse_file(path)
        except CompError:
            continue            # not good: cannot count
    return out


CORPUS = _compiled()


def _items(c: Component):
    return c.pins + c.params


def _code(c: Component) -> str:
    return c.code


def _has(pattern: str) -> Callable[[Component], bool]:
    return lambda c: re.search(pattern, c.code, re.M) is not None


def _cython(c: Component) -> bool:
    return bool(c.option("cython"))


Check = Callable[[Component], bool]

#: the declarations of the manual's syntax section
DECLARATIONS: dict[str, Check] = {
    "component": lambda c: bool(c.name),
    "component with doc": lambda c: bool(c.doc),
    "pin": lambda c: bool(c.pins),
    "param": lambda c: bool(c.params),
    "function": lambda c: bool(c.functions),
    "function fp": lambda c: any(f.fp for f in c.functions),
    "function nofp": lambda c: any(not f.fp for f in c.functions),
    "function with doc": lambda c: any(f.doc for f in c.functions),
    "function _": lambda c: any(f.name == "_" for f in c.functions),
    "option": lambda c: bool(c.options),
    "variable": lambda c: bool(c.variables),
    "variable array": lambda c: any(v.size for v in c.variables),
    "variable pointer": lambda c: any(v.stars for v in c.variables),
    "variable default": lambda c: any(v.default for v in c.variables),
    "modparam int": lambda c: any(m.type == "int" for m in c.modparams),
    "modparam string": lambda c: any(m.type == "string"
                                     for m in c.modparams),
    "modparam dummy": lambda c: any(m.type == "dummy" for m in c.modparams),
    "license": lambda c: bool(c.license),
    "author": lambda c: bool(c.authors),
    "description": lambda c: bool(c.description),
    "notes": lambda c: bool(c.notes),
    "see_also": lambda c: bool(c.see_also),
    "examples": lambda c: bool(c.examples),
    "include <>": lambda c: any(i.startswith("<") for i in c.includes),
    'include ""': lambda c: any(i.startswith('"') for i in c.includes),
}

#: the options of the manual, plus ours (cython); fp is the older spelling
OPTIONS = ["singleton", "default_count", "count_function", "rtapi_app",
           "data", "extra_setup", "extra_cleanup", "userspace", "userinit",
           "extra_link_args", "extra_compile_args", "homemod", "tpmod",
           "default_personality", "fp", "cython"]

#: options our compiler knows that no corpus file uses, and why
UNSUPPORTED_OPTIONS = {
    "period": "not in the 2.9 manual; accepted and ignored",
    "no_convenience_defines": "not in the 2.9 manual",
    "constructable": "not in the 2.9 manual (newinst of comps comes later)",
    "personality": "an older spelling that changes nothing (as in the "
                   "reference); test_halcompile_refcompat.py compiles it",
    "modparam long": "not in the manual's grammar (RTAPI_MP_LONG in the "
                     "code section is covered)",
}

TYPES = ["bit", "float", "s32", "u32", "s64", "u64"]
#: the spellings the manual prefers (the model folds them into s32/u32)
TYPE_WORDS = ["signed", "unsigned"]

#: the rest of the manual and the issue's list of what real files do
FEATURES: dict[str, Check] = {
    "pin in": lambda c: any(p.direction == "in" for p in c.pins),
    "pin out": lambda c: any(p.direction == "out" for p in c.pins),
    "pin io": lambda c: any(p.direction == "io" for p in c.pins),
    "param r": lambda c: any(p.direction == "r" for p in c.params),
    "param rw": lambda c: any(p.direction == "rw" for p in c.params),
    "array [SIZE]": lambda c: any(p.array and p.array.condsize is None
                                  for p in _items(c)),
    "array [MAX : CONDSIZE]": lambda c: any(p.array and p.array.condsize
                                            for p in _items(c)),
    "conditional pin (if)": lambda c: any(p.condition for p in c.pins),
    "conditional param (if)": lambda c: any(p.condition for p in c.params),
    "default 1e20": lambda c: any(p.default == "1e20" for p in _items(c)),
    "default .5": lambda c: any(p.default == ".5" for p in _items(c)),
    "default TRUE": lambda c: any(p.default == "TRUE" for p in _items(c)),
    "default FALSE": lambda c: any(p.default == "FALSE" for p in _items(c)),
    "default hex": lambda c: any((p.default or "").lower().startswith("0x")
                                 for p in _items(c)),
    "default negative": lambda c: any((p.default or "").startswith("-")
                                      for p in _items(c)),
    "item doc": lambda c: any(p.doc for p in _items(c)),
    "multi-line doc": lambda c: any("\n" in (p.doc or "")
                                    for p in _items(c)),
    "hal_ prefix dropped": lambda c: c.name.startswith("hal_"),
    "# run of one": lambda c: any(re.search(r"(^|[^#])#([^#]|$)", p.name)
                                  for p in _items(c)),
    "# run of several": lambda c: any("##" in p.name for p in _items(c)),
    "# in the middle": lambda c: any(re.search(r"#[.\-_]?\w", p.name)
                                     for p in _items(c)),
    "trailing _": lambda c: any(p.name.endswith("_") for p in _items(c)),
    "- and . in names": lambda c: any("-" in p.name and "." in p.name
                                      for p in _items(c)),
    "function name with _": lambda c: any("_" in f.name.strip("_")
                                          for f in c.functions),
    "functions named read and write": lambda c: {"read", "write"} <= {
        f.name for f in c.functions},
    "python keyword names": lambda c: {"in", "and", "or"} <= {
        p.name.rstrip("_") for p in c.pins},
    "libc names": lambda c: {"index", "select", "open"} <= {
        p.name for p in c.pins},
    "several functions": lambda c: len(c.functions) > 1,
    "FUNCTION(name)": _has(r"^FUNCTION\("),
    "implicit FUNCTION body": lambda c: not c.option("userspace")
    and "FUNCTION" not in c.code,
    "EXTRA_SETUP": _has(r"^EXTRA_SETUP\(\)"),
    "EXTRA_CLEANUP": _has(r"^EXTRA_CLEANUP\(\)"),
    "extra_arg": _has(r"\bextra_arg\b"),
    "fperiod": _has(r"\bfperiod\b"),
    "period": _has(r"\bperiod\b"),
    "personality in code": _has(r"\bpersonality\b"),
    "module-level count": _has(r"=\s*count\b|\+\s*count\b"),
    "get_count()": _has(r"\bget_count\s*\("),
    "data macro": _has(r"\bdata\."),
    "RTAPI_MP_INT": _has(r"RTAPI_MP_INT\("),
    "RTAPI_MP_LONG": _has(r"RTAPI_MP_LONG\("),
    "RTAPI_MP_STRING": _has(r"RTAPI_MP_STRING\("),
    "RTAPI_MP_ARRAY_INT": _has(r"RTAPI_MP_ARRAY_INT\("),
    "#define": _has(r"^#define\s"),
    "file-scope struct": _has(r"^(typedef\s+)?struct\b"),
    "mutable global": _has(r"^(static\s+)?int\s+\w+(\s*=\s*[^;(]+)?;"),
    "file-scope helper function": _has(r"^(static\s+)?\w+\s+\w+\([^)]*\)\s*"
                                       r"(\{|$)"),
    "export() with rtapi_app no": _has(r"\bexport\("),
    "user_mainloop": _has(r"\buser_mainloop\b"),
    "FOR_ALL_INSTS": _has(r"FOR_ALL_INSTS\(\)"),
    "userinit()": _has(r"\buserinit\("),
    "Cython code section": _cython,
    "Cython FUNCTION block": lambda c: _cython(c) and bool(
        re.search(r"^FUNCTION\(\w+\):", c.code, re.M)),
    "Cython implicit body": lambda c: _cython(c) and "FUNCTION" not in c.code,
    "Cython EXTRA_SETUP": lambda c: _cython(c) and "EXTRA_SETUP" in c.code,
}


def _users(check: Check) -> list[str]:
    return [name for name, comp in CORPUS.items() if check(comp)]


def test_corpus_has_forty_compiled_files():
    assert len(CORPUS) >= 40, sorted(CORPUS)


@pytest.mark.parametrize("decl", sorted(DECLARATIONS))
def test_declaration_is_covered(decl):
    assert _users(DECLARATIONS[decl]), f"no compiled corpus file has {decl}"


@pytest.mark.parametrize("option", OPTIONS)
def test_option_is_covered(option):
    assert _users(lambda c: option in c.options), \
        f"no compiled corpus file sets option {option}"


@pytest.mark.parametrize("option", sorted(UNSUPPORTED_OPTIONS))
def test_unlisted_options_really_are_unused(option):
    """The list of the unused must stay true: if a file starts using one,
    move it to OPTIONS."""
    if option.startswith("modparam "):
        kind = option.split()[1]
        assert not _users(lambda c: any(m.type == kind for m in c.modparams))
    else:
        assert not _users(lambda c: option in c.options)


def test_every_option_of_the_compiler_is_listed():
    from halcompile.model import OPTIONS as KNOWN
    listed = set(OPTIONS) | set(UNSUPPORTED_OPTIONS)
    assert set(KNOWN) <= listed, set(KNOWN) - listed


@pytest.mark.parametrize("type_", TYPES)
def test_type_is_covered(type_):
    assert _users(lambda c: any(p.type == type_ for p in _items(c)))


@pytest.mark.parametrize("word", TYPE_WORDS)
def test_type_spelling_is_covered(word):
    pattern = re.compile(rf"^\s*(pin|param)\s+\w+\s+{word}\s", re.M)
    users = []
    for name in CORPUS:
        with open(os.path.join(COMPS, name + ".comp"), encoding="utf-8") as f:
            if pattern.search(f.read()):
                users.append(name)
    assert users, f"no compiled corpus file spells a type '{word}'"


@pytest.mark.parametrize("feature", sorted(FEATURES))
def test_feature_is_covered(feature):
    assert _users(FEATURES[feature]), f"no compiled corpus file has {feature}"


def test_both_code_section_kinds_and_userspace_are_plenty():
    cython = _users(_cython)
    user = _users(lambda c: bool(c.option("userspace")))
    c_bodied = [n for n in CORPUS if n not in cython]
    assert len(cython) >= 4 and len(user) >= 4 and len(c_bodied) >= 30


def test_the_audit_can_fail():
    """A feature no file has is reported as missing."""
    assert not _users(lambda c: c.name == "no-such-comp")
