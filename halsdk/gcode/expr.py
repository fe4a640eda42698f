"""Expression trees of G-code values and their evaluation."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Union

from .errors import GCodeError
from .params import Parameters

#: Two values closer than this compare equal (EQ, NE, GE, LE).
TOLERANCE_EQUAL = 0.0001


@dataclass
class Where:
    """The file and line an expression comes from, for error messages."""

    file: str
    line: int

    def error(self, message: str, column: int) -> GCodeError:
        return GCodeError(message, self.file, self.line, column)


class Expr:
    """A node of an expression; ``column`` is its 1-based source column."""

    column: int = 1

    def evaluate(self, params: Parameters, where: Where) -> float:
        raise NotImplementedError


@dataclass
class Number(Expr):
    value: float
    column: int = 1

    def evaluate(self, params: Parameters, where: Where) -> float:
        return self.value


@dataclass
class ParamRef(Expr):
    """``#n``, ``#[expr]``, ``##n`` (index is an Expr) or ``#<name>``."""

    index: Union[Expr, str]
    column: int = 1

    def key(self, params: Parameters, where: Where) -> Union[int, str]:
        if isinstance(self.index, str):
            return self.index
        value = self.index.evaluate(params, where)
        number = round(value)
        if abs(number - value) > 1e-4:
            raise where.error("Non integer value for integer",
                              self.column)
        return int(number)

    def evaluate(self, params: Parameters, where: Where) -> float:
        key = self.key(params, where)
        try:
            return params.get(key)
        except GCodeError as exc:
            raise where.error(exc.message, self.column) from None


@dataclass
class Negate(Expr):
    operand: Expr
    column: int = 1

    def evaluate(self, params: Parameters, where: Where) -> float:
        return -self.operand.evaluate(params, where)


def _degrees(fn: Callable[[float], float]) -> Callable[[float], float]:
    return lambda x: fn(math.radians(x))


def _round(x: float) -> float:
    return float(math.floor(abs(x) + 0.5)) * (1 if x >= 0 else -1)


#: Unary functions: name -> (function, domain check or None, domain text).
FUNCTIONS: dict[str, tuple[Callable[[float], float],
                           Callable[[float], bool] | None, str]] = {
    "abs": (abs, None, ""),
    "acos": (lambda x: math.degrees(math.acos(x)), lambda x: -1 <= x <= 1,
             "Argument to acos out of range"),
    "asin": (lambda x: math.degrees(math.asin(x)), lambda x: -1 <= x <= 1,
             "Argument to asin out of range"),
    "cos": (_degrees(math.cos), None, ""),
    "sin": (_degrees(math.sin), None, ""),
    "tan": (_degrees(math.tan), None, ""),
    "exp": (math.exp, lambda x: x < 709, "Calculation resulted in 'infinity'"),
    "fix": (lambda x: float(math.floor(x)), None, ""),
    "fup": (lambda x: float(math.ceil(x)), None, ""),
    "round": (_round, None, ""),
    "ln": (math.log, lambda x: x > 0, "Zero or negative argument to ln"),
    "sqrt": (math.sqrt, lambda x: x >= 0, "Negative argument to sqrt"),
}


@dataclass
class Function(Expr):
    name: str
    operand: Expr
    column: int = 1

    def evaluate(self, params: Parameters, where: Where) -> float:
        fn, valid, text = FUNCTIONS[self.name]
        value = self.operand.evaluate(params, where)
        if valid is not None and not valid(value):
            raise where.error(text, self.column)
        return float(fn(value))


@dataclass
class Atan(Expr):
    """``ATAN[y]/[x]``: the four-quadrant arc tangent in degrees."""

    y: Expr
    x: Expr
    column: int = 1

    def evaluate(self, params: Parameters, where: Where) -> float:
        return math.degrees(math.atan2(self.y.evaluate(params, where),
                                       self.x.evaluate(params, where)))


@dataclass
class Exists(Expr):
    name: str
    column: int = 1

    def evaluate(self, params: Parameters, where: Where) -> float:
        return 1.0 if params.exists(self.name) else 0.0


def _eq(a: float, b: float) -> bool:
    return abs(a - b) < TOLERANCE_EQUAL


def _mod(a: float, b: float) -> float:
    return math.fmod(a, b) if (a >= 0) == (b >= 0) else a - b * math.floor(a / b)


#: Binary operators: name -> (precedence, function); higher binds tighter.
BINARY: dict[str, tuple[int, Callable[[float, float], float]]] = {
    "**": (5, lambda a, b: a ** b),
    "*": (4, lambda a, b: a * b),
    "/": (4, lambda a, b: a / b),
    "mod": (4, _mod),
    "+": (3, lambda a, b: a + b),
    "-": (3, lambda a, b: a - b),
    "eq": (2, lambda a, b: float(_eq(a, b))),
    "ne": (2, lambda a, b: float(not _eq(a, b))),
    "gt": (2, lambda a, b: float(a > b and not _eq(a, b))),
    "ge": (2, lambda a, b: float(a > b or _eq(a, b))),
    "lt": (2, lambda a, b: float(a < b and not _eq(a, b))),
    "le": (2, lambda a, b: float(a < b or _eq(a, b))),
    "and": (1, lambda a, b: float(a != 0 and b != 0)),
    "or": (1, lambda a, b: float(a != 0 or b != 0)),
    "xor": (1, lambda a, b: float((a != 0) != (b != 0))),
}


@dataclass
class Binary(Expr):
    op: str
    left: Expr
    right: Expr
    column: int = 1

    def evaluate(self, params: Parameters, where: Where) -> float:
        a = self.left.evaluate(params, where)
        b = self.right.evaluate(params, where)
        if self.op == "/" and b == 0:
            raise where.error("Attempt to divide by zero", self.column)
        if self.op == "mod" and b == 0:
            raise where.error("Calculation resulted in 'not a number'",
                              self.column)
        try:
            result = BINARY[self.op][1](a, b)
        except OverflowError:
            raise where.error("Calculation resulted in 'infinity'",
                              self.column) from None
        except (ValueError, ZeroDivisionError) as exc:
            raise where.error(f"cannot compute {a:g} {self.op.upper()} "
                              f"{b:g}: {exc}", self.column) from None
        if isinstance(result, complex) or not math.isfinite(result):
            if self.op == "**" and a < 0:
                raise where.error("Attempt to raise negative to non integer "
                                  "power", self.column)
            raise where.error("Calculation resulted in 'not a number'"
                              if isinstance(result, complex)
                              or math.isnan(result) else
                              "Calculation resulted in 'infinity'",
                              self.column)
        return float(result)
