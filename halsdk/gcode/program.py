"""A G-code program: its lines, o-word structure and execution order."""

from __future__ import annotations

import bisect
import os
import re
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, BinaryIO, Optional, Union

from ._eval import evaluate, make_block
from ._fast import candidate_lines, set_file_lines
from ._flow import run as run_flow
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
    # the line ranges of the subroutine definitions (first, last), sorted
    sub_starts: list[int] = field(default_factory=list)
    sub_ends: list[int] = field(default_factory=list)

    def sub_end(self, index: int) -> int:
        """The endsub line of the definition line ``index`` is in, or -1
        when it is in none."""
        at = bisect.bisect_right(self.sub_starts, index) - 1
        if at >= 0 and index <= self.sub_ends[at]:
            return self.sub_ends[at]
        return -1


#: Characters that may start an o-word or a '%' line: only lines holding
#: one are read by the first pass over a program.
_CANDIDATE = re.compile(r"[oO%]")
#: Line ends that ``str.splitlines`` knows besides \n and \r\n: a file
#: holding one is read whole (as text) rather than streamed.
_OTHER_LINE_ENDS = (b"\x0b", b"\x0c", b"\x1c", b"\x1d", b"\x1e", b"\xc2\x85",
                    b"\xe2\x80\xa8", b"\xe2\x80\xa9")


def _other_line_ends(chunk: bytes, end: int, ascii: bool) -> bool:
    """True if ``chunk[:end]`` holds a line end other than \\n and
    \\r\\n (``ascii``: it is all ASCII)."""
    if chunk.find(b"\r", 0, end) >= 0 and \
            chunk.count(b"\r", 0, end) != chunk.count(b"\r\n", 0, end):
        return True
    others = _OTHER_LINE_ENDS[:5] if ascii else _OTHER_LINE_ENDS
    return any(chunk.find(other, 0, end) >= 0 for other in others)


#: Size of the pieces a program file is scanned in.
_CHUNK = 1 << 20

#: A read line: the fast path's (text, N number, words), a :class:`Line`,
#: or the error of a line that cannot be read (raised when reached).
_Entry = Union[tuple, Line, GCodeError]


class _TextLines:
    """The lines of a program held in memory."""

    def __init__(self, lines: list[str]) -> None:
        self.lines = lines
        self.count = len(lines)

    def line(self, index: int) -> Optional[str]:
        return self.lines[index] if index < self.count else None

    def close(self) -> None:
        pass


class _FileLines:
    """The lines of a program file, read as they are needed: sequential
    reads go on from where the last one stopped; a jump seeks to the
    nearest line whose offset the first pass kept (the o-word lines) and
    reads on from there, as the reference reads a program.  Memory does
    not grow with the length of the file."""

    def __init__(self, path: str, offsets: dict[int, int],
                 count: int) -> None:
        self.path = path
        self.offsets = offsets
        self.known = sorted(offsets)
        self.count = count
        self._file: Optional[BinaryIO] = None
        self._next = 0

    def line(self, index: int) -> Optional[str]:
        if index >= self.count:
            return None
        stream = self._file
        if stream is None or index != self._next:
            stream = self._seek(index)
        raw = stream.readline()
        self._next = index + 1
        return raw.decode("utf-8").rstrip("\r\n")

    def _seek(self, index: int) -> BinaryIO:
        stream = self._file
        if stream is None:
            try:
                stream = self._file = open(self.path, "rb")
            except OSError as exc:
                raise GCodeError(f"cannot read program: {exc.strerror}",
                                 self.path) from None
        if index == self._next:
            return stream
        if index in self.offsets:
            start = index
        else:
            start = self.known[bisect.bisect_right(self.known, index) - 1]
        stream.seek(self.offsets[start])
        for _ in range(index - start):
            stream.readline()
        self._next = index
        return stream

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None
            self._next = 0


set_file_lines(_FileLines, _TextLines)


