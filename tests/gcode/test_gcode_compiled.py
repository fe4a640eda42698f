"""The compiled lexer and evaluator agree with the Python ones.

``lexer.parse_line`` reads a line with the compiled lexer (``_lex``) and
falls back to the Python lexer (``parse_line_python``) for any line the
compiled one refuses; the program front end evaluates values with the
compiled evaluator (``_eval.evaluate``), which falls back to the Python
tree.  For random lines and expressions, both must give the same lines,
values and errors (message and column).
"""

from __future__ import annotations

import copy
import math
import pickle
from typing import Optional

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from halsdk.gcode import GCodeError, Parameters, Program, _eval, _lex, lexer
from halsdk.gcode.expr import Where

# -- the lexer ---------------------------------------------------------------

TOKENS = st.sampled_from([
    "G", "g", "M", "X", "Y", "Z", "F", "N", "n", "O", "o", "I", "J", "P",
    "Q", "R", "S", "T", "E", "K", "L", "D", "H", "1", "0", "2.5", "-", "+",
    ".", "..", "3.", ".5", "12", "007", "[", "]", "#", "##", "#<",
    "<", ">", "<a b>", "<_x>", "=", "*", "**", "/", "MOD", "mod", "EQ",
    "NE", "GT", "GE", "LT", "LE", "AND", "OR", "XOR", "and", "xo", "SIN",
    "cos", "ATAN", "atan", "EXISTS", "exists", "SQRT", "abs", "FIX",
    "foo", "sub", "endsub", "call", "if", "elseif", "else", "endif",
    "while", "endwhile", "do", "repeat", "endrepeat", "return", "break",
    "continue", " ", "\t", "(c)", "(msg,hi)", "(debug, #1)", "(", ")",
    ";x", "%", "\x0b", "\x1c", "\x00", "é", "$", "1" * 320,
])

LINES = st.lists(TOKENS, max_size=14).map("".join)

WORD_LINE = st.builds(
    lambda parts: " ".join(parts),
    st.lists(st.sampled_from([
        "G1", "X[1+2*SIN[30]]", "Y#1", "Z-#<a>", "#<b>=[#2 MOD 3]",
        "F[ATAN[1]/[2]]", "#3=-[1]", "S[EXISTS[#<c>]]", "M3",
        "T[2**3]", "(note)", "I[FUP[2.5] - FIX[-1.5]]", "J[#[1+2]]",
        "#<_g>=[1 EQ 1.00001 OR 2 LT 1 XOR 0]", "R[ROUND[-2.5]]",
    ]), max_size=6))

OWORD_LINE = st.builds(
    lambda name, keyword, args: f"o{name} {keyword}{args}",
    st.sampled_from(["100", "<name>", "<A b>", "[#1]", "#2", "007"]),
    st.sampled_from(["sub", "endsub", "call", "if", "elseif", "else",
                     "endif", "while", "endwhile", "do", "repeat",
                     "endrepeat", "return", "break", "continue", "what"]),
    st.sampled_from(["", " [1]", " [#1 GT 2]", " [1] [2] [3]", " [", "x"]))


def python_result(text: str) -> object:
    try:
        return lexer.parse_line_python(text, "t.ngc", 7)
    except GCodeError as exc:
        return str(exc)


@settings(max_examples=1000, deadline=None)
@given(st.one_of(LINES, WORD_LINE, OWORD_LINE))
def test_compiled_lexer_agrees(text: str) -> None:
    expected = python_result(text)
    compiled = _lex.parse_line(text, "t.ngc", 7)
    if isinstance(expected, str):
        assert compiled is None           # errors are the Python lexer's
    elif text.isascii():
        assert compiled == expected       # the compiled lexer read it
    else:
        assert compiled is None
    try:
        got: object = lexer.parse_line(text, "t.ngc", 7)
    except GCodeError as exc:
        got = str(exc)
    assert got == expected


