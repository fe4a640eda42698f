"""Documentation generator: a manual page and a reStructuredText page per
``.comp`` file.

The text of a ``.comp`` file's documentation strings (the component's
short description, ``description``, ``notes``, ``examples``,
``see_also`` and the docs of pins, params, functions and modparams) is
groff ``man`` markup, as in the reference.  The manual page keeps it as it
is; the reStructuredText page gets it through :func:`troff_to_rst`, which
understands the markup such strings use (font escapes, special
characters, paragraphs, tagged and bulleted paragraphs, no-fill blocks)
and drops the rest.

Entry points: :func:`man_page` and :func:`rst_page` (text from a parsed
:class:`~halcompile.model.Component`), :func:`document` (files from a
``.comp``), :func:`view_doc` (show the manual page) and
:func:`install_doc` (put it where ``man`` finds it).
"""

from __future__ import annotations

import datetime
import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unicodedata
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Optional

from halcompile.model import Component, Function, Pin, hal_identifier
from halcompile.parser import parse_file

FORMATS = ("man", "rst")

_FP_NOTE = "requires a floating-point thread"


# ------------------------------------------------------------------ facts


@dataclass
class _Item:
    """What both formats say about a pin, param or function."""

    parts: list[tuple[str, bool]]   # the HAL name: (text, placeholder?)
    type: str = ""
    direction: str = ""
    default: Optional[str] = None
    index: Optional[str] = None     # e.g. "MM=00..03"
    condition: Optional[str] = None
    doc: Optional[str] = None
    fp: Optional[bool] = None


def _numbered(comp: Component) -> bool:
    """Instances are named ``<prefix>.N`` (else: one, named ``prefix``)."""
    return not comp.option("singleton")


def _index_text(p: Pin) -> Optional[str]:
    if p.array is None:
        return None
    run = max(re.findall("#+", p.name), key=len)
    width = len(run)
    placeholder = "M" * width
    if p.array.condsize:
        return (f"{placeholder} from {0:0{width}d}; {p.array.condsize} "
                f"items, at most {p.array.size}")
    return (f"{placeholder}={0:0{width}d}..{p.array.size - 1:0{width}d}")


def _head(comp: Component, name: str) -> list[tuple[str, bool]]:
    """The parts of the HAL name of item ``name`` of an instance (the
    function ``_``, with the empty name, is named like its instance)."""
    parts = [(comp.prefix, False)]
    if _numbered(comp):
        parts += [(".", False), ("N", True)]
    if name:
        parts.append((".", False))
    for k, piece in enumerate(re.split("(#+)", name)):
        if piece:
            parts.append(("M" * len(piece), True) if k % 2
                         else (piece, False))
    return parts


def _pin_item(comp: Component, p: Pin) -> _Item:
    return _Item(_head(comp, hal_identifier(p.name)), p.type, p.direction,
                 p.default, _index_text(p), p.condition, p.doc)


def _function_item(comp: Component, fn: Function) -> _Item:
    return _Item(_head(comp, fn.hal_name), doc=fn.doc, fp=fn.fp)


def _functions(comp: Component) -> list[Function]:
    return [] if comp.option("userspace") else comp.functions


def man_section(comp: Component) -> str:
    """The manual section of ``comp``: 9 (realtime components), or 1
    (userspace components: programs that ``loadusr`` starts)."""
    return "1" if comp.option("userspace") else "9"


def file_name(comp: Component, fmt: str) -> str:
    """The name of the page of ``comp`` in format ``fmt``."""
    if fmt == "man":
        return f"{comp.name}.{man_section(comp)}"
    if fmt == "rst":
        return comp.name + ".rst"
    raise ValueError(f"unknown documentation format {fmt!r} "
                     f"(formats: {', '.join(FORMATS)})")


def _own_loading(comp: Component) -> bool:
    """``option rtapi_app no``: the code section's rtapi_app_main makes
    the instances, and its ``modparam`` lines are the whole load line."""
    return not comp.option("userspace") and \
        not comp.option("rtapi_app", True)


