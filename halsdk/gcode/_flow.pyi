# Type information of the compiled control flow of a G-code program
# (halsdk/gcode/_flow.pyx).
from collections.abc import Iterator
from typing import Any

from .block import Block

def run(program: Any, interp: Any = None) -> Iterator[Block]: ...
