"""Numbered and named G-code parameters, their scopes and the var file."""

from __future__ import annotations

from typing import Callable, Optional, Union

from halsdk.atomicfile import write_atomic

from .errors import GCodeError

#: The highest parameter number.
MAX_PARAMETER = 5602

#: Numbered parameters written to the var file even when they were absent.
PERSISTENT: tuple[int, ...] = tuple(
    list(range(5161, 5170)) + list(range(5181, 5190)) + [5220]
    + [n for base in range(5221, 5382, 20) for n in range(base, base + 10)]
)

#: The current position in program coordinates (X .. W), read-only
#: values the interpreter answers through :meth:`Parameters.set_predefined`.
POSITION = range(5420, 5429)

#: The tool in the spindle (#5400 number, #5401.. offsets, diameter,
#: angles, orientation): set by the interpreter, read-only for programs.
READ_ONLY = range(5400, 5414)

#: Numbered parameters local to a subroutine call (its arguments).
LOCAL_NUMBERED = range(1, 31)

Key = Union[int, str]


_NORMALIZED: dict[str, str] = {}


def normalize_name(name: str) -> str:
    """Lower-case a parameter name and drop its spaces and tabs."""
    normal = _NORMALIZED.get(name)
    if normal is None:
        normal = "".join(name.split()).lower()
        if len(_NORMALIZED) < 4096:     # the names of a few programs
            _NORMALIZED[name] = normal
    return normal


class _Frame:
    """The local parameters of one subroutine call (or the top level)."""

    __slots__ = ("numbered", "named")

    def __init__(self, numbered: Optional[dict[int, float]] = None) -> None:
        self.numbered: dict[int, float] = numbered if numbered is not None \
            else {}
        self.named: dict[str, float] = {}


