# Type information of the compiled G-code lexer (halsdk/gcode/_lex.pyx).
from typing import Optional

from .lexer import Line

def parse_line(text: str, file: str = ..., lineno: int = ...
               ) -> Optional[Line]: ...
