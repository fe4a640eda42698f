"""The short path of plain moves does what the general path does.

``Interpreter.execute`` hands plain moves (G0-G3 or the modal motion
with axis, F and arc words) to the compiled ``fast_move``; every other
block, and any block through ``Interpreter._execute``, goes the general
way.  For random machine states and moves, both must emit the same
commands, end in the same state and refuse the same blocks.

``Interpreter.run`` goes further: the program executes runs of plain
moves itself, in compiled code, without making their blocks
(``_fast.run_plain``).  Random programs, held in memory or streamed from
a file, with loops and subroutines, must run as they do block by block,
for the recording canon, the reference's calls and the ``rs274`` text;
lines of plain comments only, which the control flow skips with the
interpreter, among them.
"""

from __future__ import annotations

import copy
import os
import tempfile
from typing import Optional

from hypothesis import given, settings
from hypothesis import strategies as st

from halsdk.gcode import GCodeError, Parameters, Program, _fast
from halsdk.gcode import interp as interp_module
from halsdk.gcode.canon import RecordingCanon
from halsdk.gcode.canon_text import TextCanon
from halsdk.gcode.interp import Interpreter

SETUP_LINES = [
    "G20", "G21", "G90", "G91", "G93", "G94", "G17", "G18", "G19",
    "G0", "G1", "G2", "G3", "G80", "G55", "G54", "G59.3", "F0", "F250",
    "G10 L2 P2 X3 Y-4 Z1.5 A10", "G10 L2 P1 X-1 Y2 W7", "G92 X1 Y1",
    "G92.1", "G43.1 Z2.5", "G49", "G0 X1 Y2 Z3", "G1 X-2 Y5 F100",
    "G91.1", "G90.1", "G7", "G8", "G10 L2 P0 R30", "G10 L2 P1 X1 R-15",
    "G10 L2 P2 R0", "G95", "M70", "M72", "(a comment)", "G5 X1 Y1 P1 Q1"]
SETUP = st.lists(st.sampled_from(SETUP_LINES), max_size=8)

value = st.sampled_from(["0", "1", "-2.5", "0.1234", "10", "-0.5", "3"])
MOVE = st.tuples(
    st.sampled_from(["", "G0", "G1", "G2", "G3"]),
    st.lists(st.tuples(st.sampled_from("xyzabcuvwfijkrp"), value),
             max_size=5, unique_by=lambda w: w[0]))


class ReferenceCanon(RecordingCanon):
    """The canon of ``rs274``: the interpreter adds the reference's calls."""
    reference_calls = True


def canon_of(ref: bool) -> RecordingCanon:
    return ReferenceCanon() if ref else RecordingCanon()


def set_up(setup: list[str], ref: bool
           ) -> Optional[tuple[Interpreter, Interpreter]]:
    """An interpreter (with the rs274 canon when ``ref``) after the lines
    ``setup``, and a copy of it; None for a setup it refuses."""
    params = Parameters()
    fast = Interpreter(params, None, canon_of(ref))
    try:
        fast.run(Program("\n".join(setup) + "\n", "s.ngc", params))
    except GCodeError:
        return None
    return fast, copy.deepcopy(fast)


def state(interp: Interpreter, canon: RecordingCanon) -> tuple:
    return (canon.commands, interp.pos, interp.feed, interp.feed_value,
            interp.diameter_mode, vars(interp.modal), interp.line,
            interp.params._numbered)


def outcome(fn, block) -> object:
    try:
        fn(block)
    except GCodeError as exc:
        return str(exc)
    return None


@settings(max_examples=300, deadline=None)
@given(SETUP, MOVE, st.booleans())
def test_plain_moves_take_the_general_path_s_way(setup: list[str],
                                                 move: tuple,
                                                 ref: bool) -> None:
    pair = set_up(setup, ref)
    if pair is None:
        return                      # a setup the interpreter refuses
    fast, general = pair
    code, words = move
    text = " ".join([code] + [f"{letter}{v}" for letter, v in words])
    blocks = list(Program(text + "\n", "m.ngc", Parameters()).blocks())
    if not blocks:
        return
    block = blocks[0]
    assert outcome(fast.execute, block) == \
        outcome(general._execute, block)
    assert state(fast, fast.canon) == state(general, general.canon)


