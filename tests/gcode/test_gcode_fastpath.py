"""The short path of plain moves does what the general path does.

``Interpreter.execute`` hands plain moves (G0-G3 or the modal motion
with axis, F and arc words) to the compiled ``fast_move``; every other
block, and any block through ``Interpreter._execute``, goes the general
way.  For random machine states and moves, both must emit the same
commands, end in the same state and refuse the same blocks.
"""

from __future__ import annotations

import copy

from hypothesis import given, settings
from hypothesis import strategies as st

from halsdk.gcode import GCodeError, Parameters, Program, _fast
from halsdk.gcode import interp as interp_module
from halsdk.gcode.canon import RecordingCanon
from halsdk.gcode.interp import Interpreter

SETUP = st.lists(st.sampled_from([
    "G20", "G21", "G90", "G91", "G93", "G94", "G17", "G18", "G19",
    "G0", "G1", "G2", "G3", "G80", "G55", "G54", "G59.3", "F0", "F250",
    "G10 L2 P2 X3 Y-4 Z1.5 A10", "G10 L2 P1 X-1 Y2 W7", "G92 X1 Y1",
    "G92.1", "G43.1 Z2.5", "G49", "G0 X1 Y2 Z3", "G1 X-2 Y5 F100",
    "G91.1", "G90.1", "G7", "G8", "G10 L2 P0 R30", "G10 L2 P1 X1 R-15",
    "G10 L2 P2 R0", "G95", "M70", "M72", "(a comment)", "G5 X1 Y1 P1 Q1"]),
    max_size=8)

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
    params = Parameters()
    canon = canon_of(ref)
    fast = Interpreter(params, None, canon)
    try:
        fast.run(Program("\n".join(setup) + "\n", "s.ngc", params))
    except GCodeError:
        return                      # a setup the interpreter refuses
    general = copy.deepcopy(fast)
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
                        ("X3", True), ("G0 Z1", True), ("G1 X1 M3", False),
                        ("G1 X1 S100", False), ("G90 G1 X1", False),
                        ("(MSG, hi)", False), ("G4 P1", False)]:
        block = next(Program(text, "m.ngc", Parameters()).blocks())
        assert _fast.fast_move(interp, block) is taken, text


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
    params = Parameters()
    fast = Interpreter(params, None, canon_of(ref))
    try:
        fast.run(Program("\n".join(setup) + "\n", "s.ngc", params))
    except GCodeError:
        return
    general = copy.deepcopy(fast)
    block = next(Program(move + "\n", "m.ngc", Parameters()).blocks())
    assert outcome(fast.execute, block) == outcome(general._execute, block)
    assert state(fast, fast.canon) == state(general, general.canon)


def test_fast_path_planes_are_the_interpreter_s() -> None:
    assert _fast.PLANES == interp_module.PLANES
