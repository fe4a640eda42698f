"""The model of a ``.comp`` file: what the parser produces and the
generators read.

Every item keeps the place of its declaration (:class:`Loc`) so that
semantic errors and ``#line`` directives can point back into the file.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Optional, Union

#: HAL types of pins and params; ``signed``/``unsigned`` are the
#: reference's other spellings of s32/u32.
HAL_TYPES = ("bit", "float", "s32", "u32", "s64", "u64")
TYPE_ALIASES = {"signed": "s32", "unsigned": "u32"}
PIN_DIRS = ("in", "out", "io")
PARAM_DIRS = ("r", "rw")

#: every option the compiler knows, with the kind of value it takes
OPTIONS = {
    "singleton": "bool", "default_count": "int", "count_function": "bool",
    "rtapi_app": "bool", "data": "name", "extra_setup": "bool",
    "extra_cleanup": "bool", "userspace": "bool", "userinit": "bool",
    "extra_compile_args": "str", "extra_link_args": "str",
    "homemod": "bool", "tpmod": "bool", "constructable": "bool",
    "fp": "bool", "period": "bool", "no_convenience_defines": "bool",
    "default_personality": "int", "cython": "bool",
    # accepted for older files; as in the reference it changes nothing
    # (a comp has a personality when a pin or param has a condition)
    "personality": "bool",
}

#: names the generated code uses for itself
RESERVED = ("comp_id", "fperiod", "rtapi_app_main", "rtapi_app_exit",
            "extra_setup", "extra_cleanup")

OptionValue = Union[bool, int, str]


@dataclass(frozen=True)
class Loc:
    """A place in a source file (line and column count from 1)."""

    file: str
    line: int
    col: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"


@dataclass
class Array:
    """``[size]`` or ``[maxsize : condsize]`` (condsize: C text)."""

    size: int
    condsize: Optional[str] = None
    condsize_loc: Optional[Loc] = None


class _Named:
    """The C and HAL names of an item declared with a .comp name."""

    name: str

    @property
    def c_name(self) -> str:
        return c_identifier(self.name)

    @property
    def hal_name(self) -> str:
        return hal_identifier(self.name)


@dataclass
class Pin(_Named):
    """A pin (``kind == "pin"``) or a parameter (``kind == "param"``)."""

    kind: str
    direction: str
    type: str
    name: str
    loc: Loc
    array: Optional[Array] = None
    condition: Optional[str] = None
    default: Optional[str] = None
    doc: Optional[str] = None
    condition_loc: Optional[Loc] = None
    default_loc: Optional[Loc] = None


@dataclass
class Function(_Named):
    name: str
    loc: Loc
    fp: bool = True
    doc: Optional[str] = None


@dataclass
class Variable:
    ctype: str
    name: str           # C identifier, without the stars
    stars: str
    loc: Loc
    size: Optional[int] = None
    default: Optional[str] = None
    default_loc: Optional[Loc] = None


@dataclass
class ModParam:
    type: str           # int, long, string or dummy
    name: str
    loc: Loc
    default: Optional[str] = None
    doc: Optional[str] = None


@dataclass
class Component:
    """Everything a ``.comp`` file declares, and its code section."""

    name: str
    loc: Loc
    file: str
    doc: Optional[str] = None
    pins: list[Pin] = field(default_factory=list)
    params: list[Pin] = field(default_factory=list)
    functions: list[Function] = field(default_factory=list)
    variables: list[Variable] = field(default_factory=list)
    modparams: list[ModParam] = field(default_factory=list)
    options: dict[str, OptionValue] = field(default_factory=dict)
    option_locs: dict[str, Loc] = field(default_factory=dict)
    includes: list[str] = field(default_factory=list)
    include_locs: list[Loc] = field(default_factory=list)
    license: Optional[str] = None
    authors: list[str] = field(default_factory=list)
    description: Optional[str] = None
    notes: Optional[str] = None
    see_also: Optional[str] = None
    examples: Optional[str] = None
    code: str = ""
    code_line: int = 0      # line of the .comp where the code starts

    def option(self, name: str, default: OptionValue = False) -> OptionValue:
        return self.options.get(name, default)

    @property
    def prefix(self) -> str:
        """The start of the HAL names of pins, params and functions: the
        component name without a leading ``hal_``, as a HAL name (``_``
        becomes ``-``: ``conv_bit_float`` makes ``conv-bit-float.0``)."""
        name = self.name[4:] if self.name.startswith("hal_") else self.name
        return hal_identifier(name)

    @property
    def has_personality(self) -> bool:
        return any(p.condition or (p.array and p.array.condsize)
                   for p in self.pins + self.params)


def c_identifier(halname: str) -> str:
    """The C name of a HALNAME: ``#`` runs go (with a ``.``, ``_`` or
    ``-`` just before them), ``.`` and ``-`` become ``_``, ``_`` runs
    shrink to one."""
    name = re.sub(r"[._-]?#+", "", halname)
    name = re.sub(r"[.-]", "_", name)
    return re.sub(r"_+", "_", name)


def hal_identifier(halname: str) -> str:
    """The HAL name of a HALNAME: ``_`` becomes ``-`` and a trailing
    ``-`` or ``.`` is dropped (``_`` alone gives the empty name)."""
    name = halname.replace("_", "-")
    return name.rstrip("-.")


def hal_format(halname: str) -> str:
    """The printf format of an item's HAL name: each ``#`` run becomes a
    zero-padded index as wide as the run."""
    name = hal_identifier(halname).replace("%", "%%")
    return re.sub(r"#+", lambda m: f"%0{len(m.group(0))}d", name)
