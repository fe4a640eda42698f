"""The bounds of runaway control flow (issue 19): loop iterations and
subroutine calls of one run counted together, and the time the control
flow runs without handing out a block."""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from halsdk.gcode import GCodeError, Program
from halsdk.gcode.program import MAX_IDLE_TIME, MAX_ITERATIONS


def frozen() -> float:
    """A clock that never moves: only the iteration bound can trigger."""
    return 0.0


class Ticking:
    """A clock that moves ``step`` seconds at every reading; a consumer
    may move it further with :meth:`advance`."""

    def __init__(self, step: float = 0.0) -> None:
        self.now = 0.0
        self.step = step

    def __call__(self) -> float:
        self.now += self.step
        return self.now

    def advance(self, seconds: float) -> None:
        self.now += seconds


def failure(program: Program) -> tuple[GCodeError, int]:
    """The error of running ``program`` and the blocks it gave before."""
    handed = 0
    with pytest.raises(GCodeError) as info:
        for _ in program.blocks():
            handed += 1
    return info.value, handed


NESTED = """G21 G90
o1 repeat [99999]
  o2 repeat [99999]
  o2 endrepeat
o1 endrepeat
M2
"""


def test_nested_big_loops_stop_at_the_total_bound() -> None:
    program = Program(NESTED, "nested.ngc", clock=frozen)
    error, handed = failure(program)
    # 1 + 99999 counts per outer iteration: the 11th outer one is too many
    assert str(error).startswith(
        f"nested.ngc:2:1: loop exceeds the limit of {MAX_ITERATIONS} loop "
        "iterations and subroutine calls in one run (endless loop?); "
        "raise it with Program(max_iterations=...) or "
        "[RS274NGC]HALSDK_MAX_ITERATIONS")
    assert program.iterations == MAX_ITERATIONS
    assert handed == 1                  # G21 G90


def test_the_inner_loop_is_named_when_it_reaches_the_bound() -> None:
    program = Program(NESTED, "nested.ngc", clock=frozen,
                      max_iterations=1000)
    error, _ = failure(program)
    assert (error.file, error.line, error.column) == ("nested.ngc", 3, 3)
    assert "limit of 1000 loop iterations" in error.message
    assert program.iterations == 1000


def test_a_loop_of_moves_longer_than_a_per_loop_bound_runs() -> None:
    # the old guard stopped every loop after 100000 iterations
    text = "o1 repeat [150000]\nG1 X1 F100\no1 endrepeat\nM2\n"
    program = Program(text, "moves.ngc")
    blocks = sum(1 for _ in program.blocks())
    assert blocks == 150000 + 1
    assert program.iterations == 150000


def test_loops_and_calls_count_together() -> None:
    text = """o<s> sub
o3 repeat [4]
  G0 X1
o3 endrepeat
o<s> endsub
o1 repeat [3]
  o<s> call
o1 endrepeat
M2
"""
    # 3 + 3 calls + 3 * 4 = 18
    program = Program(text, "t.ngc")
    assert sum(1 for _ in program.blocks()) == 12 + 1
    assert program.iterations == 18
    error, handed = failure(Program(text, "t.ngc", max_iterations=17))
    assert (error.line, handed) == (2, 11)
    assert error.message.startswith("loop exceeds the limit of 17")


def test_branching_recursion_is_bounded_by_its_calls() -> None:
    # depth 31 only, but 2**31 calls
    text = """o<r> sub
o<r> if [#1 gt 0]
  o<r> call [#1 - 1]
  o<r> call [#1 - 1]
o<r> endif
o<r> endsub
o<r> call [30]
"""
    program = Program(text, "r.ngc", max_iterations=5000, clock=frozen)
    error, _ = failure(program)
    assert error.line in (3, 4) and error.column == 3
    assert error.message.startswith("subroutine call exceeds the limit "
                                    "of 5000")
    assert program.iterations == 5000


def test_do_while_and_continue_count_each_body_run() -> None:
    text = """#1 = 0
o1 do
  #1 = [#1 + 1]
  o1 if [#1 lt 3]
    o1 continue
  o1 endif
  G0 X#1
o1 while [#1 lt 5]
#2 = 0
o2 while [#2 lt 4]
  #2 = [#2 + 1]
o2 endwhile
"""
    program = Program(text, "t.ngc")
    assert [b.words["x"] for b in program.blocks()] == [3, 4, 5]
    assert program.iterations == 5 + 4


def test_a_loop_without_blocks_stops_at_the_time_limit() -> None:
    clock = Ticking(step=0.5)
    program = Program("G0 X0\n  o7 while [1]\n  o7 endwhile\n", "t.ngc",
                      max_idle_time=3, clock=clock)
    error, handed = failure(program)
    assert handed == 1
    assert (error.line, error.column) == (2, 3)
    assert error.message.startswith("loop ran 3.5 s without a block to "
                                    "execute, more than the limit of 3 s")
    assert "Program(max_idle_time=...) or [RS274NGC]HALSDK_MAX_IDLE_TIME" \
        in error.message
    assert program.iterations < 10


