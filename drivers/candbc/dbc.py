"""Loading a DBC file with readable errors, and the mapping of one DBC
signal to one HAL pin (type rule, raw <-> pin value, limits)."""

from __future__ import annotations

import math
import os
import re
from typing import Any, Optional, Union

import cantools
from cantools.database.can import Database, Message, Signal

PinValue = Union[bool, int, float]

_MESSAGE_LINE = re.compile(r"^\s*BO_\s+\d+\s+(\w+)\s*:")
_MESSAGE_SIZE = re.compile(r"^\s*BO_\s+\d+\s+(\w+)\s*:\s*(\d+)")
_SIGNAL_BITS = re.compile(r"^\s*SG_\s+(\w+)[^:]*:\s*(\d+)\|(\d+)@")
#: the largest CAN frame (CAN FD), in bytes
MAX_FRAME_BYTES = 64


class ConfigError(Exception):
    """A bad command line or DBC file; the message names file:line."""


def line_of_message(path: str, error: str) -> Optional[int]:
    """The line of the ``BO_`` definition of the first message named in
    ``error`` (semantic errors from cantools name a message, not a line)."""
    try:
        with open(path, encoding="cp1252", errors="replace") as f:
            lines = f.read().splitlines()
    except OSError:
        return None
    best: Optional[tuple[int, int]] = None
    for number, line in enumerate(lines, 1):
        match = _MESSAGE_LINE.match(line)
        if not match:
            continue
        found = re.search(rf"\b{re.escape(match.group(1))}\b", error)
        if found and (best is None or found.start() < best[0]):
            best = (found.start(), number)
    return best[1] if best else None


#: appended to the text so that a statement cut off at the end of the
#: file fails to parse (cantools accepts one that reaches the end)
_SENTINEL = "\nBS_:\n"
_EMPTY_LINE = re.compile(r"^\s*(//.*)?$")


def load_dbc(path: str, shown: Optional[str] = None) -> Database:
    """Load ``path`` as a DBC file; any problem raises :class:`ConfigError`
    with ``shown:line:`` (``shown`` is the name the user gave, default
    ``path``; line 1 when no better position is known)."""
    shown = path if shown is None else shown
    try:
        with open(path, encoding="cp1252") as f:
            text = f.read()
    except OSError as exc:
        raise ConfigError(f"{shown}: cannot read: {exc.strerror or exc}"
                          ) from None
    lines = text.splitlines()
    if all(_EMPTY_LINE.match(line) for line in lines):
        raise ConfigError(f"{shown}: empty DBC file")
    _check_sizes(lines, shown)
    try:
        db = cantools.database.load_string(text + _SENTINEL,
                                           database_format="dbc")
    except Exception as exc:     # cantools raises several kinds
        raise ConfigError(_error_text(exc, path, shown, lines)) from None
    if not isinstance(db, Database):     # (typed: or a diagnostics one)
        raise ConfigError(f"{shown}: not a CAN database")
    return db


def _check_sizes(lines: list[str], shown: str) -> None:
    """Frame sizes and signal bits no CAN frame can hold, refused before
    cantools lays them out (a size of 2**31 bytes would take it for
    ever)."""
    bits = 8 * MAX_FRAME_BYTES
    for number, line in enumerate(lines, 1):
        match = _MESSAGE_SIZE.match(line)
        if match and int(match.group(2)) > MAX_FRAME_BYTES:
            raise ConfigError(
                f"{shown}:{number}: message {match.group(1)}: "
                f"{match.group(2)} bytes; a CAN frame has at most "
                f"{MAX_FRAME_BYTES}")
        match = _SIGNAL_BITS.match(line)
        if match and (int(match.group(2)) >= bits or
                      int(match.group(3)) > bits):
            raise ConfigError(
                f"{shown}:{number}: signal {match.group(1)}: bit "
                f"{match.group(2)}, {match.group(3)} bits; a CAN frame "
                f"has {bits} bits")


def _error_text(exc: Exception, path: str, shown: str,
                lines: list[str]) -> str:
    """``shown:line[:column]: text`` for a cantools load error."""
    inner = getattr(exc, "e_dbc", None) or exc
    line = getattr(inner, "line", None)
    if line is not None:
        if line > len(lines):        # the parse ran into the sentinel
            last = max(n for n, text in enumerate(lines, 1)
                       if not _EMPTY_LINE.match(text))
            return (f"{shown}:{last}: incomplete statement at the end of "
                    "the file (truncated?)")
        column = getattr(inner, "column", None)
        where = f"{line}:{column}" if column else f"{line}"
        text = str(inner)
        text = re.sub(r"^Invalid syntax at line \d+, column \d+: ",
                      "invalid syntax: ", text)
        return f"{shown}:{where}: {text}"
    text = str(inner).strip('"')
    if text.startswith("DBC: "):
        text = text[5:].strip('"')
    line = line_of_message(path, text) or 1
    return f"{shown}:{line}: {text}"


def find_package_dbc(name: str) -> Optional[str]:
    """A DBC file shipped with this package (``demo.dbc``), or None."""
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, name)
    return path if name.endswith(".dbc") and os.path.isfile(path) else None


def pin_type(signal: Signal) -> str:
    """The HAL type of the pin of ``signal``.

    IEEE float signals and scaled signals (scale != 1 or offset != 0,
    unless they have value names) are ``float``; 1-bit unsigned signals
    are ``bit``; other integer signals are ``s32``/``u32`` by signedness,
    ``s64``/``u64`` when longer than 32 bits.  Signals with value names
    (choices) carry their raw value.
    """
    if signal.is_float:
        return "float"
    if not signal.choices and (signal.scale != 1 or signal.offset != 0):
        return "float"
    if signal.length == 1 and not signal.is_signed:
        return "bit"
    width = "32" if signal.length <= 32 else "64"
    return ("s" if signal.is_signed else "u") + width


class SignalPin:
    """One DBC signal and its HAL pin (``pin`` is relative to the prefix:
    ``<message>.<signal>``)."""

    def __init__(self, message: Message, signal: Signal, pin: str):
        self.message = message
        self.signal = signal
        self.pin = pin
        self.type = pin_type(signal)
        self.scaled = self.type == "float"
        if signal.is_float:
            self.raw_min, self.raw_max = -math.inf, math.inf
        elif signal.is_signed:
            self.raw_min = -(1 << (signal.length - 1))
            self.raw_max = (1 << (signal.length - 1)) - 1
        else:
            self.raw_min, self.raw_max = 0, (1 << signal.length) - 1
        # limits in pin units: the DBC range where it says something
        low, high = signal.minimum, signal.maximum
        if low is None or high is None or low >= high or signal.choices:
            low, high = None, None
        self.low: Optional[float] = low
        self.high: Optional[float] = high

    def from_raw(self, raw: Any) -> PinValue:
        """The pin value of a raw (unscaled) signal value."""
        if self.type == "bit":
            return bool(raw)
        if self.scaled:
            return float(raw) * self.signal.scale + self.signal.offset
        return int(raw)

    def to_raw(self, value: PinValue) -> Union[int, float]:
        """The raw value to send for a pin value, limited to the DBC range
        (when given) and to what the signal's bits can hold."""
        number = float(value)
        if math.isnan(number):
            number = 0.0
        if self.low is not None and self.high is not None:
            number = min(max(number, self.low), self.high)
        if self.scaled:
            number = (number - self.signal.offset) / self.signal.scale
        if self.signal.is_float:
            return number
        if math.isinf(number):
            return self.raw_max if number > 0 else self.raw_min
        raw = int(round(number))
        return min(max(raw, self.raw_min), self.raw_max)
