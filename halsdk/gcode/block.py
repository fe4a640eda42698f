"""One parsed and evaluated line of G-code."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

from .errors import GCodeError


@dataclass
class Block:
    """The words of one executed line, with their values already computed.

    ``g`` and ``m`` hold every G and M number of the line in source order,
    ``words`` the other letters (lower case) and ``columns`` the 1-based
    column of each word (keys ``'x'``, ``'g38.2'``, ``'m6'`` ...), so the
    interpreter can point at the offending word.
    """

    file: str
    line: int
    text: str
    g: list[float] = field(default_factory=list)
    m: list[float] = field(default_factory=list)
    words: dict[str, float] = field(default_factory=dict)
    columns: dict[str, int] = field(default_factory=dict)
    comments: list[str] = field(default_factory=list)
    message: Optional[str] = None
    block_delete: bool = False
    line_number: Optional[float] = None   # the N word, if any

    def column_of(self, letter: str = "") -> int:
        """The column of ``letter`` (``'x'``, ``'g1'``, ``'m6'``) or 1."""
        key = letter.lower()
        if key in self.columns:
            return self.columns[key]
        if key[:1] in ("g", "m") and key[1:]:
            try:
                number = float(key[1:])
            except ValueError:
                return 1
            name = key[0] + _code_name(number)
            return self.columns.get(name, 1)
        return 1

    def error(self, msg: str, letter: str = "") -> GCodeError:
        """A :class:`GCodeError` for this block, at the column of ``letter``."""
        return GCodeError(msg, self.file, self.line, self.column_of(letter))

    def has(self, letter: str) -> bool:
        """True if the block has the (non G/M) word ``letter``."""
        return letter.lower() in self.words


def _code_name(number: float) -> str:
    """``1.0`` -> ``'1'``, ``38.2`` -> ``'38.2'`` (the key form of codes)."""
    text = f"{round(number, 4):.4f}".rstrip("0").rstrip(".")
    return text or "0"


_CODE_KEYS: dict[tuple[str, float], str] = {}


def code_key(letter: str, number: float) -> str:
    """The ``columns`` key of a G or M code: ``code_key('g', 38.2) == 'g38.2'``."""
    key = _CODE_KEYS.get((letter, number))
    if key is None:
        key = letter.lower() + _code_name(number)
        # a few hundred codes are in use; 0 is not kept (-0.0 == 0.0 but
        # its key is 'g-0')
        if number and len(_CODE_KEYS) < 4096:
            _CODE_KEYS[(letter, number)] = key
    return key