def test_blocks_restart_the_time_and_their_consumer_is_not_counted(
        ) -> None:
    clock = Ticking(step=1.0)
    program = Program("o1 repeat [50]\nG0 X1\no1 endrepeat\n", "t.ngc",
                      max_idle_time=1.5, clock=clock)
    for _ in program.blocks():
        clock.advance(100.0)            # the machine moves, slowly
    assert program.iterations == 50


def test_comment_blocks_do_not_restart_the_time() -> None:
    clock = Ticking(step=1.0)
    program = Program("o1 repeat [50]\n(only a comment)\no1 endrepeat\n",
                      "t.ngc", max_idle_time=10, clock=clock)
    holding = 0

    def consume() -> None:
        nonlocal holding
        for _ in program.blocks():
            holding += 1
            clock.advance(100.0)        # held by the consumer: not idle
    with pytest.raises(GCodeError, match="t.ngc:1:1: loop ran"):
        consume()
    assert 1 < holding < 10


def test_each_run_starts_from_zero() -> None:
    program = Program("o1 repeat [3]\no1 endrepeat\n", max_iterations=3)
    list(program.blocks())
    list(program.blocks())
    assert program.iterations == 3


@pytest.mark.parametrize("options, message", [
    ({"max_iterations": 0}, "max_iterations must be at least 1"),
    ({"max_idle_time": 0}, "max_idle_time must be more than 0 s"),
    ({"max_idle_time": float("nan")}, "max_idle_time must be more than"),
])
def test_bad_limits_are_refused(options, message) -> None:
    with pytest.raises(ValueError, match=message):
        Program("", **options)


def test_defaults() -> None:
    program = Program("")
    assert (program.max_iterations, program.max_idle_time) == \
        (MAX_ITERATIONS, MAX_IDLE_TIME) == (1_000_000, 5.0)


# -- property: completes exactly or stops at the bound ------------------------

@dataclass
class Loop:
    kind: str                   # repeat, while, do
    count: int
    emits: bool
    body: list[Loop] = field(default_factory=list)

    @property
    def runs(self) -> int:
        """How often the body runs each time the loop is reached."""
        return max(self.count, 1) if self.kind == "do" else self.count


loops = st.recursive(
    st.builds(Loop, st.sampled_from(["repeat", "while", "do"]),
              st.integers(0, 5), st.booleans()),
    lambda inner: st.builds(Loop, st.sampled_from(["repeat", "while", "do"]),
                            st.integers(0, 5), st.booleans(),
                            st.lists(inner, max_size=3)),
    max_leaves=8)


def source(body: list[Loop]) -> str:
    lines: list[str] = []
    number = 0

    def emit(loop: Loop, indent: str) -> None:
        nonlocal number
        number += 1
        n, i = number, f"#<i{number}>"
        inner = indent + "  "
        if loop.kind == "repeat":
            lines.append(f"{indent}o{n} repeat [{loop.count}]")
        else:
            lines.append(f"{indent}{i} = 0")
            lines.append(f"{indent}o{n} " + (
                f"while [{i} lt {loop.count}]" if loop.kind == "while"
                else "do"))
            lines.append(f"{inner}{i} = [{i} + 1]")
        if loop.emits:
            lines.append(f"{inner}G0 X{n}")
        for child in loop.body:
            emit(child, inner)
        lines.append(f"{indent}o{n} " + {
            "repeat": "endrepeat", "while": "endwhile",
            "do": f"while [{i} lt {loop.count}]"}[loop.kind])
    for loop in body:
        emit(loop, "")
    return "\n".join(lines) + "\n"


def expected(body: list[Loop], times: int = 1) -> tuple[int, int]:
    """(iterations, blocks) of running ``body`` ``times`` times."""
    iterations = blocks = 0
    for loop in body:
        runs = times * loop.runs
        iterations += runs
        blocks += runs if loop.emits else 0
        deeper = expected(loop.body, runs)
        iterations += deeper[0]
        blocks += deeper[1]
    return iterations, blocks


@settings(max_examples=200, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(loops, min_size=1, max_size=3), st.integers(1, 300))
def test_programs_complete_exactly_or_stop_at_the_bound(body, bound) -> None:
    text = source(body)
    program = Program(text, "p.ngc", max_iterations=bound, clock=frozen)
    iterations, blocks = expected(body)
    got = 0
    try:
        for _ in program.blocks():
            got += 1
            assert program.iterations <= bound
    except GCodeError as error:
        assert iterations > bound, text
        assert error.message.startswith(
            f"loop exceeds the limit of {bound} loop iterations")
        assert text.splitlines()[error.line - 1].strip().startswith("o")
        assert program.iterations == bound
        assert got <= blocks
    else:
        assert iterations <= bound, text
        assert (program.iterations, got) == (iterations, blocks)
