"""HAL types and directions, with the reference's numeric values."""

from __future__ import annotations

from enum import IntEnum
from typing import Union

from halsdk.core import _core
from halsdk.errors import InvalidError


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


class Direction(IntEnum):
    """Direction of a pin (IN, OUT, IO) or a param (RO, RW)."""

    IN = _core.IN
    OUT = _core.OUT
    IO = _core.IO
    RO = _core.RO
    RW = _core.RW


_TYPE_WORDS = {t.name.lower(): t for t in HalType}
_DIR_WORDS = {"in": Direction.IN, "out": Direction.OUT, "io": Direction.IO,
              "i/o": Direction.IO, "ro": Direction.RO, "rw": Direction.RW}


def parse_type(value: Union[str, int]) -> HalType:
    """A HalType from a word ("float") or a number."""
    if isinstance(value, str):
        t = _TYPE_WORDS.get(value.strip().lower())
        if t is None:
            raise InvalidError(f"unknown HAL type '{value}' (one of "
                               f"{', '.join(_TYPE_WORDS)})")
        return t
    try:
        return HalType(value)
    except ValueError:
        raise InvalidError(f"unknown HAL type {value!r}") from None


def parse_direction(value: Union[str, int], param: bool = False) -> Direction:
    """A Direction from a word ("in", "rw") or a number."""
    if isinstance(value, str):
        d = _DIR_WORDS.get(value.strip().lower())
    else:
        try:
            d = Direction(value)
        except ValueError:
            d = None
    allowed = (Direction.RO, Direction.RW) if param else (
        Direction.IN, Direction.OUT, Direction.IO)
    if d not in allowed:
        what = "param direction (ro, rw)" if param else \
            "pin direction (in, out, io)"
        raise InvalidError(f"{value!r} is not a {what}")
    return d
