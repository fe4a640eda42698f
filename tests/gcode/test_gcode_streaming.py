"""The fast paths of the G-code reader and streamed program files.

The reader has fast paths (the compiled reader of plain numbered lines,
the ASCII reader of the lexer) next to the general one, and
``Program.from_file`` streams the file where ``Program(text)`` holds it:
each must give what the general way gives, errors included.  A long
file must run in bounded memory, its first block coming before the rest
is read.
"""

from __future__ import annotations

import os
import tracemalloc
from pathlib import Path

import pytest
from helpers import data_path
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from halsdk.gcode import GCodeError, Parameters, Program, lexer
from halsdk.gcode import program as program_module
from halsdk.gcode._fast import simple_words
from halsdk.gcode.canon import Canon, Command, StraightFeed
from halsdk.gcode.expr import Number
from halsdk.gcode.interp import Interpreter

HERE = data_path("gcode")

#: pieces of lines, valid and not: random lines are made of them
TOKENS = ["G1", "g0", "G2", "G38.2", "M3", "m2", "X", "y", "Z", "F", "I",
          "J", "P", "R", "N10", "n", "O", "o100", "o<sub>", "1", "-2.5",
          "+.5", "3.", ".", "12.0.1", "0", "-", "+", "*", "**", "/", "[",
          "]", "#", "#1", "#<a>", "#<_x>", "##2", "=", "sin", "ATAN", "mod",
          "EQ", "exists", "abs", "sub", "endsub", "call", "while",
          "endwhile", "if", "else", "endif", "repeat", "return", "(", ")",
          "(msg,hi)", "(debug, #1)", ";c", " ", "  ", "\t", "%", "e", "q"]

lines = st.lists(st.sampled_from(TOKENS), max_size=12).map("".join)
numbered = st.lists(
    st.tuples(st.sampled_from("gGmMxXyYzZfFiIjJsStTpPrRn"),
              st.sampled_from(["", " ", "\t"]),
              st.from_regex(r"[-+]?([0-9]{1,6}(\.[0-9]{0,5})?|\.[0-9]{1,4})",
                            fullmatch=True),
              st.sampled_from(["", " ", "  "])),
    max_size=8).map(lambda ws: "".join("".join(w) for w in ws))


def generic(text: str, lineno: int = 1) -> lexer.Line:
    """``parse_line`` through the general character reader."""
    text = text.rstrip("\r\n")
    chars, comments = lexer._strip(text, "t.ngc", lineno)
    reader = lexer._Reader(chars, "t.ngc", lineno, len(text) + 1)
    return lexer._read_line(reader, lexer.Line("t.ngc", lineno, text,
                                               comments=comments))


def outcome(fn, *args):
    try:
        return fn(*args)
    except GCodeError as exc:
        return str(exc)


@settings(max_examples=250, deadline=None)
@given(st.one_of(lines, numbered))
def test_ascii_reader_reads_as_the_general_reader(text: str) -> None:
    assert text.isascii()
    assert outcome(lexer.parse_line, text, "t.ngc", 1) == \
        outcome(generic, text)


@settings(max_examples=250, deadline=None)
@given(st.one_of(lines, numbered))
def test_fast_words_are_those_of_the_lexer(text: str) -> None:
    simple = simple_words(text)
    if simple is None:
        return          # the lexer reads it (or says what is wrong)
    line = lexer.parse_line(text, "t.ngc", 1)
    number, words = simple
    assert number == line.line_number
    assert not (line.assignments or line.comments or line.oword
                or line.percent or line.block_delete)
    assert all(isinstance(w.value, Number) for w in line.words)
    assert words == [(w.letter, w.value.value, w.column)   # type: ignore
                     for w in line.words]


