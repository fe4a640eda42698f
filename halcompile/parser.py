"""Parser of the ``.comp`` declaration language.

:func:`parse` reads the declarations up to ``;;`` and keeps the rest of
the file as the code section.  Every error is a :class:`CompError` that
names the place (``file:line:col``) and shows the line with a caret.
"""

from __future__ import annotations

import os
import re
from typing import Optional

from halcompile.model import (
    HAL_TYPES,
    OPTIONS,
    PARAM_DIRS,
    PIN_DIRS,
    RESERVED,
    TYPE_ALIASES,
    Array,
    Component,
    Function,
    Loc,
    ModParam,
    Pin,
    Variable,
)

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_HALNAME = re.compile(r"[A-Za-z_#][A-Za-z0-9_#.\-]*")
_INT = re.compile(r"0[xX][0-9A-Fa-f]+|[0-9]+")
_NUMBER = re.compile(r"[+-]?(0[xX][0-9A-Fa-f]+|([0-9]+\.?[0-9]*|\.[0-9]+)"
                     r"([eE][+-]?[0-9]+)?)")
_ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "\\": "\\", '"': '"',
            "'": "'", "a": "\a", "b": "\b", "f": "\f", "v": "\v",
            "0": "\0", "\n": ""}
_BOOL_WORDS = {"yes": True, "true": True, "TRUE": True, "no": False,
               "false": False, "FALSE": False}


def _bool_value(value: object) -> Optional[bool]:
    """A boolean option's value as the reference reads it: bare (True),
    yes/no, true/false, TRUE/FALSE, or a number (true unless zero).
    Other words and strings are refused (None): the reference would read
    even ``off`` or ``"no"`` as true."""
    if value is True:
        return True
    if not isinstance(value, str):
        return None
    if value in _BOOL_WORDS:
        return _BOOL_WORDS[value]
    if not _NUMBER.fullmatch(value):
        return None
    try:
        return int(value, 0) != 0
    except ValueError:
        return float(value) != 0


class CompError(Exception):
    """A user error in a ``.comp`` file, with its place."""

    def __init__(self, loc: Loc, message: str,
                 line_text: Optional[str] = None) -> None:
        super().__init__(message)
        self.loc = loc
        self.message = message
        self.line_text = line_text

    def __str__(self) -> str:
        text = f"{self.loc}: {self.message}"
        if self.line_text is not None:
            shown = self.line_text.expandtabs(1)
            text += f"\n    {shown}\n    {' ' * (self.loc.col - 1)}^"
        return text


