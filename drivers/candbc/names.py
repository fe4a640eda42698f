"""Conversion of DBC names (CamelCase, underscores) to HAL pin names."""

from __future__ import annotations

import re
from collections.abc import Iterable

_LOWER_UPPER = re.compile(r"([a-z0-9])([A-Z])")
_ACRONYM_WORD = re.compile(r"([A-Z]+)([A-Z][a-z])")
_SEPARATORS = re.compile(r"[^a-z0-9]+")


def hal_name(name: str) -> str:
    """``EngineSpeed`` → ``engine-speed``, ``ABS_Status2`` →
    ``abs-status2``, ``VCU_RPMLimit`` → ``vcu-rpm-limit``."""
    text = _ACRONYM_WORD.sub(r"\1-\2", name)
    text = _LOWER_UPPER.sub(r"\1-\2", text)
    return _SEPARATORS.sub("-", text.lower()).strip("-")


class NameClash(ValueError):
    """Two DBC names convert to the same HAL name."""


def unique_names(names: Iterable[str], what: str,
                 reserved: Iterable[str] = ()) -> dict[str, str]:
    """Map each DBC name to its HAL name; raise :class:`NameClash` naming
    both DBC names when two give the same HAL name (or one gives a
    ``reserved`` name, or an empty one).  ``what`` is "message" or
    "signal"."""
    reserved = set(reserved)
    seen: dict[str, str] = {}
    result: dict[str, str] = {}
    for name in names:
        converted = hal_name(name)
        if not converted:
            raise NameClash(f"{what} {name!r} gives an empty HAL name")
        if converted in reserved:
            raise NameClash(f"{what} {name!r} gives the HAL name "
                            f"{converted!r}, which the driver uses itself")
        if converted in seen:
            raise NameClash(f"{what}s {seen[converted]!r} and {name!r} both "
                            f"give the HAL name {converted!r}")
        seen[converted] = name
        result[name] = converted
    return result
