"""User M-codes in the interpreter: the command each one becomes, its P
and Q, and its place in the block, against the calls the reference's
preview interpreter makes (tests/data/gcode/user-m/calls.reference,
from LinuxCNC's Python module gcode on calls.ngc)."""

from __future__ import annotations

import pytest
from helpers import repo_path

from halsdk.gcode import GCodeError, Parameters, Program
from halsdk.gcode import canon as C
from halsdk.gcode.interp import Interpreter

DATA = repo_path("tests", "data", "gcode", "user-m")


def run(text: str, known=range(100, 200)) -> list[C.Command]:
    params = Parameters()
    rec = C.RecordingCanon()
    interp = Interpreter(params, None, rec)
    interp.user_m = lambda n: f"/m/M{n}" if n in known else None
    interp.run(Program(text, "u.ngc", params))
    return rec.commands


def test_the_reference_preview_calls():
    expected = []
    for line in (DATA / "calls.reference").read_text().splitlines():
        if line and not line.startswith("#"):
            expected.append(line)
    ours = []
    for c in run((DATA / "calls.ngc").read_text()):
        if isinstance(c, C.UserMCode):
            ours.append(f"user_defined_function {c.code - 100} {c.p!r} "
                        f"{c.q!r}")
            assert c.path == f"/m/M{c.code}"
        elif isinstance(c, C.StraightFeed):
            ours.append("straight_feed")
    assert ours == expected


def test_unknown_is_refused_before_the_block_runs():
    params = Parameters()
    rec = C.RecordingCanon()
    interp = Interpreter(params, None, rec)
    interp.user_m = lambda n: "/m/M101" if n == 101 else None
    with pytest.raises(GCodeError, match="u.ngc:2:7: Unknown m code used: "
                       "M120") as e:
        interp.run(Program("G21 G1 X1 F100\nG1 X2 M120\nM2\n", "u.ngc",
                           params))
    assert str(e.value) == "u.ngc:2:7: Unknown m code used: M120"
    # nothing of the refused line ran: one feed, to X1
    feeds = rec.of_type(C.StraightFeed)
    assert [c.end[0] for c in feeds] == [1.0]


@pytest.mark.parametrize("line, message", [
    ("M101 R1", "R word with no g code that uses it"),
    ("M101 M102", "Two m codes used from same modal group"),
])
def test_words_and_groups(line, message):
    with pytest.raises(GCodeError, match=message):
        run(line + "\nM2\n")
