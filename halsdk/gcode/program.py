"""A G-code program: its lines, o-word structure and execution order."""

from __future__ import annotations

import os
import re
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Optional

from .block import Block, code_key
from .errors import GCodeError
from .expr import Expr, ParamRef, Where
from .lexer import Line, OWord, parse_line
from .params import Parameters

#: Default limit of the control-flow work of one run of a program: loop
#: iterations (every entry into the body of a while, do or repeat loop, of
#: every loop, nested or not, counted together) plus subroutine calls.
#: Ten times a loop of 100,000 moves, which is already a long job; a loop
#: that spins without an end reaches it in about a second.
MAX_ITERATIONS = 1_000_000

#: Default limit, in seconds, of the time the control flow may run without
#: handing the interpreter a block that does something (a code, a word or
#: a message): the time the consumer spends on blocks is not counted.
MAX_IDLE_TIME = 5.0

#: Default limit of nested subroutine calls.
MAX_CALL_DEPTH = 64

_LOOP_OPENERS = ("while", "do", "repeat")
_DEBUG_PARAM = re.compile(r"#\s*<([^>]*)>|#\s*(\d+)")


@dataclass
class _Structure:
    """Where the partner lines of each o-word line are (indexes)."""

    subs: dict[str, tuple[int, int]] = field(default_factory=dict)
    # if line -> [elseif/else lines..., endif line]
    branches: dict[int, list[int]] = field(default_factory=dict)
    # elseif/else line -> endif line
    endif_of: dict[int, int] = field(default_factory=dict)
    # loop opener <-> closer
    loop_end: dict[int, int] = field(default_factory=dict)
    loop_start: dict[int, int] = field(default_factory=dict)
    # break/continue -> loop opener
    loop_of: dict[int, int] = field(default_factory=dict)
    # line index -> the sub it belongs to
    sub_of: dict[int, str] = field(default_factory=dict)


class _Unit:
    """One source file (or string): its lines and their structure."""

    def __init__(self, text: str, file: str) -> None:
        self.file = file
        self.lines: list[Line | GCodeError] = []
        for number, source in enumerate(text.splitlines(), start=1):
            try:
                self.lines.append(parse_line(source, file, number))
            except GCodeError as exc:
                self.lines.append(exc)
        self.structure = _scan(self)

    def oword(self, index: int) -> Optional[OWord]:
        line = self.lines[index]
        return line.oword if isinstance(line, Line) else None

    def keyword(self, index: int) -> str:
        """The keyword of line ``index``, which the scan found an o-word."""
        oword = self.oword(index)
        if oword is None:
            raise RuntimeError(f"{self.file}: line {index + 1} is not an "
                               "o-word")
        return oword.keyword


def _name_text(oword: OWord) -> str:
    return oword.name if isinstance(oword.name, str) else "?"


def _label(name: str) -> str:
    """How an o-word is shown in messages: ``O100`` or ``O<name>``."""
    return f"O{name}" if name[:1].isdigit() else f"O<{name}>"