def _synopsis(comp: Component) -> str:
    """The load line, plain text."""
    userspace = comp.option("userspace")
    words = ["loadusr" if userspace else "loadrt", comp.name]
    own = _own_loading(comp)
    if _numbered(comp) and not comp.option("count_function") and not own:
        words.append("[count=N|names=name1[,name2...]]")
    if comp.has_personality and not own:
        words.append("[personality=P,P,...]")
    for mp in comp.modparams:
        words.append(f"[{mp.name}={'S' if mp.type == 'string' else 'N'}]")
    if userspace and comp.option("userinit"):
        words.append("[ARGUMENT...]")
    return " ".join(words)


@dataclass
class _LoadParam:
    """A word of the load line and what it does."""

    name: str
    default: Optional[str]
    text: str                   # plain text (ours)
    doc: Optional[str] = None   # troff text (the .comp's)


def _load_params(comp: Component) -> list[_LoadParam]:
    out: list[_LoadParam] = []
    own = _own_loading(comp)
    if own:
        pass
    elif _numbered(comp) and not comp.option("count_function"):
        out.append(_LoadParam(
            "count", str(comp.option("default_count", 1)),
            "The number of instances to make; they are named "
            f"{comp.prefix}.0, {comp.prefix}.1 and so on. Give count or "
            "names, not both."))
        out.append(_LoadParam(
            "names", None,
            "The names of the instances to make, separated by commas; "
            "each name replaces the prefix " + comp.prefix + ".N of the "
            "items of its instance."))
    elif comp.option("count_function"):
        out.append(_LoadParam(
            "count", None,
            "There is no count parameter: the component decides how many "
            "instances it makes."))
    if comp.has_personality and not own:
        out.append(_LoadParam(
            "personality", str(comp.option("default_personality", 0)),
            "One integer per instance, separated by commas: it selects "
            "which pins and params the instance has (the conditions and "
            "array sizes below)."))
    if comp.option("userspace") and comp.option("userinit"):
        out.append(_LoadParam(
            "ARGUMENT", None,
            "The other words of the command line go to the component, "
            "which reads them when it starts (userinit)."))
    for mp in comp.modparams:
        default = mp.default
        if mp.type == "string" and default is not None:
            default = f'"{default}"'
        kind = {"int": ": an integer", "long": ": an integer",
                "string": ": a string"}.get(mp.type, " of the code section")
        out.append(_LoadParam(mp.name, default,
                              f"A module parameter{kind}.", mp.doc))
    return out


# ------------------------------------------------------------------ man


def _man_text(text: str) -> str:
    """Plain text for the inside of a troff text line."""
    return text.replace("\\", "\\e").replace("-", "\\-")


def _man_escape(text: str) -> str:
    """Plain text for troff text lines (none of them a request)."""
    return "\n".join(("\\&" + ln) if ln[:1] in (".", "'") else ln
                     for ln in _man_text(text).split("\n"))


def _man_name(parts: Sequence[tuple[str, bool]]) -> str:
    """A HAL name in bold, with its placeholders (N, MM) in italics."""
    out = "".join(f"\\fI{text}\\fB" if var else _man_text(text)
                  for text, var in parts)
    return "\\fB" + out + "\\fR"


def _doc_lines(doc: Optional[str]) -> list[str]:
    """A .comp doc string (troff) as lines of the page."""
    if not doc:
        return []
    return doc.strip("\n").split("\n")


def _man_item(item: _Item) -> str:
    tag = _man_name(item.parts)
    if item.type:
        tag += f" {item.type} {item.direction}"
    if item.index:
        tag += " (" + _man_text(item.index) + ")"
    if item.condition:
        tag += " [if " + _man_text(item.condition) + "]"
    if item.default is not None:
        tag += " (default: " + _man_text(item.default) + ")"
    if item.fp:
        tag += f" ({_FP_NOTE})"
    return tag


def _man_items(items: Sequence[_Item]) -> list[str]:
    """Tagged paragraphs; undocumented items sit on consecutive lines."""
    out: list[str] = []
    previous_doc = True
    for item in items:
        if not previous_doc:
            out.append(".PD 0")
        out += [".TP", _man_item(item)]
        if not previous_doc:
            out.append(".PD")
        out += _doc_lines(item.doc)
        previous_doc = bool(item.doc)
    return out