def _read_file(path: str) -> tuple[Union[_TextLines, _FileLines],
                                   list[tuple[int, str]]]:
    """The lines of the program file ``path`` and the candidate lines of
    the first pass, ``(index, text)``.

    One pass over the file in pieces of :data:`_CHUNK` bytes keeps the
    byte offset of every line that may be an o-word or '%' line; the
    file is not held in memory.  A file with line ends other than \\n
    and \\r\\n is read whole, as text.
    """
    candidates: list[tuple[int, str]] = []
    offsets = {0: 0}
    index = 0           # lines before ``base``
    base = 0            # file offset of ``chunk``
    try:
        with open(path, "rb") as stream:
            rest = b""
            while True:
                piece = stream.read(_CHUNK)
                chunk = rest + piece
                if piece:
                    cut = chunk.rfind(b"\n") + 1
                    if cut == 0:
                        rest = chunk
                        continue
                    rest = chunk[cut:]
                elif not chunk:
                    break
                else:
                    cut = len(chunk)
                    rest = b""
                # the lines of chunk[:cut], without copying them
                ascii = chunk.isascii()
                if _other_line_ends(chunk, cut, ascii):
                    return _read_text(path)
                if not ascii:
                    chunk[:cut].decode("utf-8")  # the error a text read gives
                lines, found = candidate_lines(chunk, cut)
                for line, start, stop in found:
                    offsets[index + line] = base + start
                    candidates.append(
                        (index + line, chunk[start:stop].decode("utf-8")
                         .rstrip("\r\n")))
                index += lines
                base += cut
                if not piece:
                    break
    except OSError as exc:
        raise GCodeError(f"cannot read program: {exc.strerror}",
                         path) from None
    return _FileLines(path, offsets, index), candidates


def _read_text(path: str) -> tuple[_TextLines, list[tuple[int, str]]]:
    try:
        with open(path, encoding="utf-8") as stream:
            text = stream.read()
    except OSError as exc:
        raise GCodeError(f"cannot read program: {exc.strerror}",
                         path) from None
    return _text_lines(text)


def _text_lines(text: str) -> tuple[_TextLines, list[tuple[int, str]]]:
    lines = text.splitlines()
    search = _CANDIDATE.search
    return _TextLines(lines), [(i, t) for i, t in enumerate(lines)
                               if search(t)]