class _Parser:
    def __init__(self, text: str, filename: str) -> None:
        self.text = text
        self.file = filename
        self.pos = 0
        self.line_starts = [0] + [m.end() for m in re.finditer("\n", text)]

    # ------------------------------------------------------------ places

    def loc(self, pos: Optional[int] = None) -> Loc:
        pos = self.pos if pos is None else pos
        lo, hi = 0, len(self.line_starts) - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if self.line_starts[mid] <= pos:
                lo = mid
            else:
                hi = mid - 1
        return Loc(self.file, lo + 1, pos - self.line_starts[lo] + 1)

    def error(self, message: str, pos: Optional[int] = None) -> CompError:
        loc = self.loc(pos)
        start = self.line_starts[loc.line - 1]
        end = self.text.find("\n", start)
        line = self.text[start:end if end >= 0 else len(self.text)]
        return CompError(loc, message, line)

    # ------------------------------------------------------------ lexing

    def skip(self) -> None:
        """Skip white space and comments."""
        text = self.text
        while self.pos < len(text):
            c = text[self.pos]
            if c in " \t\r\n\f\v":
                self.pos += 1
            elif text.startswith("//", self.pos):
                end = text.find("\n", self.pos)
                self.pos = len(text) if end < 0 else end + 1
            elif text.startswith("/*", self.pos):
                end = text.find("*/", self.pos + 2)
                if end < 0:
                    raise self.error("unterminated comment")
                self.pos = end + 2
            else:
                break

    def at(self, s: str) -> bool:
        self.skip()
        return self.text.startswith(s, self.pos)

    def at_word(self, *words: str) -> Optional[str]:
        self.skip()
        m = _IDENT.match(self.text, self.pos)
        if m and m.group(0) in words:
            return m.group(0)
        return None

    def expect(self, s: str, what: Optional[str] = None) -> None:
        if not self.at(s):
            raise self.error(f"expected {what or repr(s)}")
        self.pos += len(s)

    def accept(self, s: str) -> bool:
        if self.at(s):
            self.pos += len(s)
            return True
        return False

    def match(self, regex: re.Pattern, what: str) -> tuple[str, int]:
        self.skip()
        m = regex.match(self.text, self.pos)
        if not m:
            raise self.error(f"expected {what}")
        self.pos = m.end()
        return m.group(0), m.start()

    def ident(self, what: str = "a name") -> tuple[str, int]:
        return self.match(_IDENT, what)

    def word_in(self, choices: tuple[str, ...], what: str) -> str:
        start = self.pos
        self.skip()
        m = _IDENT.match(self.text, self.pos)
        if not m or m.group(0) not in choices:
            self.pos = start
            self.skip()
            raise self.error(f"expected {what} ({', '.join(choices)})")
        self.pos = m.end()
        return m.group(0)

    def integer(self, what: str) -> int:
        text, _ = self.match(_INT, what)
        return int(text, 0)

    def at_string(self) -> bool:
        self.skip()
        return self.text.startswith(('"', 'r"'), self.pos)

    def string(self, what: str = "a string") -> str:
        self.skip()
        start = self.pos
        raw = self.text.startswith('r"', self.pos)
        if raw:
            self.pos += 1
        if not self.text.startswith('"', self.pos):
            raise self.error(f"expected {what}")
        triple = self.text.startswith('"""', self.pos)
        quote = '"""' if triple else '"'
        self.pos += len(quote)
        out: list[str] = []
        while True:
            if self.pos >= len(self.text):
                raise self.error("unterminated string", start)
            if self.text.startswith(quote, self.pos):
                self.pos += len(quote)
                return "".join(out)
            c = self.text[self.pos]
            if c == "\n" and not triple:
                raise self.error("unterminated string", start)
            if c == "\\" and self.pos + 1 < len(self.text):
                nxt = self.text[self.pos + 1]
                if raw:
                    out.append(c + nxt)
                elif nxt in _ESCAPES:
                    out.append(_ESCAPES[nxt])
                else:
                    out.append(c + nxt)
                self.pos += 2
                continue
            out.append(c)
            self.pos += 1

    def raw_until(self, stops: str, what: str) -> tuple[str, int]:
        """C text up to one of ``stops`` at nesting level 0 (a lone ``=``
        stops only if ``=`` is in ``stops``; ``==`` ``<=`` ... never do),
        or a string."""
        self.skip()
        start = self.pos
        depth = 0
        text = self.text
        i = self.pos
        while i < len(text):
            c = text[i]
            if c in "([{":
                depth += 1
            elif c in ")]}":
                if depth == 0 and c in stops:
                    break
                depth -= 1
                if depth < 0:
                    raise self.error(f"unbalanced '{c}'", i)
            elif depth == 0 and c in stops:
                if c == "=" and (text[i + 1:i + 2] == "=" or
                                 text[i - 1:i] in "=<>!"):
                    i += 1
                    continue
                break
            elif c == '"' or text.startswith('r"', i) and not \
                    (i > 0 and (text[i - 1].isalnum() or text[i - 1] == "_")):
                break
            elif c == "\n" and text.startswith("\n;;", i):
                break       # a missing ';' before the code section
            i += 1
        value = text[start:i].strip()
        if not value:
            raise self.error(f"expected {what}")
        self.pos = i
        return value, start

    # ------------------------------------------------------------ grammar

    def parse(self) -> Component:
        comp: Optional[Component] = None
        self.skip()
        while True:
            self.skip()
            if self.pos >= len(self.text):
                code, code_line = "", len(self.line_starts) + 1
                break
            if self.text.startswith(";;", self.pos):
                self.pos += 2
                nl = self.text.find("\n", self.pos)
                rest = self.text[self.pos:nl if nl >= 0 else len(self.text)]
                if nl >= 0 and not rest.strip():
                    self.pos = nl + 1
                code_line = self.loc().line
                code = self.text[self.pos:]
                break
            kw, kw_pos = self.ident("a declaration")
            if kw == "component":
                if comp is not None:
                    raise self.error("a second component declaration",
                                     kw_pos)
                name, npos = self.ident("the component name")
                doc = self.string() if self.at_string() else None
                comp = Component(name, self.loc(npos), self.file, doc)
            elif comp is None:
                raise self.error("the file must start with 'component NAME;'",
                                 kw_pos)
            else:
                handler = getattr(self, "decl_" + kw, None)
                if handler is None:
                    raise self.error(f"unknown declaration '{kw}'", kw_pos)
                handler(comp, kw, kw_pos)
            if self.at(";;") and not self.text.startswith(";;;", self.pos):
                raise self.error("expected ';' (before the ';;' that starts "
                                 "the code section)")
            self.expect(";", "';'")
        if comp is None:
            raise self.error("no component declaration", 0)
        comp.code = code
        comp.code_line = code_line
        return comp

    def _pinlike(self, comp: Component, kind: str) -> Pin:
        dirs = PIN_DIRS if kind == "pin" else PARAM_DIRS
        direction = self.word_in(dirs, f"a {kind} direction")
        type_ = self.word_in(HAL_TYPES + tuple(TYPE_ALIASES), "a HAL type")
        type_ = TYPE_ALIASES.get(type_, type_)
        name, npos = self.match(_HALNAME, f"a {kind} name")
        item = Pin(kind, direction, type_, name, self.loc(npos))
        if self.accept("["):
            size = self.integer("an array size")
            condsize = None
            if self.accept(":"):
                condsize, cpos = self.raw_until("]", "a size expression")
            self.expect("]", "']'")
            if size < 1:
                raise self.error(f"array {name} must have at least one item",
                                 npos)
            item.array = Array(size, condsize)
            if condsize is not None:
                item.array.condsize_loc = self.loc(cpos)
        if "#" in name and item.array is None:
            raise self.error(f"'{name}' contains '#' but is not an array "
                             "(add [SIZE])", npos)
        if item.array is not None and "#" not in name:
            raise self.error(f"array '{name}' has no '#' in its name", npos)
        if item.array is not None and len(re.findall("#+", name)) > 1:
            raise self.error(f"array '{name}' has more than one run of '#'",
                             npos)
        if self.at_word("if"):
            self.pos += 2
            item.condition, cpos = self.raw_until("=;", "a condition")
            item.condition_loc = self.loc(cpos)
        if self.accept("="):
            item.default, vpos = self.raw_until(";", "a value")
            late_if = re.search(r"\sif\b", item.default)
            if late_if and item.condition is None:
                # the reference's order: '= DEFAULT if CONDITION'
                item.default = item.default[:late_if.start()].rstrip()
                self.pos = vpos + late_if.start()
                self.skip()
                self.pos += 2
                item.condition, cpos = self.raw_until(";", "a condition")
                item.condition_loc = self.loc(cpos)
            self._check_value(item.default, vpos)
            item.default_loc = self.loc(vpos)
        if self.at_string():
            item.doc = self.string()
        return item

    def _check_value(self, value: str, pos: int) -> None:
        if _NUMBER.fullmatch(value) or _IDENT.fullmatch(value):
            return
        if re.fullmatch(r"[-+(]*[\w.+\-*/() ]*[)]*", value):
            return          # a constant expression, left to the compiler
        raise self.error(f"'{value}' is not a value", pos)

    def decl_pin(self, comp: Component, kw: str, pos: int) -> None:
        comp.pins.append(self._pinlike(comp, "pin"))

    def decl_param(self, comp: Component, kw: str, pos: int) -> None:
        comp.params.append(self._pinlike(comp, "param"))

    def decl_function(self, comp: Component, kw: str, pos: int) -> None:
        name, npos = self.match(_HALNAME, "a function name")
        if "#" in name:
            raise self.error(f"function name '{name}' may not contain '#'",
                             npos)
        fn = Function(name, self.loc(npos))
        fp = self.at_word("fp", "nofp")
        if fp:
            self.pos += len(fp)
            fn.fp = fp == "fp"
        if self.at_string():
            fn.doc = self.string()
        comp.functions.append(fn)

    def decl_variable(self, comp: Component, kw: str, pos: int) -> None:
        words: list[tuple[str, int]] = []
        stars = ""
        while True:
            self.skip()
            if self.text.startswith("*", self.pos):
                if words and self.text[self.pos - 1] not in " \t\n*":
                    # "int* x": the star belongs to no name
                    raise self.error("write the '*' of a pointer variable "
                                     "next to its name ('int *p')")
                stars += "*"
                self.pos += 1
                if _IDENT.match(self.text, self.pos) is None and \
                        not self.text.startswith("*", self.pos):
                    raise self.error("expected a variable name after '*'")
                continue
            m = _IDENT.match(self.text, self.pos)
            if not m:
                break
            if stars:
                words.append((m.group(0), m.start()))
                self.pos = m.end()
                break
            words.append((m.group(0), m.start()))
            self.pos = m.end()
        if len(words) < 2:
            raise self.error("expected a C type and a variable name")
        name, npos = words[-1]
        ctype = " ".join(w for w, _ in words[:-1])
        var = Variable(ctype, name, stars, self.loc(npos))
        if self.accept("["):
            var.size = self.integer("an array size")
            self.expect("]", "']'")
        if self.accept("="):
            var.default, vpos = self.raw_until(";", "a value")
            var.default_loc = self.loc(vpos)
        comp.variables.append(var)

    def decl_option(self, comp: Component, kw: str, pos: int) -> None:
        name, npos = self.ident("an option name")
        if name in comp.options:
            raise self.error(f"option {name} is given twice", npos)
        if name not in OPTIONS:
            raise self.error(f"unknown option '{name}' (options: "
                             f"{', '.join(sorted(OPTIONS))})", npos)
        kind = OPTIONS[name]
        self.skip()
        vpos = self.pos
        value: object
        if self.at(";"):
            if kind != "bool":
                raise self.error(f"option {name} needs a value")
            value = True
        elif self.at_string():
            if kind == "bool":
                raise self.error(f"option {name} takes yes or no (or 1 "
                                 "or 0), not a string", vpos)
            value = self.string()
        else:
            m = (_NUMBER.match(self.text, self.pos)
                 or _IDENT.match(self.text, self.pos))
            if not m:
                raise self.error(f"expected a value for option {name}")
            self.pos = m.end()
            value = m.group(0)
        if kind == "bool":
            value = _bool_value(value)
            if value is None:
                raise self.error(f"option {name} takes yes or no (or 1 "
                                 "or 0)", vpos)
        elif kind == "int":
            if not isinstance(value, str) or not _INT.fullmatch(value):
                raise self.error(f"option {name} takes an integer", vpos)
            value = int(value, 0)
        elif kind == "name":
            if not isinstance(value, str) or not _IDENT.fullmatch(value):
                raise self.error(f"option {name} takes a C type name", vpos)
        comp.options[name] = value
        comp.option_locs[name] = self.loc(npos)

    def decl_modparam(self, comp: Component, kw: str, pos: int) -> None:
        type_ = self.word_in(("int", "long", "string", "dummy"),
                             "a modparam type")
        name, npos = self.ident("a modparam name")
        mp = ModParam(type_, name, self.loc(npos))
        if self.accept("="):
            if type_ == "string":
                mp.default = self.string("a string value")
            else:
                text, vpos = self.match(_NUMBER, "an integer value")
                if not re.fullmatch(r"[+-]?(0[xX][0-9A-Fa-f]+|[0-9]+)", text):
                    raise self.error(f"'{text}' is not an integer", vpos)
                mp.default = text
        if self.at_string():
            mp.doc = self.string()
        comp.modparams.append(mp)

    def decl_license(self, comp: Component, kw: str, pos: int) -> None:
        comp.license = self.string("the license string")

    def decl_author(self, comp: Component, kw: str, pos: int) -> None:
        comp.authors.append(self.string("the author string"))

    def decl_include(self, comp: Component, kw: str, pos: int) -> None:
        self.skip()
        m = re.compile(r'<[^>\n]+>|"[^"\n]+"').match(self.text, self.pos)
        if not m:
            raise self.error('expected <header.h> or "header.h"')
        comp.include_locs.append(self.loc())
        self.pos = m.end()
        comp.includes.append(m.group(0))

    def _doc(self, comp: Component, kw: str, pos: int) -> None:
        setattr(comp, kw, self.string(f"the {kw} text"))

    decl_description = decl_notes = decl_see_also = decl_examples = _doc