def _page_date(comp: Component, date: Optional[str]) -> str:
    if date:
        return date
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    try:
        stamp = float(epoch) if epoch else os.path.getmtime(comp.file)
    except (OSError, ValueError):
        stamp = datetime.datetime.now().timestamp()
    return datetime.datetime.fromtimestamp(
        stamp, datetime.timezone.utc).strftime("%Y-%m-%d")


def man_page(comp: Component, date: Optional[str] = None) -> str:
    """The manual page (troff ``man`` macros; section 9, or 1 for a
    userspace component) of ``comp``.

    ``date`` (``YYYY-MM-DD``) goes in the page footer; by default the
    date of ``$SOURCE_DATE_EPOCH`` or else of the ``.comp`` file, so
    that an unchanged file gives the same page."""
    title = comp.name.upper()
    section = man_section(comp)
    lines = [
        f'.\\" {comp.name}({section}): generated by halsdk\'s halcompile from '
        f"{os.path.basename(comp.file)}.",
        '.\\" Edit the .comp file, not this one.',
        f'.TH "{_man_escape(title)}" {section} "{_page_date(comp, date)}" '
        '"halsdk" "HAL Component"',
        ".nh",
        ".SH NAME",
    ]
    short = comp.doc.strip() if comp.doc else ""
    lines.append(_man_escape(comp.name) + (" \\- " + short if short else ""))

    lines += [".SH SYNOPSIS", ".HP", ".B " + _man_escape(_synopsis(comp))]
    for lp in _load_params(comp):
        lines += [".TP", "\\fB" + _man_text(lp.name) + "\\fR"
                  + (" [default: " + _man_text(lp.default) + "]"
                     if lp.default is not None else ""),
                  _man_escape(lp.text)]
        if lp.doc:
            lines += [".br"] + _doc_lines(lp.doc)

    def text_section(title: str, text: Optional[str]) -> None:
        if text and text.strip():
            lines.extend([f".SH {title}"] + _doc_lines(text))

    text_section("DESCRIPTION", comp.description)
    functions = [_function_item(comp, f) for f in _functions(comp)]
    if functions:
        lines += [".SH FUNCTIONS"] + _man_items(functions)
    if comp.pins:
        lines += [".SH PINS"] + _man_items(
            [_pin_item(comp, p) for p in comp.pins])
    if comp.params:
        lines += [".SH PARAMETERS"] + _man_items(
            [_pin_item(comp, p) for p in comp.params])
    text_section("NOTES", comp.notes)
    text_section("EXAMPLES", comp.examples)
    text_section("SEE ALSO", comp.see_also)
    if comp.authors:
        lines += [".SH AUTHOR"]
        for i, author in enumerate(comp.authors):
            lines += ([".br"] if i else []) + [_man_escape(author)]
    if comp.license:
        lines += [".SH LICENSE", _man_escape(comp.license)]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ troff


_SPECIAL = {
    "bu": "\u2022", "em": "\u2014", "en": "\u2013", "aq": "'", "dq": '"',
    "lq": "\u201c", "rq": "\u201d", "oq": "\u2018", "cq": "\u2019",
    "co": "\u00a9", "rg": "\u00ae", "de": "\u00b0", "mu": "\u00d7",
    "+-": "\u00b1", "hy": "-", "mi": "-", "ti": "~", "ha": "^",
    "rs": "\\", "sl": "/", "or": "|", "<=": "\u2264", ">=": "\u2265",
    "!=": "\u2260", "->": "\u2192", "<-": "\u2190", "*m": "\u00b5",
    "*p": "\u03c0", "ga": "`", "ul": "_", "pl": "+", "eq": "=",
}
_FONTS = {"B": "B", "I": "I", "R": "R", "P": "R", "BI": "B", "CW": "R",
          "CR": "R", "CB": "B", "CI": "I", "1": "R", "2": "I", "3": "B",
          "4": "B", "C": "R"}