class _Unit:
    """One source file (or string): its o-word lines, their structure,
    and the other lines read as the run reaches them.

    Only the o-word and '%' lines are kept from the first pass; the lines
    of loops and subroutine definitions are kept once read (they are read
    again); the others are read and dropped, so a long program runs in
    constant memory.
    """

    def __init__(self, source: Union[_TextLines, _FileLines], file: str,
                 candidates: list[tuple[int, str]]) -> None:
        self.file = file
        self.source = source
        self.owords: dict[int, Line] = {}
        self.percents: list[int] = []
        for index, text in candidates:
            try:
                line = parse_line(text, file, index + 1)
            except GCodeError:
                continue            # raised when the run reaches it
            if line.oword is not None:
                self.owords[index] = line
            elif line.percent:
                self.percents.append(index)
        self.structure = _scan(self)
        # the line ranges read more than once: loops and subroutines
        spans = sorted([(a, b) for a, b in self.structure.loop_end.items()]
                       + list(self.structure.subs.values()))
        self._keep_starts: list[int] = []
        self._keep_ends: list[int] = []
        for first, last in spans:
            if self._keep_ends and first <= self._keep_ends[-1]:
                self._keep_ends[-1] = max(self._keep_ends[-1], last)
            else:
                self._keep_starts.append(first)
                self._keep_ends.append(last)
        self._kept: dict[int, _Entry] = {}
        #: the lines that run again, compiled (by ``_flow.run``)
        self._codes: dict[int, Any] = {}

    @classmethod
    def from_text(cls, text: str, file: str) -> _Unit:
        source, candidates = _text_lines(text)
        return cls(source, file, candidates)

    @classmethod
    def from_file(cls, path: str) -> _Unit:
        source, candidates = _read_file(path)
        return cls(source, path, candidates)

    @property
    def count(self) -> int:
        """The number of lines."""
        return self.source.count

    def oword(self, index: int) -> Optional[OWord]:
        line = self.owords.get(index)
        return line.oword if line is not None else None

    def keyword(self, index: int) -> str:
        """The keyword of line ``index``, which the scan found an o-word."""
        oword = self.oword(index)
        if oword is None:
            raise RuntimeError(f"{self.file}: line {index + 1} is not an "
                               "o-word")
        return oword.keyword

    def close(self) -> None:
        self.source.close()


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
        line = unit.owords[index]
        assert line.oword is not None
        return GCodeError(message, unit.file, line.number, line.oword.column)

    def unmatched(index: int, wanted: tuple[str, ...], name: str
                  ) -> GCodeError:
        """The reference's words for an o-word without its opener."""
        line = unit.owords[index]
        for kind, open_name, opener in reversed(stack):
            if open_name == name and kind not in wanted:
                return fail(index, f"{line.number}: no matching label: "
                                   f"'{line.text}' (found '{kind}' in line "
                                   f"{unit.owords[opener].number})")
        return fail(index, f"{line.number}: undefined O-word label: "
                           f"'{line.text}'")

    for index in sorted(unit.owords):
        oword = unit.owords[index].oword
        assert oword is not None
        name, keyword = _name_text(oword), oword.keyword
        label = _label(name)
        if keyword == "sub":
            if current_sub is not None:
                raise fail(index, "Nested subroutine definition")
            if name in result.subs:
                raise fail(index, f"File:{unit.file} line:"
                                  f"{unit.owords[index].number} redefining "
                                  f"sub: o|{name}| already defined in "
                                  f"file:{unit.file}")
            current_sub = (name, index)
        elif keyword == "endsub":
            if current_sub is None:
                raise fail(index, f"{unit.owords[index].number}: not in a "
                                  "subroutine definition: "
                                  f"'{unit.owords[index].text}'")
            if stack:
                kind, open_name, _ = stack[-1]
                raise fail(index, f"{label} endsub before the end of "
                                  f"{_label(open_name)} {kind}")
            if current_sub[0] != name:
                raise fail(index, f"{label} endsub does not match "
                                  f"o<{current_sub[0]}> sub")
            result.subs[name] = (current_sub[1], index)
            result.sub_starts.append(current_sub[1])
            result.sub_ends.append(index)
            current_sub = None
        elif keyword == "return":
            if current_sub is None or current_sub[0] != name:
                raise fail(index, f"{unit.owords[index].number}: not in a "
                                  "subroutine definition: "
                                  f"'{unit.owords[index].text}'")
        elif keyword == "if":
            stack.append(("if", name, index))
            result.branches[index] = []
        elif keyword in ("elseif", "else", "endif"):
            if not stack or stack[-1][0] != "if" or stack[-1][1] != name:
                raise unmatched(index, ("if",), name)
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
                raise unmatched(index, (wanted,), name)
            opener = stack.pop()[2]
            result.loop_end[opener] = index
            result.loop_start[index] = opener
        elif keyword in ("break", "continue"):
            loops = [entry for entry in stack
                     if entry[0] in _LOOP_OPENERS and entry[1] == name]
            if not loops:
                raise unmatched(index, _LOOP_OPENERS, name)
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
        # (the reference reads on to the end, looking for the endsub)
        raise GCodeError("File ended with no percent sign or program end",
                         unit.file, unit.count, 1)
    return result


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
        self._frames: list[Any] = []
        self._main = _Unit.from_text(text, file)
        self._files: dict[str, _Unit] = {}
        #: ``python_subs(name)``: a Python subroutine for ``o<name> call``
        #: (``f(args, file, line, column)`` -> the value returned or None),
        #: looked for before the NGC ones; set by the interpreter that has
        #: a ``[PYTHON]`` plugin (see :mod:`halsdk.gcode.remap`)
        self.python_subs: Optional[Callable[[str], Optional[Callable[
            [list[float], str, int, int], Optional[float]]]]] = None

    @classmethod
    def from_file(cls, path: str, params: Parameters | None = None,
                  search_path: Sequence[str] = (), **options: object
                  ) -> Program:
        """Read a program file; its directory is searched for subroutine
        files after ``search_path``.

        The file is streamed: a first pass keeps only where its o-word
        lines are (and checks their structure, as :class:`Program` does);
        :meth:`blocks` then reads the lines as the run reaches them, so a
        program of any length starts at once and runs in constant memory.
        The file must not change while the program runs.
        """
        unit = _Unit.from_file(path)
        directory = os.path.dirname(os.path.abspath(path))
        program = cls("", path, params, [*search_path, directory],
                      **options)  # type: ignore[arg-type]
        program._main = unit
        return program

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
                loaded = _Unit.from_text(text, path)
                if name not in loaded.structure.subs:
                    raise GCodeError(f"file defines no o<{name}> sub", path,
                                     1, 1)
                self._files[name] = loaded
                return loaded
        return None

    # -- evaluation helpers ------------------------------------------------
    def _value(self, expr: Expr, line: Line) -> float:
        return evaluate(expr, self.params, line.file, line.number)

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
        return make_block(self, line)

    def _block_python(self, line: Line) -> Block:
        """:meth:`_block` in Python: the reference of its behaviour."""
        block = Block(line.file, line.number, line.text,
                      block_delete=line.block_delete,
                      line_number=line.line_number)
        params = self.params
        file, number = line.file, line.number
        for word in line.words:
            value = evaluate(word.value, params, file, number)
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
                   evaluate(a.value, params, file, number), a.column)
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

    def blocks(self, interp: Any = None) -> Iterator[Block]:
        """The blocks in execution order (see the class docstring); ends at
        M2/M30, the closing '%' or the end of the file.

        With ``interp`` (an :class:`~halsdk.gcode.interp.Interpreter`;
        its ``run`` does this), the plain moves that its short path takes
        are executed by it as they are read, by compiled code, and not
        handed out (``_fast.run_plain``): the consumer must execute
        every block it gets with that interpreter, and nothing else."""
        self.params.reset_scopes()
        self.iterations = 0
        try:
            yield from self._run(interp)
        finally:
            self.params.reset_scopes()
            self._main.close()
            for unit in self._files.values():
                unit.close()

    def subroutine_blocks(self) -> Iterator[Block]:
        """:meth:`blocks` for a program run inside another one (a remapped
        code's procedure, G-code run by Python): the parameter scopes of
        the running program are left as they are."""
        self.iterations = 0
        yield from self._run()

    def share_files(self, other: Program) -> None:
        """Use the subroutine files ``other`` has read (and read more)."""
        self._files = other._files

    def _run(self, interp: Any = None) -> Iterator[Block]:
        """The control flow, compiled (``_flow.run``)."""
        return run_flow(self, interp)

    def _python_call(self, python: Callable[[list[float], str, int, int],
                                            Optional[float]],
                     oword: OWord, line: Line) -> None:
        """``o<name> call`` of a Python subroutine: its value returned in
        ``#<_value>`` (and ``#<_value_returned>`` 1), as an NGC one's."""
        args = [self._value(a, line) for a in oword.args]
        self.params.set("_value_returned", 0.0)
        returned = python(args, line.file, line.number, oword.column)
        if returned is not None:
            self.params.set("_value", returned)
            self.params.set("_value_returned", 1.0)

    def _runaway(self, unit: _Unit, index: int, what: str,
                 idle: Optional[float]) -> GCodeError:
        """The error of a loop iteration or a subroutine call (``what``,
        line ``index`` of ``unit``) past a limit: the iterations, or the
        ``idle`` time when it is given (``_flow.run`` counts)."""
        if idle is None:
            message = (
                f"{what} exceeds the limit of {self.max_iterations} loop "
                "iterations and subroutine calls in one run (endless "
                "loop?); raise it with Program(max_iterations=...) or "
                "[RS274NGC]HALSDK_MAX_ITERATIONS")
        else:
            message = (
                f"{what} ran {idle:.3g} s without a block to execute, "
                f"more than the limit of {self.max_idle_time:g} s "
                "(endless loop?); raise it with Program(max_idle_time=...)"
                " or [RS274NGC]HALSDK_MAX_IDLE_TIME")
        line = unit.owords[index]
        assert line.oword is not None
        return GCodeError(message, line.file, line.number,
                          line.oword.column)