def test_fast_path_takes_cam_lines_and_refuses_the_rest() -> None:
    assert simple_words("N20 G1 X1.2345 Y-0.5 Z.25 F1500.") == (
        20.0, [("g", 1.0, 5), ("x", 1.2345, 8), ("y", -0.5, 16),
               ("z", 0.25, 22), ("f", 1500.0, 27)])
    assert simple_words("") == (None, [])
    for text in ("G1 X1 X2", "G1 X[1]", "G1 X1 (c)", "/G1 X1", "o1 sub",
                 "G1 X1.2.3", "G1 X", "%", "G1 X1 ; c", "G1 X#1",
                 "G1 X1 N2", "G1 X\u00b2", "G1 X-+1"):
        assert simple_words(text) is None, text


# -- streamed files read what the text gives -----------------------------

PROGRAMS = {
    "plain": "G21 G90\nG0 X0 Y0\nG1 X1 Y2 F100\nN30 G1 X-1.5\nM2\n",
    "no last line end": "G0 X1\nG1 Y2 F10",
    "crlf": "G0 X1\r\nG1 Y2 F10\r\n(comment with o)\r\nM2\r\n",
    "percent": "%\nG0 X1\n%\nG0 X2\n",
    "percent after code": "G0 X1\n%\nG0 X2\n",
    "subs and loops": (
        "o<twice> sub\n  G1 X[#1 * 2] F100\no<twice> endsub\n"
        "#<i> = 0\no1 while [#<i> LT 3]\n  o<twice> call [#<i>]\n"
        "  #<i> = [#<i> + 1]\no1 endwhile\n"
        "o2 repeat [2]\n  G0 Y1\no2 endrepeat\n"
        "o3 if [#<i> EQ 3]\n  G0 Z1\no3 else\n  G0 Z2\no3 endif\n"
        "o4 do\n  #<i> = [#<i> - 1]\n  o5 if [#<i> LT 1]\n"
        "    o4 break\n  o5 endif\no4 while [1]\nM2\n"),
    "comments, messages, parameters": (
        "(MSG, hello)\n#1 = 2 #<_g> = [#1 + 1]\nG0 X#1 Y#<_g>\n"
        "(DEBUG, x is #1)\n; a comment holding o and %\nG1 X1 F5\n"),
    "block delete": "/G0 X1\nG0 X2\n/o1 if [1]\nG0 Y1\n/o1 endif\nM2\n",
    "bad line reached": "G0 X1\nG1 X[1 +\nG0 X3\n",
    "bad line not reached": "G0 X1\nM2\nG1 X[1 +\n",
    "bad structure": "G0 X1\no1 while [1]\nG0 X2\n",
    "o in a comment": "G0 X1 (go to x)\n(o100 sub)\nG0 X2 (to)\n",
    "utf-8": "(caf\u00e9 o\u00f9)\nG0 X1 (\u00e9t\u00e9)\nM2\n",
    "form feed": "G0 X1\x0cG0 X2\nM2\n",
    "lone cr": "G0 X1\rG0 X2\rM2\r",
    "sub skipped in the main flow": (
        "G0 X1\no7 sub\nG0 X99\no7 endsub\nG0 X2\no7 call\nM2\n"),
}


def blocks_of(program: Program) -> list:
    try:
        return [vars(b) for b in program.blocks()]
    except GCodeError as exc:
        return [str(exc)]


def from_text(text: str, name: str) -> list:
    try:
        program = Program(text, name, Parameters())
    except GCodeError as exc:
        return [str(exc)]
    return blocks_of(program)


def from_file(path: str) -> list:
    try:
        program = Program.from_file(path, Parameters())
    except GCodeError as exc:
        return [str(exc)]
    return blocks_of(program)


@pytest.mark.parametrize("chunk", [program_module._CHUNK, 7])
@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_streamed_file_gives_the_blocks_of_its_text(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str,
        chunk: int) -> None:
    # chunk 7: the first pass meets line ends at every piece boundary
    monkeypatch.setattr(program_module, "_CHUNK", chunk)
    path = tmp_path / "p.ngc"
    path.write_bytes(PROGRAMS[name].encode())
    with open(path, encoding="utf-8") as f:
        text = f.read()                # what a text read makes of it
    assert from_file(str(path)) == from_text(text, str(path))


