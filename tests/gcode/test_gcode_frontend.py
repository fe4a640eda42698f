"""Tests of the G-code front end: lines, expressions, parameters, o-words."""

from __future__ import annotations

import math
import os
from pathlib import Path

import pytest
from helpers import data_path

from halsdk.gcode import Block, GCodeError, Parameters, Program
from halsdk.gcode.lexer import parse_line

HERE = data_path("gcode")


def run(text: str, params: Parameters | None = None, **options) -> list[Block]:
    return list(Program(text, "t.ngc", params, **options).blocks())


def value(expression: str, params: Parameters | None = None) -> float:
    params = params if params is not None else Parameters()
    run(f"#100 = {expression}", params)
    return params.get(100)


def error_of(text: str, **options) -> str:
    with pytest.raises(GCodeError) as info:
        run(text, **options)
    return str(info.value)


# -- lines -> blocks ---------------------------------------------------------

def test_words_case_spaces_comments_and_columns() -> None:
    text = "n 10 G1 g 9 0 X 1 . 5 y-2 f500 (plain) M3 s 1000 ; tail"
    [block] = run(text)
    assert block.g == [1.0, 90.0]
    assert block.m == [3.0]
    assert block.words == {"x": 1.5, "y": -2.0, "f": 500.0, "s": 1000.0}
    assert block.line_number == 10
    assert block.comments == ["plain", "tail"]
    assert block.columns["g1"] == 6 and block.columns["g90"] == 9
    assert block.columns["x"] == 15 and block.columns["m3"] == text.index("M3") + 1
    assert block.line == 1 and block.file == "t.ngc"
    assert str(block.error("no", "x")) == "t.ngc:1:15: no"
    assert str(block.error("no", "g90")) == "t.ngc:1:9: no"


def test_dotted_codes_and_expression_words() -> None:
    [block] = run("#<_f>=7\nG38.2 Z[-1-1] F#<_f>")
    assert block.g == [38.2]
    assert block.words == {"z": -2.0, "f": 7.0}
    assert block.columns["g38.2"] == 1


def test_messages_and_debug_substitution() -> None:
    blocks = run("#1=2.5 #<_n>=3\n(MSG, Change tool now )\n"
                 "(debug, one=#1 n=#<_n> no=#<nothing>)")
    assert blocks[0].message == "Change tool now"
    assert blocks[1].message == "one=2.500000 n=3.000000 no=#"


def test_block_delete_flag_and_skipping() -> None:
    blocks = run("/g1 x1\ng1 x2")
    assert [b.block_delete for b in blocks] == [True, False]
    blocks = run("/#1=5 g1 x1\ng1 x[#1+2]", block_delete=True)
    assert [b.words["x"] for b in blocks] == [2.0]


def test_percent_delimits_and_m2_m30_end() -> None:
    assert [b.words["x"] for b in run("%\ng0 x1\n%\ng0 x2\n")] == [1.0]
    assert [b.words.get("x") for b in run("g0 x1\nm2\ng0 x2")] == [1.0, None]
    assert len(run("g0 x1\nM30\ng0 x2")) == 2
    # what follows the end is not even evaluated
    assert len(run("m2\ng0 x[1/0]")) == 1


def test_lexer_keeps_expressions_unevaluated() -> None:
    line = parse_line("g1 x#1 #2=[#1+1]")
    assert [w.letter for w in line.words] == ["g", "x"]
    assert len(line.assignments) == 1


# -- expressions -----------------------------------------------------------