def _runs(text: str, font: str = "R") -> tuple[list[tuple[str, str]], str]:
    """Split troff text into (font, plain text) runs; returns the runs
    and the font at the end."""
    runs: list[tuple[str, str]] = []
    buf: list[str] = []
    previous = "R"

    def flush() -> None:
        if buf:
            runs.append((font, "".join(buf)))
            buf.clear()

    i = 0
    n = len(text)
    while i < n:
        c = text[i]
        if c != "\\" or i + 1 >= n:
            buf.append(c)
            i += 1
            continue
        e = text[i + 1]
        i += 2
        if e == "f":
            if text[i:i + 1] == "(":
                name, i = text[i + 1:i + 3], i + 3
            elif text[i:i + 1] == "[":
                end = text.find("]", i)
                end = n if end < 0 else end
                name, i = text[i + 1:end], end + 1
            else:
                name, i = text[i:i + 1], i + 1
            new = previous if name in ("P", "") else _FONTS.get(name, "R")
            flush()
            previous, font = font, new
        elif e == "(":
            code = text[i:i + 2]
            buf.append(_SPECIAL.get(code, code))
            i += 2
        elif e == "[":
            end = text.find("]", i)
            end = n if end < 0 else end
            code = text[i:end]
            buf.append(_SPECIAL.get(code, code))
            i = end + 1
        elif e == "*":             # a string register: dropped
            if text[i:i + 1] == "(":
                i += 3
            elif text[i:i + 1] == "[":
                end = text.find("]", i)
                i = n if end < 0 else end + 1
            else:
                i += 1
        elif e in ("e", "\\"):
            buf.append("\\")
        elif e in ("-", "'", "`", ".", '"'):
            if e == '"':            # a comment: the rest of the line goes
                break
            buf.append({"'": "\u00b4"}.get(e, e))
        elif e in (" ", "~", "0"):
            buf.append(" ")
        elif e in ("&", "|", "^", "c", ")", "%", ",", "/", ":"):
            pass
        else:
            buf.append(e)
    flush()
    return runs, font


_RST_PLAIN = re.compile(r"([\\*`_|])")


#: what may stand just before and after inline markup with no escaped
#: space between (the docutils rules, ASCII part)
_BEFORE_MARKUP = set(" \t\n-:/'\"<([{")
_AFTER_MARKUP = set(" \t\n-.,:;!?\\/'\")]}>")


def _rst_text(runs: Iterable[tuple[str, str]]) -> str:
    """reStructuredText of font runs (one line of inline markup)."""
    pieces = [(f, _RST_PLAIN.sub(r"\\\1", t)) for f, t in runs if t]
    out = ""
    for k, (font, body) in enumerate(pieces):
        if font == "R" or not body.strip():
            out += body
            continue
        core = body.strip()
        lead = body[:len(body) - len(body.lstrip())]
        trail = body[len(body.rstrip()):]
        out += lead
        if out and out[-1] not in _BEFORE_MARKUP:
            out += "\\ "
        mark = "**" if font == "B" else "*"
        out += mark + core + mark + trail
        following = pieces[k + 1][1][:1] if k + 1 < len(pieces) else ""
        if not trail and following and following not in _AFTER_MARKUP:
            out += "\\ "
    return out


@dataclass
class _Block:
    kind: str           # para, literal, bullet, term, rubric
    text: str = ""      # troff text (para, bullet, rubric); term: the tag
    lines: Optional[list[str]] = None   # literal lines / term body (troff)
    spaced: bool = False    # literal made of lines that start with a space


_FONT_MACROS = {"B": "B", "I": "I", "SB": "B", "SM": "R"}
_ALT_MACROS = {"BI", "BR", "IB", "IR", "RB", "RI"}


def _macro_args(rest: str) -> list[str]:
    return [a[1:-1] if a.startswith('"') else a
            for a in re.findall(r'"[^"]*"|\S+', rest)]