def test_fast_path_takes_plain_moves() -> None:
    params = Parameters()
    interp = Interpreter(params, None, RecordingCanon())
    interp.run(Program("G21 G90 F100\n", "s.ngc", params))
    for text, taken in [("G2 X2 Y0 I1", True), ("G1 X1 Y2", True),
                        ("X3", True), ("G0 Z1", True), ("G1 X1 F20", True),
                        ("F30", True), ("G1 X1 M3", False),
                        ("G1 X1 S100", False), ("G90 G1 X1", False),
                        ("(MSG, hi)", False), ("G4 P1", False)]:
        block = next(Program(text, "m.ngc", Parameters()).blocks())
        assert _fast.fast_move(interp, block) is taken, text


def test_f_words_and_comments_take_the_short_path(monkeypatch) -> None:
    # a move with an F word (units per minute) and a line of comments
    # alone do not go the general way (the reference's calls aside)
    params = Parameters()
    canon = RecordingCanon()
    interp = Interpreter(params, None, canon)
    interp.run(Program("G21 G90 F100\n", "s.ngc", params))

    def general(block) -> None:
        raise AssertionError(f"general path: {block.text}")

    monkeypatch.setattr(interp, "_execute", general)
    for text in ["G1 X1 F200", "F300", "G0 Y2 F50", "(a comment)",
                 "(PROBEOPEN probe.txt)"]:
        interp.execute(next(Program(text, "m.ngc", Parameters()).blocks()))
    assert interp.feed_value == 50.0 and interp.feed == 50.0
    assert [type(c).__name__ for c in canon.commands[-5:]] == [
        "SetFeedRate", "StraightFeed", "SetFeedRate", "SetFeedRate",
        "StraightTraverse", "ProbeOpen"][-5:]


COMMENT = st.sampled_from([
    "(a comment)", "(PROBEOPEN probe.txt)", "(PROBECLOSE)", "(LOG,x #1)",
    "(LOGOPEN,log.txt)", "(LOGAPPEND,log.txt)", "(logclose)",
    "(MSG, hello)", "(debug, #1 is)", "(print,p #<_x>)", "(a) (b)",
    "N10 (numbered)", "(#1 = x, #2 = y)", "; only this", "(msg ,no)"])


@settings(max_examples=150, deadline=None)
@given(SETUP, COMMENT, st.booleans())
def test_comments_take_the_general_path_s_way(setup: list[str],
                                              text: str,
                                              ref: bool) -> None:
    pair = set_up(setup, ref)
    if pair is None:
        return                      # a setup the interpreter refuses
    fast, general = pair
    blocks = list(Program(text + "\n", "m.ngc", Parameters()).blocks())
    if not blocks:
        return
    block = blocks[0]
    assert outcome(fast.execute, block) == \
        outcome(general._execute, block)
    assert state(fast, fast.canon) == state(general, general.canon)


def test_fast_path_constants_are_the_interpreter_s() -> None:
    assert _fast.COORD_CODES == interp_module.COORD_CODES


small = st.sampled_from(["0", "1", "-2.5", "0.1234", "3", "-0.75"])


@settings(max_examples=200, deadline=None)
@given(SETUP, st.sampled_from(["G2", "G3", ""]), small, small,
       st.sampled_from(["", " Z1", " Z-0.5 A3"]),
       st.sampled_from(["", " P2", " P1", " P0.5", " F120"]),
       st.sampled_from(["G17", "G18", "G19"]), st.booleans())
def test_arcs_take_the_general_path_s_way(setup: list[str], code: str,
                                          i: str, j: str, helix: str,
                                          extra: str, plane: str,
                                          ref: bool) -> None:
    # incremental: the end is twice the centre offset, a half circle
    setup = setup + [f"{plane} G91 G91.1 F100"]
    first, second, w1, w2 = {"G17": ("X", "Y", "I", "J"),
                             "G18": ("Z", "X", "K", "I"),
                             "G19": ("Y", "Z", "J", "K")}[plane]
    if first in helix or second in helix:
        helix = ""
    move = (f"{code} {first}{2 * float(i)} {second}{2 * float(j)} "
            f"{w1}{i} {w2}{j}{helix}{extra}")
    pair = set_up(setup, ref)
    if pair is None:
        return                      # a setup the interpreter refuses
    fast, general = pair
    block = next(Program(move + "\n", "m.ngc", Parameters()).blocks())
    assert outcome(fast.execute, block) == outcome(general._execute, block)
    assert state(fast, fast.canon) == state(general, general.canon)