@pytest.mark.parametrize("expression, expected", [
    ("[2.0 / 3 * 1.5 - 5.5 / 11.0]", 0.5),
    ("[2 + 3 * 4]", 14.0),
    ("[[2 + 3] * 4]", 20.0),
    ("[2 * 3 ** 2]", 18.0),
    ("[2 ** 3 ** 2]", 64.0),          # left to right within a group
    ("[10 - 4 - 3]", 3.0),
    ("[7 mod 3]", 1.0),
    ("[-7 mod 3]", 2.0),
    ("[1 + 2 eq 3]", 1.0),            # + binds tighter than EQ
    ("[1 eq 1 and 2 gt 1]", 1.0),      # EQ binds tighter than AND
    ("[0 or 0]", 0.0),
    ("[1 xor 1]", 0.0),
    ("[1 xor 0]", 1.0),
    ("[3 ne 3.00001]", 0.0),          # equality tolerance
    ("[3 ge 3.00001]", 1.0),
    ("[3 lt 3.00001]", 0.0),
    ("[2 le 1]", 0.0),
    ("[-[2]]", -2.0),
    ("[1 + acos[0] - [#3 ** [4.0/2]]]", 91.0),
])
def test_expression_precedence(expression: str, expected: float) -> None:
    assert value(expression) == pytest.approx(expected)


@pytest.mark.parametrize("expression, expected", [
    ("atan[1]/[-1]", 135.0),
    ("abs[-2.5]", 2.5),
    ("acos[0.5]", 60.0),
    ("asin[1]", 90.0),
    ("cos[60]", 0.5),
    ("exp[1]", math.e),
    ("fix[-2.8]", -3.0),
    ("fix[2.8]", 2.0),
    ("fup[-2.8]", -2.0),
    ("fup[2.2]", 3.0),
    ("round[2.5]", 3.0),
    ("round[-2.5]", -3.0),
    ("ln[1]", 0.0),
    ("sin[30]", 0.5),
    ("sqrt[16]", 4.0),
    ("tan[45]", 1.0),
    ("SQRT [ 9 ]", 3.0),
])
def test_functions(expression: str, expected: float) -> None:
    assert value(expression) == pytest.approx(expected)


def test_exists() -> None:
    params = Parameters()
    assert value("exists[#<_nope>]", params) == 0.0
    params.set("_yes", 1)
    assert value("EXISTS[#<_yes>]", params) == 1.0


# -- parameters -------------------------------------------------------------

def test_numbered_named_and_indirect_parameters() -> None:
    params = Parameters()
    run("#2=3 #3=7 #<Some Name>=4 #<_glob>=5\n"
        "#10=##2 #11=#[1+2] #12=#<somename> #13=#<_GLOB>", params)
    assert [params.get(n) for n in (10, 11, 12, 13)] == [7, 7, 4, 5]
    assert params.get(99) == 0.0


def test_assignments_take_effect_after_the_line_in_order() -> None:
    params = Parameters()
    params.set(3, 15)
    [block] = run("#3=6 G1 X#3 #4=#3", params)
    assert block.words["x"] == 15.0
    assert params.get(3) == 6.0 and params.get(4) == 15.0
    run("#5=1 #5=2", params)
    assert params.get(5) == 2.0


def test_predefined_named_parameters_are_read_only() -> None:
    params = Parameters()
    params.set_predefined(lambda name: 12.5 if name == "_x" else None)
    assert value("#<_x>", params) == 12.5
    with pytest.raises(GCodeError, match=r"t.ngc:1:4: .*read-only"):
        run("g0 #<_x>=3", params)


def test_var_file_round_trip_is_atomic(tmp_path: Path) -> None:
    path = tmp_path / "sim.var"
    path.write_text("junk line\n4000 9\n5161\t1.5\n5221 -2\n")
    params = Parameters()
    params.load(str(path))
    assert params.get(5161) == 1.5 and params.get(5221) == -2.0
    params.set(5222, 3.25)
    params.save(str(path))
    lines = path.read_text().splitlines()
    assert "4000\t9.000000" in lines and "5222\t3.250000" in lines
    numbers = [int(line.split()[0]) for line in lines]
    assert numbers == sorted(numbers) and 5390 in numbers
    assert (tmp_path / "sim.var.bak").read_text().startswith("junk")
    assert [p.name for p in tmp_path.iterdir()
            if p.name.startswith(".var-")] == []
    again = Parameters()
    again.load(str(path))
    assert again.get(5222) == 3.25 and again.get(4000) == 9.0