def _blocks(text: str) -> list[_Block]:
    """Parse troff text into blocks of the reStructuredText page."""
    blocks: list[_Block] = []
    para: list[str] = []
    target: Optional[_Block] = None     # the block that takes text lines
    pending_tag = False                 # .TP: the next line is the tag
    literal: Optional[list[str]] = None

    def end_para() -> None:
        nonlocal target
        if para:
            blocks.append(_Block("para", " ".join(para)))
            para.clear()
        target = None

    def add_text(line: str) -> None:
        nonlocal pending_tag, target
        if pending_tag:
            pending_tag = False
            target = _Block("term", line, [])
            blocks.append(target)
            return
        if target is not None:
            if target.kind == "term":
                assert target.lines is not None
                target.lines.append(line)
            else:
                target.text += " " + line
            return
        para.append(line)

    for raw in text.split("\n"):
        if literal is not None:
            if re.match(r"[.'](fi|EE)\b", raw):
                end_para()
                blocks.append(_Block("literal", lines=literal))
                literal = None
            elif not re.match(r"[.']\S", raw) or raw.startswith(".\\&"):
                literal.append("".join(t for _, t in _runs(raw)[0]))
            continue
        if raw.startswith((".", "'")) and not raw.startswith(".\\&"):
            m = re.match(r"[.']\s*(\S*)\s*(.*)", raw)
            assert m
            name, rest = m.group(1), m.group(2)
            if name.startswith('\\"') or name == "":
                continue
            if name in ("P", "PP", "LP", "sp", "br"):
                end_para()
            elif name in ("nf", "EX"):
                end_para()
                literal = []
            elif name in ("SH", "SS"):
                end_para()
                blocks.append(_Block("rubric", rest))
            elif name == "TP":
                end_para()
                pending_tag = True
            elif name == "IP":
                end_para()
                args = _macro_args(rest)
                tag = args[0] if args else ""
                if tag in ("\\(bu", "\\[bu]", "*", "-", "\\-", "o"):
                    target = _Block("bullet", "")
                    blocks.append(target)
                elif tag:
                    target = _Block("term", tag, [])
                    blocks.append(target)
            elif name in _FONT_MACROS:
                font = _FONT_MACROS[name]
                words = " ".join(_macro_args(rest))
                add_text(f"\\f{font}{words}\\fR" if font != "R" else words)
            elif name in _ALT_MACROS:
                args = _macro_args(rest)
                add_text("".join(f"\\f{name[k % 2]}{a}"
                                 for k, a in enumerate(args)) + "\\fR")
            elif name in ("UR", "MT", "URL"):
                args = _macro_args(rest)
                if args:
                    add_text(args[0])
            # every other request changes layout only: dropped
            continue
        if not raw.strip():
            if not pending_tag:
                end_para()
            continue
        if raw[:1].isspace() and target is None and not pending_tag:
            # troff keeps a line that starts with a space on its own:
            # consecutive ones make a literal block
            end_para()
            if blocks and blocks[-1].spaced:
                assert blocks[-1].lines is not None
                blocks[-1].lines.append("".join(
                    t for _, t in _runs(raw)[0]))
            else:
                blocks.append(_Block(
                    "literal", lines=["".join(t for _, t in _runs(raw)[0])],
                    spaced=True))
            continue
        if blocks and blocks[-1].spaced:
            blocks[-1].spaced = False
        add_text(raw)
    if literal is not None:
        blocks.append(_Block("literal", lines=literal))
    end_para()
    return blocks


def _rst_line(troff: str) -> str:
    """One paragraph of troff text as one line of reStructuredText,
    escaped so that it cannot start a list, a block or a section."""
    runs, _ = _runs(troff)
    text = re.sub(r"\s+", " ", _rst_text(runs)).strip()
    if re.match(r"[-+#>:.(\d\u2022\u2023\u2043=~^\"'<!$%&,;?@\[\]{}/]",
                text):
        text = "\\" + text
    text = re.sub(r"::$", r":\\:", text)
    return text


