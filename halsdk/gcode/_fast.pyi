# Type information of the compiled hot path of the G-code reader and
# interpreter (halsdk/gcode/_fast.pyx).
from typing import Any, Optional

from .block import Block

EMPTY: tuple[str]
COORD_CODES: tuple[int, ...]
PLANES: dict[int, tuple[int, int, int, str]]

def simple_words(text: str) -> Optional[
        tuple[Optional[float], list[tuple[str, float, int]]]]: ...
def simple_block(file: str, number: int, text: str,
                 line_number: Optional[float],
                 words: list[tuple[str, float, int]]) -> Block: ...
def read_line(unit: Any, index: int) -> Any: ...
def set_file_lines(cls: type, text_cls: Optional[type] = None) -> None: ...
def fast_move(interp: Any, block: Block) -> bool: ...
def run_plain(unit: Any, index: int, interp: Any,
              main_flow: bool) -> tuple[int, Any, bool]: ...