def _scan(unit: _Unit) -> _Structure:
    """Match sub/endsub, if/endif, loops; raise on mismatches."""
    result = _Structure()
    stack: list[tuple[str, str, int]] = []      # (keyword, name, index)
    current_sub: Optional[tuple[str, int]] = None

    def fail(index: int, message: str) -> GCodeError:
        line = unit.lines[index]
        assert isinstance(line, Line) and line.oword is not None
        return GCodeError(message, unit.file, line.number, line.oword.column)

    for index in range(len(unit.lines)):
        oword = unit.oword(index)
        if current_sub is not None:
            result.sub_of[index] = current_sub[0]
        if oword is None:
            continue
        name, keyword = _name_text(oword), oword.keyword
        label = _label(name)
        if keyword == "sub":
            if current_sub is not None:
                raise fail(index, f"{label} sub inside subroutine "
                                  f"o<{current_sub[0]}>")
            if name in result.subs:
                raise fail(index, f"{label} sub defined twice")
            current_sub = (name, index)
            result.sub_of[index] = name
        elif keyword == "endsub":
            if current_sub is None:
                raise fail(index, f"{label} endsub without sub")
            if stack:
                kind, open_name, _ = stack[-1]
                raise fail(index, f"{label} endsub before the end of "
                                  f"{_label(open_name)} {kind}")
            if current_sub[0] != name:
                raise fail(index, f"{label} endsub does not match "
                                  f"o<{current_sub[0]}> sub")
            result.subs[name] = (current_sub[1], index)
            current_sub = None
        elif keyword == "return":
            if current_sub is None or current_sub[0] != name:
                raise fail(index, f"{label} return outside subroutine "
                                  f"{label}")
        elif keyword == "if":
            stack.append(("if", name, index))
            result.branches[index] = []
        elif keyword in ("elseif", "else", "endif"):
            if not stack or stack[-1][0] != "if" or stack[-1][1] != name:
                raise fail(index, f"{label} {keyword} without {label} if")
            opener = stack[-1][2]
            branches = result.branches[opener]
            if branches and unit.keyword(branches[-1]) == "else" \
                    and keyword != "endif":
                raise fail(index, f"{label} {keyword} after {label} else")
            branches.append(index)
            if keyword == "endif":
                stack.pop()
                for branch in branches[:-1]:
                    result.endif_of[branch] = index
        elif keyword in ("while", "do", "repeat"):
            if keyword == "while" and stack and stack[-1][0] == "do" \
                    and stack[-1][1] == name:
                opener = stack.pop()[2]
                result.loop_end[opener] = index
                result.loop_start[index] = opener
            else:
                stack.append((keyword, name, index))
        elif keyword in ("endwhile", "endrepeat"):
            wanted = keyword[3:]
            if not stack or stack[-1][0] != wanted or stack[-1][1] != name:
                raise fail(index, f"{label} {keyword} without {label} "
                                  f"{wanted}")
            opener = stack.pop()[2]
            result.loop_end[opener] = index
            result.loop_start[index] = opener
        elif keyword in ("break", "continue"):
            loops = [entry for entry in stack
                     if entry[0] in _LOOP_OPENERS and entry[1] == name]
            if not loops:
                raise fail(index, f"{label} {keyword} outside loop {label}")
            result.loop_of[index] = loops[-1][2]
        elif keyword == "call":
            pass
    if stack:
        kind, name, index = stack[-1]
        closer = {"if": "endif", "while": "endwhile", "do": "while",
                  "repeat": "endrepeat"}[kind]
        raise fail(index, f"{_label(name)} {kind} without {_label(name)} "
                          f"{closer}")
    if current_sub is not None:
        raise fail(current_sub[1],
                   f"{_label(current_sub[0])} sub without endsub")
    return result


@dataclass
class _Frame:
    """A subroutine call in progress."""

    return_unit: _Unit
    return_index: int
    name: str