def parse(text: str, filename: str = "<string>") -> Component:
    """Parse a ``.comp`` source and check it (see :func:`check`)."""
    parser = _Parser(text, filename)
    comp = parser.parse()
    check(comp, parser)
    return comp


def parse_file(path: str, display_name: Optional[str] = None) -> Component:
    with open(path, encoding="utf-8") as f:
        text = f.read()
    comp = parse(text, display_name or path)
    stem = os.path.splitext(os.path.basename(path))[0]
    if path.endswith(".comp") and comp.name != stem:
        raise _err(_Parser(text, display_name or path), comp.loc,
                   f"component name '{comp.name}' does not match the file "
                   f"name '{stem}'")
    return comp


def _err(parser: _Parser, loc: Loc, message: str) -> CompError:
    start = parser.line_starts[loc.line - 1]
    return parser.error(message, start + loc.col - 1)


def check(comp: Component, parser: _Parser) -> None:
    """Semantic checks: names, options, required declarations."""
    seen: dict[str, str] = {}
    items = ([(p.c_name, p.loc, p.kind) for p in comp.pins + comp.params]
             + [(f.c_name, f.loc, "function") for f in comp.functions]
             + [(v.name, v.loc, "variable") for v in comp.variables]
             + [(m.name, m.loc, "modparam") for m in comp.modparams])
    for cname, loc, kind in items:
        if cname in seen:
            raise _err(parser, loc, f"duplicate item name '{cname}' "
                       f"(already a {seen[cname]})")
        if cname in RESERVED or cname.startswith("_comp") or \
                cname == "personality" and kind != "function":
            raise _err(parser, loc, f"{kind} name '{cname}' is reserved")
        seen[cname] = kind
    hal_names: dict[str, str] = {}
    for p in comp.pins + comp.params:
        if p.hal_name in hal_names:
            raise _err(parser, p.loc, f"{p.kind} '{p.name}' has the same HAL "
                       f"name as {hal_names[p.hal_name]}")
        hal_names[p.hal_name] = f"{p.kind} '{p.name}'"
    fnames: set[str] = set()
    for f in comp.functions:
        if f.hal_name in fnames:
            raise _err(parser, f.loc, f"two functions named '{f.hal_name}'")
        fnames.add(f.hal_name)
    if comp.option("userspace"):
        if comp.functions:
            raise _err(parser, comp.option_locs["userspace"],
                       "userspace components may not have functions "
                       f"(remove 'function {comp.functions[0].name}')")
        if not re.search(r"\buser_mainloop\b", comp.code):
            raise _err(parser, comp.option_locs["userspace"],
                       "option userspace needs 'void user_mainloop(void)' "
                       "in the code section")
        if comp.option("userinit") and not re.search(r"\buserinit\b",
                                                     comp.code):
            raise _err(parser, comp.option_locs["userinit"],
                       "option userinit needs 'void userinit(int argc, "
                       "char **argv)' in the code section")
    elif comp.option("userinit"):
        # the reference warns and goes on
        comp.options["userinit"] = False
    if comp.option("cython"):
        for opt, bad in (("data", None), ("rtapi_app", False),
                         ("userspace", True)):
            if opt in comp.options and (bad is None
                                        or comp.options[opt] == bad):
                raise _err(parser, comp.option_locs[opt],
                           f"option {opt} is not supported with option "
                           "cython")
    if comp.option("singleton") and comp.option("count_function"):
        raise _err(parser, comp.option_locs["count_function"],
                   "option count_function cannot go with option singleton")
    _check_definitions(comp, parser)
    if comp.option("homemod") or comp.option("tpmod"):
        comp.options["singleton"] = True
    if not comp.pins:
        raise _err(parser, comp.loc, "a component must have at least one "
                   "pin")
    if comp.license is None:
        raise _err(parser, comp.loc, "license not specified (add "
                   "'license \"GPL\";')")
    if comp.option("default_count", 1) < 0:       # type: ignore[operator]
        raise _err(parser, comp.option_locs["default_count"],
                   "default_count must not be negative")


def _check_definitions(comp: Component, parser: _Parser) -> None:
    """Catch a declared function (or option extra_setup, extra_cleanup,
    count_function) that the code section never defines: the module would
    build but fail to load.  Lenient: any mention of the name counts."""
    code = comp.code
    if "FUNCTION" not in code and len(comp.functions) == 1:
        return                  # the code section is the function's body
    for fn in comp.functions:
        if not re.search(rf"\b{re.escape(fn.c_name)}\b", code):
            raise _err(parser, fn.loc, f"function '{fn.name}' has no "
                       f"definition (FUNCTION({fn.c_name}) {{ ... }}) in the "
                       "code section")
    needs = [("extra_setup", "EXTRA_SETUP", "EXTRA_SETUP() { ... }"),
             ("extra_cleanup", "EXTRA_CLEANUP", "EXTRA_CLEANUP() { ... }"),
             ("count_function", "get_count", "int get_count(void)")]
    for option, macro, form in needs:
        if comp.option(option) and option in comp.option_locs and not (
                re.search(rf"\b{macro}\b", code)
                or re.search(rf"\b{option}\b", code)):
            raise _err(parser, comp.option_locs[option],
                       f"option {option} needs {form} in the code section")