def test_fast_path_planes_are_the_interpreter_s() -> None:
    assert _fast.PLANES == interp_module.PLANES


# -- the read-execute loop (Interpreter.run: _fast.run_plain) ---------------
#
# Interpreter.run lets the program execute runs of plain moves itself, in
# compiled code, without making their blocks.  Whole programs must run as
# they do block by block through the general path (Interpreter._execute
# only), and as block by block through Interpreter.execute: the same
# commands, the same end state, the same error.


class General(Interpreter):
    """Every block through the general path (no short path at all)."""

    def execute(self, block) -> None:
        self._execute(block)


class PerBlock(Interpreter):
    """Every block through Interpreter.execute (its short path
    included), no read-execute loop (execute is overridden)."""

    def execute(self, block) -> None:
        Interpreter.execute(self, block)


class TextLines:
    """A TextCanon's output, kept."""

    def __init__(self) -> None:
        self.out: list[str] = []

    def __call__(self, text: str) -> None:
        self.out.append(text)


def run_program(cls, text: str, canon_kind: str, path: str,
                units: str = "mm", stream: bool = False) -> tuple:
    """Run ``text`` (named ``path``; streamed from that file with
    ``stream``) with an interpreter of ``cls``; everything that can be
    compared."""
    params = Parameters()
    if canon_kind == "text":
        written = TextLines()
        canon = TextCanon(written)
    else:
        canon = canon_of(canon_kind == "ref")
    interp = cls(params, None, canon, units=units)
    if canon_kind == "text":
        canon.interp = interp
    program = Program.from_file(path, params) if stream else \
        Program(text, path, params)
    try:
        interp.run(program)
        error = None
    except GCodeError as exc:
        error = str(exc)
    commands = written.out if canon_kind == "text" else canon.commands
    return (error, commands, interp.pos, interp.feed, interp.feed_value,
            interp.diameter_mode, vars(interp.modal), interp.line,
            interp.params._numbered, interp.ended)


number = st.sampled_from(["0", "1", "-2.5", "0.1234", "10", "-0.5", "3",
                          "1.", ".5", "+2", "0.0001", "-7.25", "2"])
axis_or_arc = st.sampled_from("xyzabcuvwijkrpXYZIJ")
PLAIN = st.tuples(
    st.sampled_from(["", "", "G0", "G1", "G2", "G3", "g1", "G01", "G1.0",
                     "N5 G1", "n20 G0", "G1.00001"]),
    st.lists(st.tuples(axis_or_arc, st.sampled_from(["", " "]), number),
             max_size=5, unique_by=lambda w: w[0].lower()),
    st.sampled_from(["", " ", "\t", "\r"]),
).map(lambda t: (t[0] + " " + "".join(f"{a}{s}{v} " for a, s, v in t[1])
                 ).strip() + t[2])
#: half circles that the checks let through: incremental centre and end
ARC = st.tuples(st.sampled_from(["G2", "G3", ""]), number, number,
                st.sampled_from(["", " Z1", " Z-0.5 A3", " P2", " P1.5"])
                ).map(lambda t: f"{t[0]} @1{2 * float(t[1]):g} "
                      f"@2{2 * float(t[2]):g} @3{t[1]} @4{t[2]}{t[3]}")
