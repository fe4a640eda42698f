"""HAL types and directions, with the reference's numeric values.

This module is the one table of type and direction words: the names a
program writes (``"float"``, ``"in"``), the words halcmd shows (``show``
prints ``float`` and ``s32``, ``setp`` errors say ``S32``), and the
directions as ``show`` prints them (``IN``, ``OUT``, ``I/O``, ``RO``,
``RW``).  Every front end takes its words from here.
"""

from __future__ import annotations

from enum import IntEnum
from typing import Union

from halsdk.core import _core
from halsdk.core.errors import InvalidError


class HalType(IntEnum):
    """Type of a pin, param or signal."""

    BIT = _core.BIT
    FLOAT = _core.FLOAT
    S32 = _core.S32
    U32 = _core.U32
    S64 = _core.S64
    U64 = _core.U64

    def __str__(self) -> str:
        return self.name.lower()

    @property
    def word(self) -> str:
        """The type as programs and ``show`` write it: ``"s32"``."""
        return TYPE_WORDS[self]

    @property
    def value_word(self) -> str:
        """The type as the reference's value errors write it: ``"S32"``
        (``bit`` and ``float`` stay lower case)."""
        return VALUE_WORDS[self]

    @property
    def is_integer(self) -> bool:
        return self not in (HalType.BIT, HalType.FLOAT)

    @property
    def range(self) -> tuple[int, int]:
        """(least, most) value of an integer type."""
        return INT_RANGES[self]


class Direction(IntEnum):
    """Direction of a pin (IN, OUT, IO) or a param (RO, RW)."""

    IN = _core.IN
    OUT = _core.OUT
    IO = _core.IO
    RO = _core.RO
    RW = _core.RW

    @property
    def word(self) -> str:
        """The direction as ``show`` prints it: ``"IN"``, ``"I/O"``."""
        return DIR_WORDS[self]


#: type -> the word programs write and ``show`` prints (the core's words)
TYPE_WORDS: dict[HalType, str] = {
    HalType(t): w for t, w in _core.TYPE_NAMES.items()}
#: type -> the word of the reference's "value invalid for ..." errors
VALUE_WORDS = {HalType.BIT: "bit", HalType.FLOAT: "float",
               HalType.S32: "S32", HalType.U32: "U32", HalType.S64: "S64",
               HalType.U64: "U64"}
#: direction -> the word ``show`` prints (the core's words)
DIR_WORDS: dict[Direction, str] = {
    Direction(d): w for d, w in _core.DIR_NAMES.items()}
#: integer type -> (least, most)
INT_RANGES = {HalType.S32: (-(1 << 31), (1 << 31) - 1),
              HalType.U32: (0, (1 << 32) - 1),
              HalType.S64: (-(1 << 63), (1 << 63) - 1),
              HalType.U64: (0, (1 << 64) - 1)}

_TYPE_BY_WORD = {w: t for t, w in TYPE_WORDS.items()}
_DIR_BY_WORD = {"in": Direction.IN, "out": Direction.OUT,
                "io": Direction.IO, "i/o": Direction.IO,
                "ro": Direction.RO, "rw": Direction.RW}


def type_word(value: int, unknown: str = "???") -> str:
    """The word of a type number (``unknown`` for a number that is none)."""
    try:
        return TYPE_WORDS[HalType(value)]
    except ValueError:
        return unknown


def dir_word(value: int, unknown: str = "???") -> str:
    """The ``show`` word of a direction number."""
    try:
        return DIR_WORDS[Direction(value)]
    except ValueError:
        return unknown


def parse_type(value: Union[str, int]) -> HalType:
    """A HalType from a word ("float", any case) or a number."""
    if isinstance(value, str):
        t = _TYPE_BY_WORD.get(value.strip().lower())
        if t is None:
            raise InvalidError(f"unknown HAL type '{value}' (one of "
                               f"{', '.join(_TYPE_BY_WORD)})")
        return t
    try:
        return HalType(value)
    except ValueError:
        raise InvalidError(f"unknown HAL type {value!r}") from None


def parse_direction(value: Union[str, int], param: bool = False) -> Direction:
    """A Direction from a word ("in", "rw") or a number."""
    if isinstance(value, str):
        d = _DIR_BY_WORD.get(value.strip().lower())
    else:
        try:
            d = Direction(value)
        except ValueError:
            d = None
    allowed = (Direction.RO, Direction.RW) if param else (
        Direction.IN, Direction.OUT, Direction.IO)
    if d is None or d not in allowed:
        what = "param direction (ro, rw)" if param else \
            "pin direction (in, out, io)"
        raise InvalidError(f"{value!r} is not a {what}")
    return d


__all__ = [
    "HalType",
    "Direction",
    "TYPE_WORDS",
    "VALUE_WORDS",
    "DIR_WORDS",
    "INT_RANGES",
    "type_word",
    "dir_word",
    "parse_type",
    "parse_direction",
]