class Program:
    """A G-code program: lines, expressions, parameters, o-word subroutines
    and loops.

    ``blocks()`` runs the control flow and yields the executable
    :class:`Block` objects in order.  ``search_path`` lists directories
    searched for ``<name>.ngc`` when ``o<name> call`` names no subroutine
    of the program.  With ``block_delete=True`` lines starting with '/'
    are skipped; otherwise they are yielded with ``block_delete`` set.

    Runaway control flow is an error (a :class:`GCodeError` at the line of
    the loop or call): one run may do at most ``max_iterations`` loop
    iterations and subroutine calls in total (all loops and calls counted
    together; :attr:`iterations` is the count), and its control flow may
    run at most ``max_idle_time`` seconds (measured with ``clock``)
    without handing out a block that has a code, a word or a message.
    """

    def __init__(self, text: str, file: str = "<string>",
                 params: Parameters | None = None,
                 search_path: Sequence[str] = (), *,
                 block_delete: bool = False,
                 max_iterations: int = MAX_ITERATIONS,
                 max_idle_time: float = MAX_IDLE_TIME,
                 max_call_depth: int = MAX_CALL_DEPTH,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not max_iterations >= 1:
            raise ValueError(f"max_iterations must be at least 1, not "
                             f"{max_iterations!r}")
        if not max_idle_time > 0:
            raise ValueError(f"max_idle_time must be more than 0 s, not "
                             f"{max_idle_time!r}")
        self.file = file
        self.params = params if params is not None else Parameters()
        self.search_path = list(search_path)
        self.block_delete = block_delete
        self.max_iterations = int(max_iterations)
        self.max_idle_time = float(max_idle_time)
        self.max_call_depth = max_call_depth
        self.clock = clock
        #: loop iterations and subroutine calls of the current (or last)
        #: run of :meth:`blocks`; never more than ``max_iterations``
        self.iterations = 0
        self._idle_since = 0.0
        self._frames: list[_Frame] = []
        self._main = _Unit(text, file)
        self._files: dict[str, _Unit] = {}

    @classmethod
    def from_file(cls, path: str, params: Parameters | None = None,
                  search_path: Sequence[str] = (), **options: object
                  ) -> Program:
        """Read a program file; its directory is searched for subroutine
        files after ``search_path``."""
        try:
            with open(path, encoding="utf-8") as stream:
                text = stream.read()
        except OSError as exc:
            raise GCodeError(f"cannot read program: {exc.strerror}",
                             path) from None
        directory = os.path.dirname(os.path.abspath(path))
        return cls(text, path, params, [*search_path, directory],
                   **options)  # type: ignore[arg-type]

    # -- subroutine lookup -----------------------------------------------
    def _find_sub(self, name: str, unit: _Unit) -> Optional[_Unit]:
        for candidate in (unit, self._main):
            if name in candidate.structure.subs:
                return candidate
        if name in self._files:
            return self._files[name]
        for directory in self.search_path:
            path = os.path.join(directory, name + ".ngc")
            if os.path.isfile(path):
                try:
                    with open(path, encoding="utf-8") as stream:
                        text = stream.read()
                except OSError as exc:
                    raise GCodeError(f"cannot read subroutine file: "
                                     f"{exc.strerror}", path) from None
                loaded = _Unit(text, path)
                if name not in loaded.structure.subs:
                    raise GCodeError(f"file defines no o<{name}> sub", path,
                                     1, 1)
                self._files[name] = loaded
                return loaded
        return None

    # -- evaluation helpers ------------------------------------------------
    def _value(self, expr: Expr, line: Line) -> float:
        return expr.evaluate(self.params, Where(line.file, line.number))

    def _set(self, key: int | str, value: float, line: Line,
             column: int) -> None:
        try:
            self.params.set(key, value)
        except GCodeError as exc:
            raise GCodeError(exc.message, line.file, line.number,
                             column) from None

    def _debug_text(self, text: str) -> str:
        def substitute(match: re.Match[str]) -> str:
            key: int | str = match.group(1) if match.group(1) is not None \
                else int(match.group(2))
            try:
                return f"{self.params.get(key):.6f}"
            except GCodeError:
                return "#"
        return _DEBUG_PARAM.sub(substitute, text)

    def _block(self, line: Line) -> Block:
        """Evaluate the words of ``line`` and apply its assignments."""
        block = Block(line.file, line.number, line.text,
                      block_delete=line.block_delete,
                      line_number=line.line_number)
        for word in line.words:
            value = self._value(word.value, line)
            if word.letter in "gm":
                value = round(value, 4)
                key = code_key(word.letter, value)
                (block.g if word.letter == "g" else block.m).append(value)
                block.columns.setdefault(key, word.column)
                block.columns.setdefault(word.letter, word.column)
            else:
                block.words[word.letter] = value
                block.columns[word.letter] = word.column
        values = [(self._parameter_key(a.target, line),
                   self._value(a.value, line), a.column)
                  for a in line.assignments]
        for param, value, column in values:
            self._set(param, value, line, column)
        for comment in line.comments:
            if comment.kind == "msg":
                block.message = comment.text
            elif comment.kind in ("debug", "print"):
                block.message = self._debug_text(comment.text).strip()
            else:
                block.comments.append(comment.text)
        return block

    def _parameter_key(self, target: Expr, line: Line) -> int | str:
        assert isinstance(target, ParamRef)
        return target.key(self.params, Where(line.file, line.number))

    # -- execution -------------------------------------------------------
    @property
    def call_level(self) -> int:
        """How deep the running :meth:`blocks` is in subroutine calls (0:
        the main program), as the reference's status ``call_level``."""
        return len(self._frames)

    def blocks(self) -> Iterator[Block]:
        """The blocks in execution order (see the class docstring); ends at
        M2/M30, the closing '%' or the end of the file."""
        self.params.reset_scopes()
        self.iterations = 0
        self._idle_since = self.clock()
        try:
            yield from self._run()
        finally:
            self.params.reset_scopes()

    def _run(self) -> Iterator[Block]:
        unit = self._main
        index = 0
        frames: list[_Frame] = []
        self._frames = frames
        repeats: dict[tuple[int, int], int] = {}
        seen_code = False
        clock = self.clock
        while True:
            if index >= len(unit.lines):
                if frames:  # pragma: no cover - the scan rules it out
                    raise GCodeError(
                        f"end of file inside {_label(frames[-1].name)}",
                        unit.file, len(unit.lines), 1)
                return
            entry = unit.lines[index]
            if isinstance(entry, GCodeError):
                raise entry
            line = entry
            structure = unit.structure
            if not frames and index in structure.sub_of:
                # a subroutine definition met in the main flow: skip it
                index = structure.subs[structure.sub_of[index]][1] + 1
                continue
            if line.percent:
                if seen_code or index > 0 and any(
                        isinstance(x, Line) and x.percent
                        for x in unit.lines[:index]):
                    return
                index += 1
                continue
            if line.block_delete and self.block_delete:
                index += 1
                continue
            oword = line.oword
            if oword is None:
                index += 1
                if line.empty:
                    continue
                if line.words:
                    seen_code = True
                block = self._block(line)
                working = bool(block.g or block.m or block.words
                               or block.message is not None)
                if working or block.comments:
                    handed = clock()
                    yield block
                    if working:
                        self._idle_since = clock()
                    else:   # the time the consumer held it is not idle
                        self._idle_since += clock() - handed
                if any(abs(m - 2) < 1e-6 or abs(m - 30) < 1e-6
                       for m in block.m):
                    return
                continue
            seen_code = True
            keyword = oword.keyword
            frame_key = id(frames[-1]) if frames else 0

            if keyword == "call":
                name = oword.name if isinstance(oword.name, str) else \
                    f"{self._value(oword.name, line):g}"
                target = self._find_sub(name, unit)
                if target is None:
                    raise GCodeError(f"unknown subroutine {_label(name)}",
                                     line.file, line.number, oword.column)
                if len(frames) >= self.max_call_depth:
                    raise GCodeError(f"subroutine calls nested deeper than "
                                     f"{self.max_call_depth}", line.file,
                                     line.number, oword.column)
                self._count(unit, index, "subroutine call")
                args = [self._value(a, line) for a in oword.args]
                if len(args) > 30:
                    raise GCodeError("at most 30 subroutine arguments",
                                     line.file, line.number, oword.column)
                self.params.set("_value_returned", 0.0)
                self.params.push_scope(args)
                frames.append(_Frame(unit, index + 1, name))
                unit = target
                index = target.structure.subs[name][0] + 1
            elif keyword in ("return", "endsub"):
                if keyword == "endsub" and not frames:
                    index += 1
                    continue
                returned = self._value(oword.args[0], line) \
                    if oword.args else None
                frame = frames.pop()
                self.params.pop_scope()
                for key in [k for k in repeats if k[0] == id(frame)]:
                    del repeats[key]
                if returned is not None:
                    self.params.set("_value", returned)
                    self.params.set("_value_returned", 1.0)
                else:
                    self.params.set("_value_returned", 0.0)
                unit, index = frame.return_unit, frame.return_index
            elif keyword == "sub":
                index = structure.subs[_name_text(oword)][1] + 1
            elif keyword == "if":
                index = self._choose_branch(unit, index, line)
            elif keyword in ("elseif", "else"):
                index = structure.endif_of[index] + 1
            elif keyword == "endif":
                index += 1
            elif keyword == "while" and index in structure.loop_start:
                # the closing "while" of a do loop
                opener = structure.loop_start[index]
                if self._value(oword.args[0], line):
                    self._count(unit, opener, "loop")
                    index = opener + 1
                else:
                    index += 1
            elif keyword == "while":
                if self._value(oword.args[0], line):
                    self._count(unit, index, "loop")
                    index += 1
                else:
                    index = structure.loop_end[index] + 1
            elif keyword == "do":
                self._count(unit, index, "loop")
                index += 1
            elif keyword == "repeat":
                count = int(self._value(oword.args[0], line))
                repeats[(frame_key, index)] = count
                if count <= 0:
                    index = structure.loop_end[index] + 1
                else:
                    self._count(unit, index, "loop")
                    index += 1
            elif keyword == "endrepeat":
                opener = structure.loop_start[index]
                key = (frame_key, opener)
                repeats[key] -= 1
                if repeats[key] > 0:
                    self._count(unit, opener, "loop")
                    index = opener + 1
                else:
                    del repeats[key]
                    index += 1
            elif keyword == "endwhile":
                index = structure.loop_start[index]
            elif keyword == "break":
                opener = structure.loop_of[index]
                repeats.pop((frame_key, opener), None)
                index = structure.loop_end[opener] + 1
            elif keyword == "continue":
                opener = structure.loop_of[index]
                index = opener if unit.keyword(opener) == "while" \
                    else structure.loop_end[opener]
            else:  # pragma: no cover - the lexer admits no other keyword
                raise GCodeError(f"unsupported o-word {keyword}", line.file,
                                 line.number, oword.column)

    def _count(self, unit: _Unit, index: int, what: str) -> None:
        """Count one more loop iteration or subroutine call of this run
        (line ``index`` of ``unit``); past a limit it is an error."""
        if self.iterations >= self.max_iterations:
            raise self._runaway(
                unit, index,
                f"{what} exceeds the limit of {self.max_iterations} loop "
                "iterations and subroutine calls in one run (endless "
                "loop?); raise it with Program(max_iterations=...) or "
                "[RS274NGC]HALSDK_MAX_ITERATIONS")
        self.iterations += 1
        idle = self.clock() - self._idle_since
        if idle > self.max_idle_time:
            raise self._runaway(
                unit, index,
                f"{what} ran {idle:.3g} s without a block to execute, "
                f"more than the limit of {self.max_idle_time:g} s "
                "(endless loop?); raise it with Program(max_idle_time=...)"
                " or [RS274NGC]HALSDK_MAX_IDLE_TIME")

    @staticmethod
    def _runaway(unit: _Unit, index: int, message: str) -> GCodeError:
        line = unit.lines[index]
        assert isinstance(line, Line) and line.oword is not None
        return GCodeError(message, line.file, line.number,
                          line.oword.column)

    def _choose_branch(self, unit: _Unit, index: int, line: Line) -> int:
        """The line to continue at after ``O.. if`` at ``index``."""
        oword = line.oword
        assert oword is not None
        if self._value(oword.args[0], line):
            return index + 1
        for branch in unit.structure.branches[index]:
            entry = unit.lines[branch]
            assert isinstance(entry, Line) and entry.oword is not None
            keyword = entry.oword.keyword
            if keyword == "else":
                return branch + 1
            if keyword == "endif":
                return branch + 1
            if self._value(entry.oword.args[0], entry):
                return branch + 1
        raise AssertionError("if without endif")  # pragma: no cover