def test_var_file_out_of_order(tmp_path: Path) -> None:
    path = tmp_path / "bad.var"
    path.write_text("5221 1\n5161 2\n")
    with pytest.raises(GCodeError, match=r"bad.var:2:1: .*out of order"):
        Parameters().load(str(path))


def test_failed_save_leaves_old_file(tmp_path: Path, monkeypatch) -> None:
    path = tmp_path / "keep.var"
    path.write_text("5161\t1.0\n")
    params = Parameters()

    def boom(*args, **kwargs):
        raise OSError("disk full")
    monkeypatch.setattr(os, "fsync", boom)
    with pytest.raises(OSError):
        params.save(str(path))
    assert path.read_text() == "5161\t1.0\n"
    assert [p.name for p in tmp_path.iterdir()] == ["keep.var"]


# -- subroutines ------------------------------------------------------------

def test_subroutine_arguments_locals_and_return_values() -> None:
    params = Parameters()
    blocks = run("""#1=100 #<loc>=1
o<add> sub
  #<loc> = [#1 + #2]
  g0 x#<loc>
  o<add> return [#<loc> * 10]
o<add> endsub
o<add> call [2] [3]
#10=#<_value> #11=#<_value_returned> #12=#1 #13=#<loc>
o100 sub
o100 endsub
o100 call
#14=#<_value_returned>
""", params)
    assert [b.words["x"] for b in blocks] == [5.0]
    assert [params.get(n) for n in range(10, 15)] == [50, 1, 100, 1, 0]


def test_local_named_parameter_not_visible_in_callee() -> None:
    message = error_of("#<mine>=1\no<s> sub\ng0 x#<mine>\no<s> endsub\n"
                       "o<s> call\n")
    assert message.startswith("t.ngc:3:5: ") and "#<mine>" in message


def test_recursion_and_globals() -> None:
    params = Parameters()
    run("""o<fact> sub
  o1 if [#1 le 1]
    #<_r> = 1
  o1 else
    o<fact> call [#1 - 1]
    #<_r> = [#<_r> * #1]
  o1 endif
o<fact> endsub
o<fact> call [5]
""", params)
    assert params.get("_r") == 120.0


def test_call_of_a_subroutine_file() -> None:
    params = Parameters()
    blocks = list(Program.from_file(str(HERE / "main.ngc"), params).blocks())
    moves = [b for b in blocks if b.words]
    assert [b.words for b in moves] == [{"z": 6.0}, {"x": 12.0, "f": 100}]
    assert moves[0].file.endswith("drill_sub.ngc") and moves[0].line == 8
    assert blocks[-1].m == [30.0] and blocks[0].comments
    assert params.get("_drilled") == 6.0


def test_search_path_for_subroutine_files(tmp_path: Path) -> None:
    (tmp_path / "half.ngc").write_text(
        "o<half> sub\no<half> return [#1/2]\no<half> endsub\n")
    params = Parameters()
    run("o<half> call [9]\n#1=#<_value>", params, search_path=[str(tmp_path)])
    assert params.get(1) == 4.5


# -- control flow -------------------------------------------------------------

def test_nested_if_elseif_else() -> None:
    text = """o1 if [#1 gt 0]
  o2 if [#2 gt 0]
    g0 x1
  o2 else
    g0 x2
  o2 endif
o1 elseif [#1 lt 0]
  g0 x3
o1 else
  g0 x4
o1 endif
"""
    def x(a: float, b: float) -> float:
        params = Parameters()
        params.set(1, a)
        params.set(2, b)
        return [blk.words["x"] for blk in run(text, params)][0]
    assert (x(1, 1), x(1, -1), x(-1, 0), x(0, 0)) == (1, 2, 3, 4)