class Parameters:
    """Numbered (``#1`` .. ``#5602``) and named (``#<name>``, ``#<_global>``)
    parameters.

    ``#1``..``#30`` and names without a leading underscore belong to the
    current scope; every subroutine call opens a new scope
    (:meth:`push_scope`) and returning closes it (:meth:`pop_scope`).
    Names starting with ``_`` are global.  Read-only predefined names
    (``#<_x>``, ``#<_metric>`` ...) come from a callback given to
    :meth:`set_predefined`.  Reading an unknown named parameter is an
    error; an unset numbered one reads 0.

    Errors raised here carry no location; the program front end re-raises
    them with file, line and column.
    """

    def __init__(self) -> None:
        self._numbered: dict[int, float] = {}
        self._globals: dict[str, float] = {}
        self._frames: list[_Frame] = [_Frame()]
        #: the current scope, ``_frames[-1]`` (read by the compiled
        #: evaluator, halsdk/gcode/_eval.pyx)
        self._top = self._frames[0]
        self._predefined: Optional[Callable[[str], Optional[float]]] = None
        self._saved: set[int] = set()

    # -- scopes ----------------------------------------------------------
    @property
    def depth(self) -> int:
        """The number of open subroutine calls (0 at the top level)."""
        return len(self._frames) - 1

    def push_scope(self, args: Optional[list[float]] = None) -> None:
        """Enter a subroutine: new locals, ``#1``.. set to ``args``."""
        if args is not None and len(args) > len(LOCAL_NUMBERED):
            raise GCodeError(f"at most {len(LOCAL_NUMBERED)} subroutine "
                             f"arguments, got {len(args)}")
        frame = _Frame({index: float(value) for index, value
                        in enumerate(args, start=1)} if args else None)
        self._frames.append(frame)
        self._top = frame

    def pop_scope(self) -> None:
        """Leave a subroutine: its locals vanish."""
        if len(self._frames) > 1:
            self._frames.pop()
            self._top = self._frames[-1]

    def reset_scopes(self) -> None:
        """Drop every open subroutine scope (after an error or abort)."""
        del self._frames[1:]
        self._top = self._frames[0]

    # -- predefined ------------------------------------------------------
    def set_predefined(self, fn: Optional[Callable[[str], Optional[float]]]
                       ) -> None:
        """Install the callback answering read-only names such as ``_x``.

        ``fn(name)`` gets the normalized name without ``<>`` (or the
        number, as a string, of a position parameter #5420..#5428) and
        returns its value, or None when it does not know it.
        """
        self._predefined = fn

    def _predefined_value(self, name: str) -> Optional[float]:
        if self._predefined is None or not name.startswith("_"):
            return None
        value = self._predefined(name)
        return None if value is None else float(value)

    # -- access ----------------------------------------------------------
    def _number(self, key: float) -> int:
        number = int(round(key))
        if abs(number - key) > 1e-4:
            raise GCodeError("Non integer value for integer")
        if not 1 <= number <= MAX_PARAMETER:
            raise GCodeError("Parameter number out of range")
        return number

    def get(self, key: Key) -> float:
        """The value of parameter ``key`` (a number or a name)."""
        if key.__class__ is int and (
                LOCAL_NUMBERED[-1] < key < POSITION[0]
                or POSITION[-1] < key <= MAX_PARAMETER):
            # neither local nor position nor out of range: stored
            return self._numbered.get(key, 0.0)
        if isinstance(key, str):
            name = normalize_name(key)
            value = self._predefined_value(name)
            if value is not None:
                return value
            table = self._globals if name.startswith("_") \
                else self._frames[-1].named
            if name not in table:
                raise GCodeError(f"Named parameter #<{name}> not defined")
            return table[name]
        number = self._number(key)
        if number in LOCAL_NUMBERED and self.depth:
            return self._frames[-1].numbered.get(number, 0.0)
        if number in POSITION and self._predefined is not None:
            # the current position: answered by the interpreter
            value = self._predefined(str(number))
            if value is not None:
                return float(value)
        return self._numbered.get(number, 0.0)

    def numbered(self, first: int, count: int) -> list[float]:
        """``#first`` .. ``#first+count-1`` (unset ones read 0), numbers
        above the subroutine locals: what ``get`` reads for them, faster
        (the interpreter reads offsets nine at a time)."""
        last = first + count - 1
        if (first <= LOCAL_NUMBERED[-1] or last > MAX_PARAMETER
                or (first <= POSITION[-1] and last >= POSITION[0])):
            return [self.get(n) for n in range(first, first + count)]
        get = self._numbered.get
        return [get(n, 0.0) for n in range(first, first + count)]

    def set(self, key: Key, value: float, *, internal: bool = False) -> None:
        """Store ``value`` in parameter ``key`` (in the current scope).

        The tool parameters #5400..#5413 and the position #5420..#5428
        are read-only for programs, as in the reference; the interpreter
        sets the tool ones with ``internal=True``."""
        value = float(value)
        if isinstance(key, str):
            name = normalize_name(key)
            if not name:
                raise GCodeError("empty parameter name")
            if self._predefined_value(name) is not None:
                raise GCodeError("Cannot assign to read-only parameter "
                                 f"#<{name}>")
            if name.startswith("_"):
                self._globals[name] = value
            else:
                self._frames[-1].named[name] = value
            return
        number = self._number(key)
        if not internal and (number in READ_ONLY or number in POSITION):
            raise GCodeError("Parameter is readonly")
        if number in LOCAL_NUMBERED and self.depth:
            self._frames[-1].numbered[number] = value
        else:
            self._numbered[number] = value

    def set_returned(self, value: Optional[float]) -> None:
        """What a subroutine call (None) or return sets: ``#<_value>``
        (when it returns a value) and ``#<_value_returned>``, globals of
        the program's own, stored without the checks of :meth:`set`."""
        if value is not None:
            self._globals["_value"] = float(value)
        self._globals["_value_returned"] = 0.0 if value is None else 1.0

    def exists(self, name: str) -> bool:
        """True if the named parameter ``name`` can be read now."""
        name = normalize_name(name)
        if self._predefined_value(name) is not None:
            return True
        table = self._globals if name.startswith("_") \
            else self._frames[-1].named
        return name in table

    def __getitem__(self, key: Key) -> float:
        return self.get(key)

    def __setitem__(self, key: Key, value: float) -> None:
        self.set(key, value)

    # -- var file --------------------------------------------------------
    def load(self, path: str) -> None:
        """Read a var file: one ``number value`` pair a line, numbers
        ascending; lines that are not two numbers are skipped."""
        try:
            with open(path, encoding="utf-8") as stream:
                lines = stream.read().splitlines()
        except OSError as exc:
            raise GCodeError(f"cannot read parameter file: {exc.strerror}",
                             path) from None
        previous = 0
        loaded: dict[int, float] = {}
        for lineno, text in enumerate(lines, start=1):
            fields = text.split()
            if len(fields) != 2:
                continue
            try:
                number_f = float(fields[0])
                value = float(fields[1])
            except ValueError:
                continue
            number = int(number_f)
            if number != number_f or not 1 <= number <= MAX_PARAMETER:
                raise GCodeError(f"bad parameter number {fields[0]}",
                                 path, lineno, 1)
            if number <= previous:
                raise GCodeError("parameter file out of order", path,
                                 lineno, 1)
            previous = number
            loaded[number] = value
        self._numbered.update(loaded)
        self._saved = set(loaded)

    def save(self, path: str) -> None:
        """Write the persistent parameters (and any loaded from the var
        file) atomically: a temporary file renamed over ``path``; the old
        file is kept as ``path.bak``."""
        numbers = sorted(set(PERSISTENT) | self._saved)
        text = "".join(f"{n}\t{self._numbered.get(n, 0.0):.6f}\n"
                       for n in numbers)
        write_atomic(path, text, backup=True)
