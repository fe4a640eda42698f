"""A G-code program: its lines, o-word structure and execution order."""

from __future__ import annotations

import bisect
import os
import re
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, BinaryIO, Optional, Union

from ._eval import assign, evaluate, make_block
from ._fast import EMPTY, read_line, run_plain, set_file_lines
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


def _candidates(chunk: bytes, end: int) -> Iterator[int]:
    """The offsets of 'o', 'O' and '%' in ``chunk[:end]``, ascending
    (bytes.find runs at memchr speed, a regular expression does not)."""
    found = [(chunk.find(c, 0, end), c) for c in (b"o", b"O", b"%")]
    heads = sorted((at, c) for at, c in found if at >= 0)
    while heads:
        at, c = heads.pop(0)
        yield at
        following = chunk.find(c, at + 1, end)
        if following >= 0:
            bisect.insort(heads, (following, c))
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
                counted = 0     # newlines before here are in ``index``
                skip = 0        # the end of the last candidate line
                for at in _candidates(chunk, cut):
                    if at < skip:
                        continue        # a second one on the same line
                    start = chunk.rfind(b"\n", 0, at) + 1
                    stop = chunk.find(b"\n", at, cut)
                    stop = cut if stop < 0 else stop
                    index += chunk.count(b"\n", counted, start)
                    counted = start
                    offsets[index] = base + start
                    candidates.append(
                        (index, chunk[start:stop].decode("utf-8")
                         .rstrip("\r\n")))
                    skip = stop + 1
                index += chunk.count(b"\n", counted, cut)
                if chunk[cut - 1] != 10:
                    index += 1          # a last line without its line end
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
        self._idle_since = self.clock()
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
        self._idle_since = self.clock()
        yield from self._run()

    def share_files(self, other: Program) -> None:
        """Use the subroutine files ``other`` has read (and read more)."""
        self._files = other._files

    def _run(self, interp: Any = None) -> Iterator[Block]:
        unit = self._main
        index = 0
        frames: list[_Frame] = []
        self._frames = frames
        repeats: dict[tuple[int, int], int] = {}
        seen_code = False
        clock = self.clock
        structure = unit.structure
        params = self.params
        while True:
            if interp is None:
                entry = read_line(unit, index)
            else:
                # plain moves run at once; the line it stops at is ours
                index, entry, ran = run_plain(unit, index, interp,
                                              not frames)
                if ran:
                    seen_code = True
                    self._idle_since = clock()
            if entry is None:
                if frames:  # pragma: no cover - the scan rules it out
                    raise GCodeError(
                        f"end of file inside {_label(frames[-1].name)}",
                        unit.file, unit.count, 1)
                return
            if not frames and structure.sub_starts and \
                    structure.sub_starts[0] <= index <= structure.sub_ends[-1]:
                end = structure.sub_end(index)
                if end >= 0:
                    # a subroutine definition met in the main flow: skip it
                    index = end + 1
                    continue
            if entry.__class__ is Block:
                # the fast path: a line of plain numbered words
                index += 1
                seen_code = True
                clock()
                yield entry
                self._idle_since = clock()
                if entry.m and any(abs(m - 2) < 1e-6 or abs(m - 30) < 1e-6
                                   for m in entry.m):
                    return
                continue
            if entry is EMPTY:
                index += 1
                continue
            if isinstance(entry, GCodeError):
                raise entry
            assert isinstance(entry, Line)
            line = entry
            if line.percent:
                if seen_code and unit.percents[0] == index:
                    # only a program opened with '%' may close with one
                    raise GCodeError("Bad character '%' used", line.file,
                                     line.number, line.text.find("%") + 1)
                if seen_code or unit.percents and unit.percents[0] < index:
                    return
                index += 1
                continue
            if line.block_delete and self.block_delete:
                index += 1
                continue
            oword = line.oword
            if oword is None:
                index += 1
                if line.words:
                    seen_code = True
                elif not line.comments:
                    if line.assignments:
                        assign(self, line)      # no block to hand out
                    continue
                block = make_block(self, line)
                working = bool(block.g or block.m or block.words
                               or block.message is not None)
                if working or block.comments:
                    handed = clock()
                    yield block
                    if working:
                        self._idle_since = clock()
                    else:   # the time the consumer held it is not idle
                        self._idle_since += clock() - handed
                if block.m and any(abs(m - 2) < 1e-6 or abs(m - 30) < 1e-6
                                   for m in block.m):
                    return
                continue
            seen_code = True
            keyword = oword.keyword

            if keyword == "call":
                name = oword.name if isinstance(oword.name, str) else \
                    f"{evaluate(oword.name, params, line.file, line.number):g}"
                python = self.python_subs(name) if self.python_subs \
                    else None
                if python is not None:
                    self._python_call(python, oword, line)
                    index += 1
                    continue
                target = self._find_sub(name, unit)
                if target is None:
                    # (the reference reads on to the end, looking for it)
                    raise GCodeError(f"EOF in file:{unit.file} seeking "
                                     f"o-word: o<{name}> from line: "
                                     f"{line.number}", unit.file,
                                     unit.count, 1)
                if len(frames) >= self.max_call_depth:
                    raise GCodeError("Too many subroutine levels", line.file,
                                     line.number, oword.column)
                self._count(unit, index, "subroutine call")
                args = [evaluate(a, params, line.file, line.number)
                        for a in oword.args]
                if len(args) > 30:
                    raise GCodeError("Too many subroutine parameters",
                                     line.file, line.number, oword.column)
                params.set_returned(None)
                params.push_scope(args)
                frames.append(_Frame(unit, index + 1, name))
                unit = target
                structure = unit.structure
                index = target.structure.subs[name][0] + 1
            elif keyword in ("return", "endsub"):
                if keyword == "endsub" and not frames:
                    index += 1
                    continue
                returned = evaluate(oword.args[0], params, line.file,
                                    line.number) if oword.args else None
                frame = frames.pop()
                params.pop_scope()
                if repeats:
                    for key in [k for k in repeats if k[0] == id(frame)]:
                        del repeats[key]
                params.set_returned(returned)
                unit, index = frame.return_unit, frame.return_index
                structure = unit.structure
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
                if evaluate(oword.args[0], params, line.file, line.number):
                    self._count(unit, opener, "loop")
                    index = opener + 1
                else:
                    index += 1
            elif keyword == "while":
                if evaluate(oword.args[0], params, line.file, line.number):
                    self._count(unit, index, "loop")
                    index += 1
                else:
                    index = structure.loop_end[index] + 1
            elif keyword == "do":
                self._count(unit, index, "loop")
                index += 1
            elif keyword == "repeat":
                count = int(evaluate(oword.args[0], params, line.file,
                                     line.number))
                repeats[(id(frames[-1]) if frames else 0, index)] = count
                if count <= 0:
                    index = structure.loop_end[index] + 1
                else:
                    self._count(unit, index, "loop")
                    index += 1
            elif keyword == "endrepeat":
                opener = structure.loop_start[index]
                key = (id(frames[-1]) if frames else 0, opener)
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
                repeats.pop((id(frames[-1]) if frames else 0, opener), None)
                index = structure.loop_end[opener] + 1
            elif keyword == "continue":
                opener = structure.loop_of[index]
                index = opener if unit.keyword(opener) == "while" \
                    else structure.loop_end[opener]
            else:  # pragma: no cover - the lexer admits no other keyword
                raise GCodeError(f"unsupported o-word {keyword}", line.file,
                                 line.number, oword.column)

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
        line = unit.owords[index]
        assert line.oword is not None
        return GCodeError(message, line.file, line.number,
                          line.oword.column)

    def _choose_branch(self, unit: _Unit, index: int, line: Line) -> int:
        """The line to continue at after ``O.. if`` at ``index``."""
        oword = line.oword
        assert oword is not None
        if self._value(oword.args[0], line):
            return index + 1
        for branch in unit.structure.branches[index]:
            entry = unit.owords[branch]
            assert entry.oword is not None
            keyword = entry.oword.keyword
            if keyword == "else":
                return branch + 1
            if keyword == "endif":
                return branch + 1
            if self._value(entry.oword.args[0], entry):
                return branch + 1
        raise AssertionError("if without endif")  # pragma: no cover
