"""Values of HAL types: the one place that reads a word as a value.

:func:`parse_word` reads a word as the reference's halcmd does (C's
``strtol``/``strtoul``/``strtod``: ``0x`` hex and leading-``0`` octal
integers, hex floats, the bit words ``1``/``0``/``TRUE``/``FALSE``).
:func:`coerce` makes a value for a type from a Python value or a word, as
``Hal.setp``, ``Pin.value = ...`` and the compat module do.
"""

from __future__ import annotations

import re
from typing import Any, Optional, Union, cast

from halsdk.core import _core
from halsdk.core.errors import InvalidError, Rule
from halsdk.core.types import INT_RANGES, HalType

Value = Union[bool, int, float]

_DEC = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?\Z")
_HEX = re.compile(r"[+-]?0[xX]([0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)"
                  r"([pP][+-]?\d+)?\Z")
_SPECIAL = re.compile(r"([+-]?)(inf|infinity|nan|nan\([0-9A-Za-z_]*\))\Z",
                      re.IGNORECASE)


def c_float(word: str) -> Optional[float]:
    """A whole word as C's ``strtod`` reads it (decimal, ``0x`` hex
    floats, ``inf``/``infinity``/``nan``/``nan(...)`` in any case), or
    None when it is not all a number."""
    if _DEC.match(word):
        return float(word)
    if _HEX.match(word):
        return float.fromhex(word)
    m = _SPECIAL.match(word)
    if m:
        value = float("nan") if m.group(2).lower().startswith("nan") \
            else float("inf")
        return -value if m.group(1) == "-" else value
    return None


def c_wrap(htype: int, v: int) -> int:
    """An integer as C gives it to a variable of an integer HAL type:
    saturated as ``strtol``/``strtoul`` do (a minus sign negates an
    unsigned one modulo 2**64), then truncated to the type's width."""
    t = HalType(htype)
    if t in (HalType.S32, HalType.S64):
        v = max(-2**63, min(2**63 - 1, v))      # strtol saturates
        bits = 32 if t == HalType.S32 else 64
        v &= (1 << bits) - 1                     # then C truncates
        return v - (1 << bits) if v >> (bits - 1) else v
    if abs(v) >= 2**64:
        v = 2**64 - 1                            # strtoul saturates
    return v & (0xFFFFFFFF if t == HalType.U32 else 2**64 - 1)


def c_integer(text: str) -> int:
    """An integer as C's ``strtol(text, &end, 0)`` reads a whole word:
    ``0x`` hex, a leading ``0`` octal, else decimal (ValueError if not)."""
    return cast(int, _core.c_integer(text))


def parse_word(htype: int, text: str, *, wrap: bool = True) -> Value:
    """The value of a word for a HAL type; ValueError if it is none.

    With ``wrap`` (halcmd's ``setp``/``sets``), an integer out of range
    is saturated as ``strtol`` does and truncated to the type's width as
    C's assignment does; without, it raises ValueError.
    """
    t = HalType(htype)
    if t == HalType.BIT:
        if text == "1" or text.lower() == "true":
            return True
        if text == "0" or text.lower() == "false":
            return False
        raise ValueError(text)
    if t == HalType.FLOAT:
        f = c_float(text.strip())
        if f is None:
            raise ValueError(text)
        return f
    if text != text.rstrip():
        raise ValueError(text)          # strtol stops at a blank
    v = c_integer(text)
    if not wrap:
        lo, hi = INT_RANGES[t]
        if not lo <= v <= hi:
            raise ValueError(text)
        return v
    return c_wrap(t, v)


def coerce(htype: int, value: Any, what: str, wrap: bool = False) -> Value:
    """A value for HAL type ``htype`` from a Python value or a word.

    Bits take ``bool``, 0, 1 and the bit words; floats any real number;
    integers whole numbers in the type's range.  InvalidError (rule
    ``BAD_VALUE``) names ``what`` ("pin 'x.y'") otherwise.  With ``wrap``
    a word is read exactly as halcmd reads it (:func:`parse_word`).
    """
    t = HalType(htype)
    if wrap and isinstance(value, str):
        try:
            return parse_word(t, value, wrap=True)
        except ValueError:
            raise _bad(f"value '{value}' for {what} is not a valid "
                       f"{t.word}", what) from None
    if t == HalType.BIT:
        if isinstance(value, str):
            try:
                return parse_word(t, value.strip())
            except ValueError:
                pass
        elif hasattr(value, "__index__") and int(value) in (0, 1):
            return bool(int(value))
        raise _bad(f"value '{value}' for {what} is not a bit (0, 1, TRUE "
                   "or FALSE)", what)
    if t == HalType.FLOAT:
        try:
            if isinstance(value, str):
                return parse_word(t, value.strip())
            return float(value)
        except (TypeError, ValueError):
            raise _bad(f"value '{value}' for {what} is not a float",
                       what) from None
    try:
        if isinstance(value, str):
            v = c_integer(value.strip())
        elif isinstance(value, float):
            if not value.is_integer():
                raise ValueError
            v = int(value)
        else:
            v = int(value.__index__())
    except (TypeError, ValueError, AttributeError):
        raise _bad(f"value '{value}' for {what} is not an integer",
                   what) from None
    lo, hi = INT_RANGES[t]
    if not lo <= v <= hi:
        raise _bad(f"value {v} for {what} is out of range for {t.word} "
                   f"({lo} .. {hi})", what)
    return v


def _bad(message: str, what: str) -> InvalidError:
    kind, _, name = what.partition(" ")
    return InvalidError(message, rule=Rule.BAD_VALUE, kind=kind,
                        names=(name.strip("'"),))


__all__ = [
    "c_float",
    "c_integer",
    "c_wrap",
    "parse_word",
    "coerce",
    "Value",
]