def test_while_with_break_and_continue() -> None:
    blocks = run("""o1 while [#1 lt 10]
  #1 = [#1 + 1]
  o2 if [#1 eq 3]
    o1 continue
  o2 endif
  o3 if [#1 eq 6]
    o1 break
  o3 endif
  g0 x#1
o1 endwhile
""")
    assert [b.words["x"] for b in blocks] == [1, 2, 4, 5]


def test_do_while_runs_once_and_continue_tests_condition() -> None:
    blocks = run("""o1 do
  #1 = [#1 + 1]
  o2 if [#1 eq 2]
    o1 continue
  o2 endif
  g0 x#1
o1 while [#1 lt 4]
o5 do
  g0 y1
o5 while [0]
""")
    assert [b.words for b in blocks] == [{"x": 1}, {"x": 3}, {"x": 4},
                                         {"y": 1}]


def test_repeat_with_break() -> None:
    blocks = run("""o1 repeat [5]
  #1 = [#1 + 1]
  o2 if [#1 eq 4]
    o1 break
  o2 endif
  g0 x#1
o1 endrepeat
o3 repeat [0]
  g0 y1
o3 endrepeat
""")
    assert [b.words["x"] for b in blocks] == [1, 2, 3]


def test_expressions_see_parameters_set_during_iteration() -> None:
    params = Parameters()
    program = Program("o1 while [#1 lt 3]\ng0 x#1\no1 endwhile\n", "t.ngc",
                      params)
    seen = []
    for block in program.blocks():
        seen.append(block.words["x"])
        params.set(1, params.get(1) + 1)   # as an interpreter might
    assert seen == [0, 1, 2]


def test_endless_loop_is_an_error_naming_the_loop() -> None:
    message = error_of("g0 x0\n  o7 while [1]\n  o7 endwhile\n",
                       max_iterations=50)
    assert message.startswith("t.ngc:2:3: loop exceeds the limit of 50 "
                              "loop iterations and subroutine calls")


# -- errors --------------------------------------------------------------------

@pytest.mark.parametrize("text, expected", [
    ("g1 &5", "t.ngc:1:4: Bad character '&' used"),
    ("g1 x1 y2 X3", "t.ngc:1:10: Multiple x words on one line"),
    ("g1 x1.2.3", "t.ngc:1:8: bad number format (trailing characters) "
                  "parsing '1.2.3'"),
    ("g1 x", "t.ngc:1:5: No characters found in reading real value"),
    ("g1 x-", "t.ngc:1:5: bad number format (conversion failed) parsing "
              "'-'"),
    ("g1 (open comment", "t.ngc:1:4: Unclosed comment found"),
    ("g1 (a (b) c)", "t.ngc:1:7: Nested comment found"),
    ("g1 x[1+[2*3]", "t.ngc:1:5: Unclosed expression"),
    ("g1 x[1 g 2]", "t.ngc:1:8: Unknown operation name starting with g"),
    ("g1 x[1 $ 2]", "t.ngc:1:8: Unknown operation"),
    ("g1 x[2 ** 2000]", "t.ngc:1:8: Calculation resulted in 'infinity'"),
    ("g0\ng1 x[4/[2-2]]", "t.ngc:2:7: Attempt to divide by zero"),
    ("g1 x[5 mod 0]", "t.ngc:1:8: Calculation resulted in 'not a number'"),
    ("g1 x[foo[2]]", "t.ngc:1:6: Unknown word starting with f"),
    ("g1 x[sqrt[-1]]", "t.ngc:1:6: Negative argument to sqrt"),
    ("g1 x#<undefined>", "t.ngc:1:5: Named parameter #<undefined> not "
                         "defined"),
    ("#<a=1", "t.ngc:1:2: Named parameter not terminated"),
    ("#1 5", "t.ngc:1:5: Equal sign missing"),      # spaces do not count
    ("#1 x2", "t.ngc:1:4: Equal sign missing in parameter setting"),
    ("g1 x#0", "t.ngc:1:5: Parameter number out of range"),
    ("o1 endsub", "t.ngc:1:1: 1: not in a subroutine definition: "
                  "'o1 endsub'"),
    ("o<a> sub\no<b> endsub", "t.ngc:2:1: O<b> endsub does not match"),
    ("g0\n  o2 if [1]\ng1", "t.ngc:2:3: O2 if without O2 endif"),
    ("o2 endif", "t.ngc:1:1: 1: undefined O-word label: 'o2 endif'"),
    ("o2 if [1]\no2 else\no2 elseif [1]\no2 endif",
     "t.ngc:3:1: O2 elseif after O2 else"),
    ("o3 while [1]\no4 endwhile",
     "t.ngc:2:1: 2: undefined O-word label: 'o4 endwhile'"),
    ("o3 repeat [2]\no3 endwhile",
     "t.ngc:2:1: 2: no matching label: 'o3 endwhile' (found 'repeat' in "
     "line 1)"),
    ("o5 break", "t.ngc:1:1: 1: undefined O-word label: 'o5 break'"),
    ("o<s> sub\ng0", "t.ngc:2:1: File ended with no percent sign or "
                     "program end"),
    ("o9 frob", "t.ngc:1:4: Unknown control command in o word"),
    ("g0 x1\n o<gone> call [1]",
     "t.ngc:2:1: EOF in file:t.ngc seeking o-word: o<gone> from line: 2"),
    ("g0 o1 call", "t.ngc:1:4: Bad character 'o' used"),
])
def test_error_locations(text: str, expected: str) -> None:
    assert error_of(text).startswith(expected)