OTHER = st.sampled_from(SETUP_LINES + [
    "", "   ", "N10", "(only a comment)", "G1 X1 F300", "M3 S1000",
    "G1 X1 (with a comment)", "#1 = 2", "G1 X#1", "/G1 X9", "G0 X1 Y1 ; c",
    "(PROBEOPEN p.txt)", "(PROBECLOSE)", "(LOG,at #1)", "G0 X2 F-1",
    "F250", "G1 Y3 F[100 + 20]", "G0 Z1 F10",
    "(MSG, hello)", "G91 G91.1 F100", "G90 G90.1", "G18", "G19", "G17",
    "G2 X1 R1", "G20", "G21", "G55", "G54", "T1 M6", "G43 H1", "M5",
    "G1 X(é)1", "G10 L20 P1 X0 Y0", "G92 Z-3", "G53 G0 X1"])
PLANE_WORDS = {"G17": "XYIJ", "G18": "ZXKI", "G19": "YZJK"}


def with_plane(lines: list[str]) -> list[str]:
    """Fill in the arcs' words for the plane in effect at each line."""
    plane = "G17"
    out = []
    for line in lines:
        for code in PLANE_WORDS:
            if code in line:
                plane = code
        for k, letter in enumerate(PLANE_WORDS[plane]):
            line = line.replace(f"@{k + 1}", letter)
        out.append(line)
    return out


PROGRAM = st.lists(st.one_of(PLAIN, PLAIN, ARC, ARC, OTHER), max_size=30
                   ).map(with_plane)


def check_program(text: str, canon_kind: str, units: str = "mm") -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "p.ngc")
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        general = run_program(General, text, canon_kind, path, units)
        for cls, stream in [(Interpreter, False), (PerBlock, False),
                            (Interpreter, True)]:
            assert run_program(cls, text, canon_kind, path, units,
                               stream) == general, (cls, stream)


@settings(max_examples=250, deadline=None)
@given(st.lists(st.sampled_from(SETUP_LINES), max_size=6), PROGRAM,
       st.sampled_from(["", "M2"]),
       st.sampled_from(["rec", "rec", "ref", "text"]),
       st.sampled_from(["mm", "inch"]))
def test_programs_run_as_block_by_block(setup: list[str], body: list[str],
                                        end: str, canon_kind: str,
                                        units: str) -> None:
    text = "\n".join(setup + ["G21 F100"] + body + [end]) + "\n"
    check_program(text, canon_kind, units)


@settings(max_examples=100, deadline=None)
@given(PROGRAM, PROGRAM, st.sampled_from(["rec", "ref"]))
def test_plain_moves_in_loops_and_subroutines(body: list[str],
                                              main: list[str],
                                              canon_kind: str) -> None:
    # the lines of loops and subroutines are kept once read; a definition
    # met in the main flow is skipped, its plain lines too
    body = [line for line in body if "#" not in line]
    text = "\n".join(
        ["G21 G91 G91.1 F100", "o<s> sub"] + body + ["o<s> endsub"]
        + main[:10] + ["#<n> = 0", "o1 while [#<n> LT 3]"] + body
        + ["o<s> call", "#<n> = [#<n> + 1]", "o1 endwhile",
           "o2 repeat [2]"] + main[10:] + ["o2 endrepeat", "M2"]) + "\n"
    check_program(text, canon_kind)


def test_the_loop_takes_plain_moves_and_hands_out_the_rest() -> None:
    params = Parameters()
    canon = RecordingCanon()
    interp = Interpreter(params, None, canon)
    text = ("G21 G90 F100\nG1 X1 Y2\nX3\nG0 Z1\n\nN7 G2 X5 I1\n"
            "G1 X1 F200\nG1 Y1\nM2\n")
    program = Program(text, "p.ngc", params)
    handed = []
    for block in program.blocks(interp):
        handed.append(block.text)
        interp.execute(block)
    assert handed == ["G21 G90 F100", "G1 X1 F200", "M2"]
    general = RecordingCanon()
    General(Parameters(), None, general).run(Program(text, "p.ngc"))
    assert canon.commands == general.commands
    assert [c.line for c in canon.commands if c.line in (2, 3, 4, 6, 8)
            ] == [2, 3, 4, 6, 8]
    # without the interpreter every line with words is handed out
    program = Program("G1 X1\nG1 X2\n", "p.ngc", Parameters())
    assert [b.text for b in program.blocks()] == ["G1 X1", "G1 X2"]


