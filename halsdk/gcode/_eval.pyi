# Type information of the compiled evaluator of G-code expressions
# (halsdk/gcode/_eval.pyx).
from typing import Any

from .expr import Expr

def evaluate(expr: Expr, params: Any, file: str, line: int) -> float: ...
def make_block(program: Any, line: Any) -> Any: ...