def test_compiled_lexer_reads_a_line_with_everything() -> None:
    text = ("/N20 G1 X[1 + 2 * SIN[30]] Y-#<A b> #5=[#[1+1] MOD 3] "
            "(msg, hi) Z[ATAN[1]/[2]] F[EXISTS[#<_x>]] ; rest")
    line = _lex.parse_line(text, "t.ngc", 3)
    assert line is not None
    assert line == lexer.parse_line_python(text, "t.ngc", 3)
    assert line.block_delete and line.line_number == 20.0
    assert [w.letter for w in line.words] == ["g", "x", "y", "z", "f"]
    assert [c.kind for c in line.comments] == ["msg", ""]


def test_compiled_lexer_leaves_errors_to_python() -> None:
    for text in ("G1 X[1", "G1 X1 X2", "o100 if", "G1 (a", "#1 2",
                 "G1 X1..2", "G1 XFOO[1]", "N1 N2"):
        assert _lex.parse_line(text, "t.ngc", 7) is None
        try:
            lexer.parse_line(text, "t.ngc", 7)
        except GCodeError as exc:
            assert str(exc) == python_result(text)
        else:
            raise AssertionError(f"{text!r} was read")


# -- the evaluator -------------------------------------------------------------

NUMBER = st.sampled_from(["0", "1", "2", "-1", "0.5", "3.25", "1.", ".5",
                          "90", "180", "-30", "1000", "0.00001", "7",
                          "12345678", "-0.5", "2.0001"])
PARAM = st.sampled_from(["#1", "#2", "#3", "#31", "#5220", "#5421",
                         "#5602", "#<a>", "#<b>", "#<_g>", "#<_x>",
                         "#<_missing>", "#<nothing>", "#[1+1]", "##1",
                         "#[0.5]", "#[6000]", "#[#2*2]", "#2.00001"])
FUNCTION = st.sampled_from(["ABS", "ACOS", "ASIN", "COS", "SIN", "TAN",
                            "EXP", "FIX", "FUP", "ROUND", "LN", "SQRT"])
OPERATOR = st.sampled_from(["**", "*", "/", "MOD", "+", "-", "EQ", "NE",
                            "GT", "GE", "LT", "LE", "AND", "OR", "XOR"])


