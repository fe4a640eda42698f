"""Reading one line of G-code into words, assignments, comments and o-words.

Values stay expression trees (see :mod:`.expr`); they are evaluated when
the program reaches the line.  Whitespace outside comments is dropped and
letters are lower-cased, but every character keeps its source column so
errors point at the right place.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Callable, Optional

from .errors import GCodeError
from .expr import (
    BINARY,
    FUNCTIONS,
    Atan,
    Binary,
    Exists,
    Expr,
    Function,
    Negate,
    Number,
    ParamRef,
)

#: Letters that may start a word (o-words are handled apart).
WORD_LETTERS = frozenset("abcdefghijklmnpqrstuvwxyz")

#: The o-word keywords.
O_KEYWORDS = ("sub", "endsub", "return", "call", "if", "elseif", "else",
              "endif", "while", "endwhile", "do", "repeat", "endrepeat",
              "break", "continue")


@dataclass
class Word:
    letter: str
    value: Expr
    column: int


@dataclass
class Assignment:
    target: ParamRef
    value: Expr
    column: int


@dataclass
class OWord:
    """``o<name> keyword [args]``; ``name`` is a string (``'100'`` or a
    lower-case name) or an expression for ``o[#1] call``."""

    name: str | Expr
    keyword: str
    args: list[Expr]
    column: int


@dataclass
class Comment:
    """A comment; ``kind`` is 'msg', 'debug', 'print' or '' (plain)."""

    text: str
    kind: str
    column: int


@dataclass
class Line:
    """One source line as read, not yet evaluated."""

    file: str
    number: int
    text: str
    block_delete: bool = False
    line_number: Optional[float] = None
    words: list[Word] = field(default_factory=list)
    assignments: list[Assignment] = field(default_factory=list)
    comments: list[Comment] = field(default_factory=list)
    oword: Optional[OWord] = None
    percent: bool = False

    @property
    def empty(self) -> bool:
        return not (self.words or self.assignments or self.oword
                    or self.comments)


class _Reader:
    """A cursor over the significant characters of a line."""

    def __init__(self, chars: list[tuple[str, int]], file: str, line: int,
                 end_column: int) -> None:
        self.chars = chars
        self.pos = 0
        self.file = file
        self.line = line
        self.end_column = end_column

    def peek(self, offset: int = 0) -> str:
        index = self.pos + offset
        return self.chars[index][0] if index < len(self.chars) else ""

    def column(self) -> int:
        if self.pos < len(self.chars):
            return self.chars[self.pos][1]
        return self.end_column

    def take(self) -> str:
        char = self.peek()
        self.pos += 1
        return char

    def at_end(self) -> bool:
        return self.pos >= len(self.chars)

    def error(self, message: str, column: Optional[int] = None) -> GCodeError:
        return GCodeError(message, self.file, self.line,
                          self.column() if column is None else column)

    def startswith(self, text: str) -> bool:
        return all(self.peek(i) == c for i, c in enumerate(text))

    def column_at(self, index: int) -> int:
        """The column of significant character ``index``."""
        return self.chars[index][1]


#: ASCII white space (what str.isspace() is true for)
_SPACE = "[ \t\n\r\x0b\x0c\x1c-\x1f]"
_SIGNIFICANT = re.compile(f"{_SPACE}*([^ \t\n\r\x0b\x0c\x1c-\x1f(;]*)")
_NUMBER = re.compile(r"[+-]?[0-9.]*")
_UNSIGNED = re.compile(r"[0-9.]*")
_WORD = re.compile(r"[a-z]*")
_OPERATOR = re.compile(r"\*\*|[*/+-]|mod|eq|ne|gt|ge|lt|le|and|or|xor")


class _AsciiReader(_Reader):
    """The reader of an ASCII line: the significant characters as one
    string, so that numbers, names and operators are read with regular
    expressions (what the character loops of the other reader read)."""

    def __init__(self, text: str, columns: list[int], file: str, line: int,
                 end_column: int) -> None:
        self.text = text
        self.columns = columns
        self.size = len(text)
        self.pos = 0
        self.file = file
        self.line = line
        self.end_column = end_column

    def peek(self, offset: int = 0) -> str:
        index = self.pos + offset
        return self.text[index] if index < self.size else ""

    def column(self) -> int:
        if self.pos < self.size:
            return self.columns[self.pos]
        return self.end_column

    def take(self) -> str:
        pos = self.pos
        self.pos = pos + 1
        return self.text[pos] if pos < self.size else ""

    def at_end(self) -> bool:
        return self.pos >= self.size

    def startswith(self, text: str) -> bool:
        return self.text.startswith(text, self.pos)

    def column_at(self, index: int) -> int:
        return self.columns[index]

    def match(self, pattern: re.Pattern[str]) -> str:
        """The text ``pattern`` matches at the cursor (it always
        matches), consumed."""
        match = pattern.match(self.text, self.pos)
        assert match is not None
        self.pos = match.end()
        return match.group()


def _strip_ascii(text: str, file: str, lineno: int
                 ) -> tuple[str, list[int], list[Comment]]:
    """:func:`_strip` of an ASCII line: the significant characters
    (lower case) as one string, their columns, the comments."""
    parts: list[str] = []
    columns: list[int] = []
    comments: list[Comment] = []
    i = 0
    size = len(text)
    significant = _SIGNIFICANT.match
    while i < size:
        run = significant(text, i)
        assert run is not None
        start, end = run.span(1)
        if end > start:
            parts.append(run.group(1))
            columns.extend(range(start + 1, end + 1))
        i = end
        if i >= size:
            break
        char = text[i]
        if char == "(":
            comment, i = _paren_comment(text, i, file, lineno)
            comments.append(comment)
        elif char == ";":
            comments.append(Comment(text[i + 1:].strip(), "", i + 1))
            break
        # else white space: the next search skips it
    return "".join(parts).lower(), columns, comments


def _paren_comment(text: str, i: int, file: str, lineno: int
                   ) -> tuple[Comment, int]:
    """The comment that opens at ``text[i]`` (a ``(``) and the index
    after its ``)``."""
    end = text.find(")", i + 1)
    if end < 0:
        raise GCodeError("Unclosed comment found",
                         file, lineno, i + 1)
    nested = text.find("(", i + 1, end)
    if nested >= 0:
        raise GCodeError("Nested comment found",
                         file, lineno, nested + 1)
    return _comment(text[i + 1:end], i + 1), end + 1


def _strip(text: str, file: str, lineno: int
           ) -> tuple[list[tuple[str, int]], list[Comment]]:
    """Split a line into significant characters (with columns) and
    comments."""
    chars: list[tuple[str, int]] = []
    comments: list[Comment] = []
    i = 0
    while i < len(text):
        char = text[i]
        if char == "(":
            comment, i = _paren_comment(text, i, file, lineno)
            comments.append(comment)
            continue
        if char == ";":
            comments.append(Comment(text[i + 1:].strip(), "", i + 1))
            break
        if not char.isspace():
            chars.append((char.lower(), i + 1))
        i += 1
    return chars, comments


def _comment(body: str, column: int) -> Comment:
    head, comma, rest = body.partition(",")
    kind = "".join(head.split()).lower()
    if comma and kind in ("msg", "debug", "print"):
        return Comment(rest.strip() if kind == "msg" else rest, kind, column)
    return Comment(body, "", column)


def parse_line(text: str, file: str = "<string>", lineno: int = 1) -> Line:
    """Read one line of G-code; raises :class:`GCodeError` with its column.

    The compiled lexer (``_lex.pyx``) reads the lines it can; any other
    line, and every line with an error, is read by
    :func:`parse_line_python`, which says what is wrong."""
    if _compiled_parse_line is not None:
        line = _compiled_parse_line(text, file, lineno)
        if line is not None:
            return line
    return parse_line_python(text, file, lineno)


def parse_line_python(text: str, file: str = "<string>",
                      lineno: int = 1) -> Line:
    """:func:`parse_line` in Python: the reference of its behaviour."""
    text = text.rstrip("\r\n")
    reader: _Reader
    if text.isascii():
        significant, columns, comments = _strip_ascii(text, file, lineno)
        reader = _AsciiReader(significant, columns, file, lineno,
                              len(text) + 1)
    else:
        chars, comments = _strip(text, file, lineno)
        reader = _Reader(chars, file, lineno, len(text) + 1)
    return _read_line(reader, Line(file, lineno, text, comments=comments))


def _read_line(reader: _Reader, line: Line) -> Line:
    """The words, assignments and o-word of ``line`` from ``reader``."""
    if reader.peek() == "%":
        reader.take()
        if not reader.at_end():
            raise reader.error("Bad character '%' used")
        line.percent = True
        return line
    if reader.peek() == "/":
        reader.take()
        line.block_delete = True
    if reader.peek() == "n":
        reader.take()
        line.line_number = _unsigned_number(reader)
    if reader.peek() == "o":
        line.oword = _oword(reader)
        if not reader.at_end():
            raise reader.error("Unexpected character after O-word")
        return line
    seen: dict[str, int] = {}
    while not reader.at_end():
        column = reader.column()
        char = reader.peek()
        if char == "#":
            target = _parameter(reader)
            if reader.peek() != "=":
                raise reader.error("Equal sign missing in parameter setting")
            reader.take()
            line.assignments.append(
                Assignment(target, _real_value(reader), column))
            continue
        if char not in WORD_LETTERS:
            if char == "o":
                raise reader.error("Bad character 'o' used")
            if char.isalpha():
                raise reader.error(f"unknown word letter '{char.upper()}'")
            if char in "$^":
                raise reader.error("No characters found in reading real "
                                   "value")
            raise reader.error(f"Bad character '{char}' used")
        reader.take()
        if char == "n":
            raise reader.error("Bad character 'n' used", column)
        if char not in "gm":
            if char in seen:
                raise reader.error(f"Multiple {char} words on one line",
                                   column)
            seen[char] = column
        line.words.append(Word(char, _real_value(reader), column))
    return line


def _unsigned_number(reader: _Reader) -> float:
    start = reader.column()
    if isinstance(reader, _AsciiReader):
        digits = reader.match(_UNSIGNED)
    else:
        digits = ""
        while reader.peek().isdigit() or reader.peek() == ".":
            digits += reader.take()
    try:
        return float(digits)
    except ValueError:
        raise reader.error("Bad format unsigned integer", start) from None


def _number(reader: _Reader) -> Number:
    """A decimal number with optional sign: ``-1.5``, ``+.25``, ``3``."""
    start = reader.column()
    if isinstance(reader, _AsciiReader):
        pos = reader.pos
        text = reader.match(_NUMBER)
        if text.count(".") < 2 and any(c.isdigit() for c in text):
            return Number(float(text), start)
        reader.pos = pos            # the loop below says what is wrong
    text = ""
    if reader.peek() and reader.peek() in "+-":
        text += reader.take()
    seen_dot = False
    digits = 0
    while reader.peek().isdigit() or reader.peek() == ".":
        char = reader.take()
        if char == ".":
            if seen_dot:
                column = reader.column_at(reader.pos - 1)
                text += char
                while reader.peek().isdigit() or reader.peek() == ".":
                    text += reader.take()
                raise reader.error("bad number format (trailing characters) "
                                   f"parsing '{text}'", column)
            seen_dot = True
        else:
            digits += 1
        text += char
    if not digits:
        if not text and reader.at_end():
            raise reader.error("No characters found in reading real value",
                               start)
        raise reader.error("bad number format (conversion failed) parsing "
                           f"'{text}'", start)
    return Number(float(text), start)


def _starts_operand(char: str) -> bool:
    """True if ``char`` starts a bracket, parameter or function."""
    return char in ("[", "#") or char.isalpha()


def _real_value(reader: _Reader) -> Expr:
    """A word value: number, ``[expr]``, ``#param``, a function call or a
    signed one of these."""
    char = reader.peek()
    column = reader.column()
    if char == "[":
        return _bracketed(reader)
    if char == "#":
        return _parameter(reader)
    if char and char in "+-" and _starts_operand(reader.peek(1)):
        # a sign before [expr], #param or a function
        reader.take()
        operand = _real_value(reader)
        return Negate(operand, column) if char == "-" else operand
    if char.isalpha():
        return _function(reader)
    return _number(reader)


def _bracketed(reader: _Reader) -> Expr:
    open_column = reader.column()
    reader.take()
    value = _expression(reader, 1)
    if reader.peek() != "]":
        if reader.at_end():
            raise reader.error("Unclosed expression", open_column)
        if reader.peek().isalpha():
            raise reader.error("Unknown operation name starting with "
                               f"{reader.peek()}")
        raise reader.error("Unknown operation")
    reader.take()
    return value


def _operator(reader: _Reader) -> Optional[str]:
    if isinstance(reader, _AsciiReader):
        match = _OPERATOR.match(reader.text, reader.pos)
        return match.group() if match is not None else None
    if reader.startswith("**"):
        return "**"
    if reader.peek() in ("*", "/", "+", "-"):
        return reader.peek()
    for name in ("mod", "eq", "ne", "gt", "ge", "lt", "le", "and", "or",
                 "xor"):
        if reader.startswith(name):
            return name
    return None


def _expression(reader: _Reader, min_precedence: int) -> Expr:
    """Precedence climbing over :data:`BINARY`; equal precedence is
    left-associative."""
    left = _real_value(reader)
    while True:
        op = _operator(reader)
        if op is None or BINARY[op][0] < min_precedence:
            return left
        column = reader.column()
        reader.pos += len(op)
        right = _expression(reader, BINARY[op][0] + 1)
        left = Binary(op, left, right, column)


def _function(reader: _Reader) -> Expr:
    column = reader.column()
    if isinstance(reader, _AsciiReader):
        name = reader.match(_WORD)
    else:
        name = ""
        while reader.peek().isalpha():
            name += reader.take()
    if name == "atan":
        if reader.peek() != "[":
            raise reader.error("Left bracket missing after unary operation "
                               "name")
        y = _bracketed(reader)
        if reader.peek() != "/":
            raise reader.error("Slash missing after first atan argument")
        reader.take()
        if reader.peek() != "[":
            raise reader.error("Left bracket missing after slash with atan")
        return Atan(y, _bracketed(reader), column)
    if name == "exists":
        if reader.peek() != "[":
            raise reader.error("EXISTS needs [#<name>]")
        open_column = reader.column()
        reader.take()
        if not (reader.peek() == "#" and reader.peek(1) == "<"):
            raise reader.error("Expected # reading parameter")
        reader.take()
        target = _name(reader)
        if reader.peek() != "]":
            if reader.at_end():
                raise reader.error("unclosed bracket: '[' without ']'",
                                   open_column)
            raise reader.error("EXISTS takes one named parameter #<name>")
        reader.take()
        return Exists(target, column)
    if name not in FUNCTIONS:
        raise reader.error(f"Unknown word starting with {name[:1]}",
                           column)
    if reader.peek() != "[":
        raise reader.error("Left bracket missing after unary operation "
                           "name")
    return Function(name, _bracketed(reader), column)


def _name(reader: _Reader) -> str:
    """``<name>`` (the cursor is on '<'): lower case, no spaces."""
    open_column = reader.column()
    reader.take()
    if isinstance(reader, _AsciiReader):
        end = reader.text.find(">", reader.pos)
        end = reader.size if end < 0 else end
        name = reader.text[reader.pos:end]
        reader.pos = end
    else:
        name = ""
        while not reader.at_end() and reader.peek() != ">":
            name += reader.take()
    if reader.at_end():
        raise reader.error("Named parameter not terminated",
                           open_column)
    reader.take()
    if not name:
        raise reader.error("Named parameter #<> not defined", open_column)
    return name


def _parameter(reader: _Reader) -> ParamRef:
    """``#n``, ``#<name>``, ``#[expr]``, ``##n`` (cursor on '#')."""
    column = reader.column()
    reader.take()
    char = reader.peek()
    if char == "<":
        return ParamRef(_name(reader), column)
    if char == "#":
        return ParamRef(_parameter(reader), column)
    if char == "[":
        return ParamRef(_bracketed(reader), column)
    if char.isdigit():
        return ParamRef(_number(reader), column)
    if char == "-":
        raise reader.error("Parameter number out of range")
    raise reader.error("bad number format (conversion failed) parsing ''")


def _oword(reader: _Reader) -> OWord:
    column = reader.column()
    reader.take()
    name: str | Expr
    if reader.peek() == "<":
        name = _name(reader)
    elif reader.peek() == "[" or reader.peek() == "#":
        name = _real_value(reader)
    elif reader.peek().isdigit():
        number = _unsigned_number(reader)
        name = f"{number:g}"
    else:
        raise reader.error("No characters found in reading real value")
    keyword_column = reader.column()
    if isinstance(reader, _AsciiReader):
        keyword = reader.match(_WORD)
    else:
        keyword = ""
        while reader.peek().isalpha():
            keyword += reader.take()
    if keyword not in O_KEYWORDS:
        raise reader.error("Unknown control command in o word",
                           keyword_column)
    args: list[Expr] = []
    if keyword in ("if", "elseif", "while", "repeat", "return", "endsub",
                   "call"):
        while reader.peek() == "[":
            args.append(_bracketed(reader))
    if keyword in ("if", "elseif", "while", "repeat") and len(args) != 1:
        raise reader.error(f"Left bracket missing after '{keyword}'"
                           if not args else
                           "Unexpected character after O-word")
    if keyword in ("return", "endsub") and len(args) > 1:
        raise reader.error("Unexpected character after O-word")
    return OWord(name, keyword, args, column)


_compiled_parse_line: Optional[Callable[[str, str, int], Optional[Line]]]
try:
    from ._lex import parse_line as _compiled_parse_line
except ImportError:     # pragma: no cover - not built: Python only
    _compiled_parse_line = None
