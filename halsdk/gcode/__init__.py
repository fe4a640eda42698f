"""G-code (RS274/NGC): front end (lines, expressions, parameters, o-words)
and interpreter."""

from .block import Block
from .errors import GCodeError
from .lexer import parse_line
from .params import Parameters
from .program import Program

__all__ = ["Block", "GCodeError", "Parameters", "Program", "parse_line"]
