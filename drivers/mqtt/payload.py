"""JSON payloads: encode published values, decode and check received ones."""

from __future__ import annotations

import json
import math
from typing import Any, Union

Value = Union[bool, int, float]

#: HAL type name -> (lowest, highest) for the integer types
INT_RANGES = {"s32": (-(2 ** 31), 2 ** 31 - 1), "u32": (0, 2 ** 32 - 1),
              "s64": (-(2 ** 63), 2 ** 63 - 1), "u64": (0, 2 ** 64 - 1)}
TYPES = ("bit", "float", *INT_RANGES)
#: largest received payload, bytes; longer ones are rejected unread
MAX_PAYLOAD = 65536
#: keys allowed in an object payload sent to a subscribed topic
SINGLE_KEYS = frozenset(("value", "type", "timestamp", "name"))


class PayloadError(ValueError):
    """A received payload that cannot set its pin."""


def dumps(obj: Any) -> str:
    """Compact JSON; non-finite floats become null (JSON has no NaN)."""
    return json.dumps(obj, separators=(",", ":"), allow_nan=False,
                      default=str)


def clean(value: Value) -> Value:
    """A HAL value as JSON can carry it."""
    if isinstance(value, float) and not math.isfinite(value):
        return None  # type: ignore[return-value]
    return value


def single(name: str, type_: str, value: Value, stamp: float) -> str:
    """The payload of one item: name, value, HAL type and time."""
    return dumps({"name": name, "value": clean(value), "type": type_,
                  "timestamp": round(stamp, 6)})


def batch(values: dict[str, Value], stamp: float, flat: bool) -> str:
    """The payload of a periodic publish of all items."""
    cleaned = {name: clean(v) for name, v in values.items()}
    if flat:
        return dumps(cleaned)
    return dumps({"timestamp": round(stamp, 6), "values": cleaned})


def _reject_constant(word: str) -> None:
    raise PayloadError(f"not JSON: {word} is not a number")


def parse(raw: bytes) -> Any:
    """Decode a payload as JSON (UTF-8) of at most MAX_PAYLOAD bytes."""
    if len(raw) > MAX_PAYLOAD:
        raise PayloadError(f"{len(raw)} bytes, more than the limit of "
                           f"{MAX_PAYLOAD}")
    shown = raw[:40].decode("utf-8", "replace")
    try:
        text = raw.decode("utf-8")
        return json.loads(text, parse_constant=_reject_constant)
    except PayloadError:
        raise
    except RecursionError:
        raise PayloadError(f"not JSON (nested too deeply): {shown!r}") \
            from None
    except (ValueError, TypeError) as exc:   # UnicodeDecodeError too
        raise PayloadError(f"not JSON ({exc.__class__.__name__}): "
                           f"{shown!r}") from None


def unwrap(obj: Any, type_: str) -> Any:
    """The value of a single-item payload: a bare JSON value, or an object
    with ``value`` (and optionally ``type``, ``timestamp``, ``name``)."""
    if not isinstance(obj, dict):
        return obj
    unknown = sorted(set(obj) - SINGLE_KEYS)
    if unknown:
        raise PayloadError(f"unknown key {unknown[0]!r}")
    if "value" not in obj:
        raise PayloadError("object without a 'value' key")
    if "type" in obj and obj["type"] != type_:
        raise PayloadError(f"type {obj['type']!r} does not match the "
                           f"pin's type {type_!r}")
    return obj["value"]


def convert(value: Any, type_: str) -> Value:
    """Check a decoded JSON value against a HAL type and return it."""
    if type_ == "bit":
        if isinstance(value, bool):
            return value
        if isinstance(value, int) and value in (0, 1):
            return bool(value)
        raise PayloadError(f"{_show(value)} is not a bit "
                           "(true, false, 0 or 1)")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise PayloadError(f"{_show(value)} is not a number")
    if type_ == "float":
        value = float(value)
        if not math.isfinite(value):
            raise PayloadError(f"{value} is out of range for float")
        return value
    if isinstance(value, float):
        if not value.is_integer():
            raise PayloadError(f"{value} is not an integer ({type_})")
        value = int(value)
    low, high = INT_RANGES[type_]
    if not low <= value <= high:
        raise PayloadError(f"{value} is out of range for {type_} "
                           f"({low}..{high})")
    return value


def _show(value: Any) -> str:
    if isinstance(value, (list, dict)):      # may be nested deeply
        return "an array" if isinstance(value, list) else "an object"
    text = json.dumps(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