def test_streamed_files_of_the_test_data() -> None:
    for name in ("main.ngc", "drill_sub.ngc", "bad_call.ngc"):
        path = os.path.join(HERE, name)
        with open(path, encoding="utf-8") as f:
            text = f.read()
        search = [os.path.dirname(path)]
        streamed = Program.from_file(path, Parameters())
        whole = Program(text, path, Parameters(), search)
        assert blocks_of(streamed) == blocks_of(whole), name


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.sampled_from([
    "G0 X1", "G1 Y[#1 + 1] F10", "#1 = [#1 + 1]", "o1 while [#1 LT 3]",
    "o1 endwhile", "o2 if [#1 GT 1]", "o2 else", "o2 endif",
    "o<s> sub", "o<s> endsub", "o<s> call [2]", "o3 repeat [2]",
    "o3 endrepeat", "(c)", "", "%", "M2", "G1 X[1/0]", "N5 G0 Z1",
    "o1 break", "o1 continue"]), max_size=14))
def test_streamed_random_programs(tmp_path: Path,
                                  program_lines: list[str]) -> None:
    text = "\n".join(program_lines) + "\n"
    path = tmp_path / "r.ngc"
    path.write_text(text, encoding="utf-8")
    assert from_file(str(path)) == from_text(text, str(path))


def test_unreadable_program_file_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(GCodeError, match="cannot read program"):
        Program.from_file(str(tmp_path / "none.ngc"))


# -- a long program streams ------------------------------------------------

LONG = 200_000
SHORT = 25_000


class _Stop(Exception):
    pass


class FirstMove(Canon):
    """Stops the run at the first motion command."""

    def emit(self, command: Command) -> None:
        if isinstance(command, StraightFeed):
            raise _Stop


def write_long(path: Path, count: int) -> None:
    with open(path, "w", encoding="ascii") as f:
        f.write("G21 G90 F1000\n")
        f.writelines(f"G1 X{i % 400 * 0.05:.4f} Y{i // 400 * 0.5:.4f} "
                     f"Z{-(i % 7) * 0.01:.4f}\n" for i in range(count - 2))
        f.write("M2\n")


@pytest.fixture(scope="module")
def long_files(tmp_path_factory: pytest.TempPathFactory) -> dict[int, Path]:
    folder = tmp_path_factory.mktemp("long")
    files = {}
    for count in (SHORT, LONG // 2, LONG):
        files[count] = folder / f"long{count}.ngc"
        write_long(files[count], count)
    return files


def test_long_program_starts_after_a_bounded_prefix(
        long_files: dict[int, Path]) -> None:
    params = Parameters()
    program = Program.from_file(str(long_files[LONG]), params)
    interp = Interpreter(params, None, FirstMove())
    blocks = program.blocks()
    with pytest.raises(_Stop):
        for block in blocks:
            interp.execute(block)
    # the first move is line 2: the run read two lines and keeps none
    assert block.line == 2
    source = program._main.source
    assert isinstance(source, program_module._FileLines)
    assert source._next == 2
    assert not program._main._kept and not program._main.owords
    blocks.close()


def peak_of_blocks(path: Path) -> tuple[int, int]:
    """(tracemalloc peak of reading the blocks of a streamed program in
    bytes, blocks)."""
    tracemalloc.start()
    try:
        count = sum(1 for _ in Program.from_file(str(path)).blocks())
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return peak, count


@pytest.mark.slow
def test_long_program_runs_in_constant_memory(
        long_files: dict[int, Path], monkeypatch: pytest.MonkeyPatch) -> None:
    # pieces of 64 kB: both files are many pieces long
    monkeypatch.setattr(program_module, "_CHUNK", 64 * 1024)
    short, blocks_short = peak_of_blocks(long_files[SHORT])
    long, blocks_long = peak_of_blocks(long_files[LONG // 2])
    assert (blocks_short, blocks_long) == (SHORT, LONG // 2)
    # four times the lines, not more memory: two pieces and a few blocks
    assert long < short + 32 * 1024, (short, long)
    assert long < 4 * 64 * 1024, long