def test_lines_of_plain_comments_are_not_handed_out() -> None:
    # a line of plain comments does nothing but name the current line:
    # with the interpreter, the control flow (_flow.run) does that itself;
    # active comments, PROBEOPEN and lines with anything else are blocks
    text = ("G21 F100\no<s> sub\n(just a note)\n  ( another )\n"
            "(PROBEOPEN p.txt)\n(MSG, hello)\n(PROBECLOSE)\n#<k> = 1\n"
            "G1 X#1\no<s> endsub\no1 repeat [2]\no<s> call [1]\n"
            "(after the call)\no1 endrepeat\nM2\n")
    params = Parameters()
    canon = RecordingCanon()
    interp = Interpreter(params, None, canon)
    handed = []
    for block in Program(text, "p.ngc", params).blocks(interp):
        handed.append(block.text)
        interp.execute(block)
        if block.text == "(MSG, hello)":
            assert interp.line == 6
    assert handed == ["G21 F100"] + ["(PROBEOPEN p.txt)", "(MSG, hello)",
                                     "(PROBECLOSE)", "G1 X#1"] * 2 + ["M2"]
    general = RecordingCanon()
    General(Parameters(), None, general).run(Program(text, "p.ngc"))
    assert canon.commands == general.commands
    # without the interpreter (the machine's executor), every one is
    program = Program(text, "p.ngc", Parameters())
    assert sum(b.text == "(just a note)" for b in program.blocks()) == 2
    # nor when the interpreter would do something with them: the
    # reference's COMMENT calls
    ref = ReferenceCanon()
    interp = Interpreter(Parameters(), None, ref)
    interp.run(Program(text, "p.ngc"))
    assert sum(c.text == 'COMMENT("just a note")'
               for c in ref.commands if hasattr(c, "text")) == 2


digits = st.text("0123456789", max_size=25)


@settings(max_examples=500, deadline=None)
@given(st.sampled_from(["", "+", "-"]), digits, st.booleans(), digits)
def test_numbers_are_read_as_float_reads_them(sign: str, whole: str,
                                              point: bool,
                                              decimals: str) -> None:
    # the compiled reader converts short numbers itself (an exact
    # division), longer ones with Python's conversion: both are float()'s
    text = sign + whole + ("." + decimals if point else "")
    if not (whole or point and decimals):
        return                                  # no digits: no number
    read = _fast.simple_words(f"X{text}")
    assert read is not None
    value = read[1][0][1]
    assert value == float(text)
    assert str(value) == str(float(text))       # -0.0 too


def test_names_that_are_not_predefined_stay_so() -> None:
    # the interpreter remembers the global names it has no value for
    # (the program's own, such as #<_depth>); predefined ones are still
    # answered, with their current value
    params = Parameters()
    interp = Interpreter(params, None, RecordingCanon())
    interp.run(Program("G21 G90 F100\n#<_depth> = -0.5\nG0 X2\n", "s.ngc",
                       params))
    for _ in range(2):
        assert interp._predefined("_depth") is None
        assert interp._predefined("_x") == 2.0
        assert interp._predefined("_feed") == 100.0
        assert params.get("_depth") == -0.5
    interp.run(Program("G0 X3\nF200\n", "t.ngc", params))
    assert interp._predefined("_x") == 3.0
    assert interp._predefined("_feed") == 200.0
    assert interp._predefined("_depth") is None


@settings(max_examples=300, deadline=None)
@given(st.lists(st.text("oO%x \r;(G1)\n", max_size=12), max_size=12),
       st.booleans())
def test_the_first_pass_finds_every_line_with_an_o_or_percent(
        pieces: list[str], last_line_end: bool) -> None:
    # _fast.candidate_lines: the lines of a chunk that may be o-word or
    # '%' lines, and the number of lines, as splitting the text finds
    text = "".join(pieces) + ("\n" if last_line_end else "")
    chunk = text.encode("ascii") + b"tail after the end"
    count, found = _fast.candidate_lines(chunk, len(text))
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()
    assert count == len(lines)
    assert [(i, chunk[start:stop].decode()) for i, start, stop in found] \
        == [(i, line) for i, line in enumerate(lines)
            if any(c in line for c in "oO%")]