def expressions() -> st.SearchStrategy[str]:
    def extend(inner: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
        return st.one_of(
            st.builds(lambda a, op, b: f"[{a} {op} {b}]", inner, OPERATOR,
                      inner),
            st.builds(lambda f, a: f"{f}[{a}]", FUNCTION, inner),
            st.builds(lambda a, b: f"ATAN[{a}]/[{b}]", inner, inner),
            st.builds(lambda a: f"-{a}", inner.filter(
                lambda a: a[:1] in "[#A")),
            st.builds(lambda a: f"#[{a}]", inner),
            st.sampled_from(["EXISTS[#<a>]", "EXISTS[#<_g>]",
                             "EXISTS[#<zz>]"]))
    return st.recursive(st.one_of(NUMBER, PARAM), extend, max_leaves=12)


def make_params(depth: int, values: list[float]) -> Parameters:
    params = Parameters()
    params.set(1, values[0])
    params.set(2, values[1])
    params.set(5220, 1.0)
    params.set("a", values[2])
    params.set("_g", values[3])
    if depth:
        params.push_scope([values[1], values[0]])
        params.set("b", values[0])

    def predefined(name: str) -> Optional[float]:
        return {"_x": 1.5, "5421": -2.0}.get(name)
    params.set_predefined(predefined)
    return params


def outcome(fn) -> object:
    try:
        value = fn()
    except GCodeError as exc:
        return ("error", str(exc))
    except (ArithmeticError, ValueError) as exc:    # what Python raises
        return ("raised", type(exc), str(exc))
    return ("value", math.copysign(1, value) if value == 0 else 0, value)


VALUE = st.sampled_from([0.0, 1.0, -1.0, 2.0, 0.5, 360.0, -7.25, 1e300])


@settings(max_examples=1000, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(expressions(), st.integers(0, 1), st.lists(VALUE, min_size=4,
                                                   max_size=4))
def test_compiled_evaluator_agrees(text: str, depth: int,
                                   values: list[float]) -> None:
    line = lexer.parse_line_python(f"X{text}", "e.ngc", 4)
    expr = line.words[0].value
    params = make_params(depth, values)
    expected = outcome(lambda: expr.evaluate(params, Where("e.ngc", 4)))
    assert outcome(lambda: _eval.evaluate(expr, params, "e.ngc", 4)) \
        == expected
    # again: the compiled form is kept on the tree
    assert outcome(lambda: _eval.evaluate(expr, params, "e.ngc", 4)) \
        == expected


def test_compiled_form_copies_and_pickles() -> None:
    line = lexer.parse_line("G1 X[#1 + 2 * COS[60]]")
    expr = line.words[1].value
    params = Parameters()
    params.set(1, 3.0)
    assert _eval.evaluate(expr, params, "f", 1) == 4.0
    assert "_compiled" in vars(expr)
    for copied in (copy.deepcopy(expr), pickle.loads(pickle.dumps(expr))):
        assert _eval.evaluate(copied, params, "f", 1) == 4.0
        assert copied == expr


def test_program_runs_values_through_the_compiled_evaluator() -> None:
    text = ("#<n> = 0\n#1 = 2\no1 while [#<n> LT 3]\n"
            "G1 X[#<n> * #1] Y[SQRT[#<n>]]\n#<n> = [#<n> + 1]\n"
            "o1 endwhile\nG1 X[1/#<n> - 1/3]\nG1 X[1/0]\n")
    blocks = []
    try:
        for block in Program(text, "w.ngc").blocks():
            blocks.append(block.words)
    except GCodeError as exc:
        error = str(exc)
    assert blocks == [{"x": 0.0, "y": 0.0}, {"x": 2.0, "y": 1.0},
                      {"x": 4.0, "y": math.sqrt(2)}, {"x": 0.0}]
    assert error == "w.ngc:8:7: Attempt to divide by zero"


ASSIGN_LINE = st.builds(
    lambda parts: " ".join(parts),
    st.lists(st.sampled_from([
        "G1", "G38.2", "M3", "M2", "X[#1 + 1]", "Y#<a>", "#1=[#2 + 1]",
        "#<a>=[#1 * 2]", "#<A B>=3", "#<_g>=[#<_g> + 1]", "#5400=1",
        "#5421=2", "#[#2]=4", "#[0.5]=1", "#31=[#1]", "#<_x>=1",
        "(msg, hello)", "(debug, a #1 #<a> #<zz>)", "(print,#<_g>)",
        "(plain)", "Z[#<nothing>]", "F[1/0]",
    ]), max_size=6, unique=True))


def block_outcome(program: Program, line: object, compiled: bool) -> object:
    try:
        block = program._block(line) if compiled else \
            program._block_python(line)
    except GCodeError as exc:
        result: object = str(exc)
    else:
        result = vars(block)
    params = program.params
    return (result, params._numbered, params._globals,
            [(f.numbered, f.named) for f in params._frames])


@settings(max_examples=500, deadline=None)
@given(ASSIGN_LINE, st.integers(0, 1), st.lists(VALUE, min_size=4,
                                                 max_size=4))
def test_compiled_block_agrees(text: str, depth: int,
                               values: list[float]) -> None:
    try:
        line = lexer.parse_line_python(text, "b.ngc", 2)
    except GCodeError:
        return          # two words of a letter
    outcomes = []
    for compiled in (True, False):
        program = Program("", "b.ngc", make_params(depth, values))
        outcomes.append(block_outcome(program, line, compiled))
    assert outcomes[0] == outcomes[1]