def troff_to_rst(text: Optional[str], indent: str = "") -> list[str]:
    """Lines of reStructuredText (blocks separated by blank lines, every
    line starting with ``indent``) for a troff documentation string."""
    if not text:
        return []
    out: list[str] = []

    def emit(lines: list[str]) -> None:
        if out:
            out.append("")
        out.extend(indent + ln if ln else "" for ln in lines)

    for b in _blocks(text):
        if b.kind == "para":
            line = _rst_line(b.text)
            if line:
                emit([line])
        elif b.kind == "rubric":
            line = _rst_line(b.text)
            if line:
                emit([f".. rubric:: {line}"])
        elif b.kind == "bullet":
            line = _rst_line(b.text)
            emit([f"- {line}" if line else "-"])
        elif b.kind == "term":
            term = _rst_line(b.text) or "\\ "
            body = troff_to_rst("\n".join(b.lines or []), "   ")
            emit([term] + (body if body else ["   \\ "]))
        elif b.kind == "literal":
            lines = textwrap.dedent("\n".join(
                ln.rstrip().expandtabs() for ln in b.lines or [])).split("\n")
            while lines and not lines[-1]:
                lines.pop()
            while lines and not lines[0]:
                lines.pop(0)
            if lines:
                emit([".. code-block:: none", ""]
                     + ["   " + ln if ln else "" for ln in lines])
    return out


# ------------------------------------------------------------------ rst


def _literal(text: str) -> str:
    """``text`` as an inline literal (or escaped text if it cannot be)."""
    text = text.strip()
    if not text:
        return ""
    if "``" in text or text.endswith("`") or text.startswith("`"):
        return _RST_PLAIN.sub(r"\\\1", text)
    return f"``{text}``"


def _rst_table(header: Sequence[str], rows: Sequence[Sequence[list[str]]],
               widths: Sequence[int]) -> list[str]:
    out = [".. list-table::", "   :header-rows: 1",
           "   :widths: " + " ".join(str(w) for w in widths), ""]
    for row in [[[h] for h in header]] + list(rows):
        for c, cell in enumerate(row):
            first = "   * - " if c == 0 else "     - "
            cell = cell or []
            if not cell:
                out.append(first.rstrip())
                continue
            out.append(first + cell[0])
            out.extend(("       " + ln) if ln else "" for ln in cell[1:])
    return out


def _plain(parts: Iterable[tuple[str, bool]]) -> str:
    return "".join(text for text, _ in parts)


def _rst_item_rows(items: Sequence[_Item]) -> list[list[list[str]]]:
    rows = []
    for item in items:
        name = [_literal(_plain(item.parts))]
        if item.index:
            name += ["", _rst_line(_man_escape(item.index))]
        if item.condition:
            name += ["", "only if " + _literal(item.condition)]
        default = [_literal(item.default)] if item.default is not None \
            else []
        rows.append([name, [item.type], [item.direction], default,
                     troff_to_rst(item.doc)])
    return rows


def _title(text: str, char: str) -> list[str]:
    """A section title and its underline, as wide as the title."""
    width = sum(2 if unicodedata.east_asian_width(c) in "WF" else
                0 if unicodedata.combining(c) else 1 for c in text)
    return [text, char * max(4, width)]


