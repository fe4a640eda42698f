# Type information of the compiled hot path of the G-code reader
# (halsdk/gcode/_fast.pyx).
from typing import Optional

from .block import Block

def simple_words(text: str) -> Optional[
        tuple[Optional[float], list[tuple[str, float, int]]]]: ...
def simple_block(file: str, number: int, text: str,
                 line_number: Optional[float],
                 words: list[tuple[str, float, int]]) -> Block: ...