def test_error_in_unreached_line_is_raised_when_reached() -> None:
    program = Program("g0 x1\ng0 x[1\n", "t.ngc")
    blocks = program.blocks()
    assert next(blocks).words == {"x": 1.0}
    with pytest.raises(GCodeError, match="t.ngc:2:5: Unclosed expression"):
        next(blocks)


def test_unknown_subroutine_in_file() -> None:
    with pytest.raises(GCodeError) as info:
        list(Program.from_file(str(HERE / "bad_call.ngc")).blocks())
    path = HERE / "bad_call.ngc"
    assert str(info.value) == (
        f"{path}:{len(path.read_text().splitlines())}:1: EOF in "
        f"file:{path} seeking o-word: o<no_such_sub> from line: 2")


def test_error_is_a_value_error_with_fields() -> None:
    error = GCodeError("bad", "", 3, 4)
    assert isinstance(error, ValueError)
    assert str(error) == "<string>:3:4: bad"
    assert (error.line, error.column, error.message) == (3, 4, "bad")


def test_signed_operands_and_words() -> None:
    params = Parameters()
    params.set(1, 3)
    [block] = run("g1 x-#1 y-[2] z-sin[90] a+[1] b - 1.5", params)
    assert block.words == {"x": -3, "y": -2, "z": -1, "a": 1, "b": -1.5}
    assert value("[2--1]") == 3.0
    assert value("[-#1*2]", params) == -6.0


def test_endsub_value_and_call_depth_limit() -> None:
    params = Parameters()
    run("o<v> sub\no<v> endsub [7]\no<v> call\n#1=#<_value>", params)
    assert params.get(1) == 7.0
    message = error_of("o<r> sub\no<r> call\no<r> endsub\no<r> call\n",
                       max_call_depth=5)
    assert message.startswith("t.ngc:2:1: Too many subroutine levels")


def test_more_than_thirty_arguments_is_an_error() -> None:
    args = " ".join(["[1]"] * 31)
    message = error_of(f"o<s> sub\no<s> endsub\no<s> call {args}")
    assert message.startswith("t.ngc:3:1: Too many subroutine parameters")


def test_line_number_only_at_start() -> None:
    assert error_of("g1 n10 x1").startswith("t.ngc:1:4: Bad character 'n' "
                                           "used")