def rst_page(comp: Component) -> str:
    """The reStructuredText page of ``comp``: the content of its manual
    page, with tables for functions, pins and parameters.  It starts
    with the label ``hal-component-NAME`` for references."""
    lines = [f".. _hal-component-{comp.name}:", ""]
    lines += [f".. Generated by halsdk's halcompile from "
              f"{os.path.basename(comp.file)}; edit the .comp file.", ""]
    short = _rst_line(comp.doc) if comp.doc and comp.doc.strip() else ""
    lines += _title(comp.name + (" \u2014 " + short if short else ""), "=")

    def section(title: str, body: list[str]) -> None:
        if body:
            lines.extend([""] + _title(title, "-") + [""] + body)

    synopsis = [".. code-block:: none", "", "   " + _synopsis(comp)]
    for lp in _load_params(comp):
        term = _literal(lp.name)
        if lp.default is not None:
            term += " (default: " + _literal(lp.default) + ")"
        synopsis += ["", term, "   " + _rst_line(_man_escape(lp.text))]
        if lp.doc:
            synopsis += [""] + troff_to_rst(lp.doc, "   ")
    section("Synopsis", synopsis)
    section("Description", troff_to_rst(comp.description))

    functions = [_function_item(comp, f) for f in _functions(comp)]
    if functions:
        rows = [[[_literal(_plain(f.parts))], ["yes" if f.fp else "no"],
                 troff_to_rst(f.doc)] for f in functions]
        section("Functions", _rst_table(
            ["Function", "Floating point", "Description"], rows,
            [30, 12, 58]))
    header = ["Name", "Type", "Direction", "Default", "Description"]
    widths = [30, 8, 10, 12, 40]
    if comp.pins:
        section("Pins", _rst_table(
            header, _rst_item_rows([_pin_item(comp, p)
                                    for p in comp.pins]), widths))
    if comp.params:
        section("Parameters", _rst_table(
            header, _rst_item_rows([_pin_item(comp, p)
                                    for p in comp.params]), widths))
    section("Notes", troff_to_rst(comp.notes))
    section("Examples", troff_to_rst(comp.examples))
    section("See also", troff_to_rst(comp.see_also))
    if comp.authors:
        section("Author", ["| " + _rst_line(_man_escape(a))
                           for a in comp.authors])
    if comp.license:
        section("License", [_rst_line(_man_escape(comp.license))])
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ files


def render(comp: Component, fmt: str) -> str:
    """The page of ``comp`` in format ``fmt`` (``man`` or ``rst``)."""
    if fmt == "man":
        return man_page(comp)
    if fmt == "rst":
        return rst_page(comp)
    raise ValueError(f"unknown documentation format {fmt!r} "
                     f"(formats: {', '.join(FORMATS)})")


def document(comp_path: str, out_dir: str,
             formats: Sequence[str] = FORMATS) -> list[str]:
    """Write the pages of the ``.comp`` file ``comp_path`` into
    ``out_dir`` (made if missing): ``NAME.9`` (manual page; ``NAME.1``
    for a userspace component) and ``NAME.rst``; returns the paths
    written.  Raises
    :class:`~halcompile.parser.CompError` for a bad ``.comp``."""
    comp = parse_file(comp_path)
    for fmt in formats:
        if fmt not in FORMATS:
            raise ValueError(f"unknown documentation format {fmt!r} "
                             f"(formats: {', '.join(FORMATS)})")
    os.makedirs(out_dir, exist_ok=True)
    written = []
    for fmt in formats:
        path = os.path.join(out_dir, file_name(comp, fmt))
        text = render(comp, fmt)
        tmp = path + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
        written.append(path)
    return written


def man_dir() -> str:
    """The user's manual folder (``man`` searches it when ``~/.local/bin``
    is on ``PATH``): ``$XDG_DATA_HOME/man`` or ``~/.local/share/man``."""
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(
        os.path.expanduser("~"), ".local", "share")
    return os.path.join(base, "man")


def install_doc(comp_path: str, dest: Optional[str] = None) -> str:
    """Install the manual page of ``comp_path`` as ``man9/NAME.9`` (or
    ``man1/NAME.1``, userspace) under ``dest`` (default:
    :func:`man_dir`); returns its path."""
    section = man_section(parse_file(comp_path))
    return document(comp_path, os.path.join(dest or man_dir(),
                                             "man" + section), ("man",))[0]


def view_doc(comp_path: str) -> int:
    """Show the manual page of ``comp_path``: formatted by ``man -l`` if
    ``man`` is installed, else as its troff text.  Returns ``man``'s exit
    status (0 when printing the text)."""
    comp = parse_file(comp_path)
    text = man_page(comp)
    man = shutil.which("man")
    if man is None:
        sys.stdout.write(text)
        sys.stdout.flush()
        return 0
    with tempfile.TemporaryDirectory(prefix="halcompile-doc-") as tmp:
        path = os.path.join(tmp, file_name(comp, "man"))
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
        sys.stdout.flush()
        return subprocess.call([man, "-l", path])


__all__ = ["FORMATS", "document", "file_name", "install_doc", "man_dir",
           "man_page", "man_section", "render", "rst_page", "troff_to_rst",
           "view_doc"]
