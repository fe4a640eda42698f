"""Wire format of the XHC WHB04B pendant: input reports and display data.

Input report (8 bytes, interrupt IN endpoint)::

    0  header      0x04
    1  random      changes from report to report, ignored
    2  key 1       code of a pressed button, 0 = none
    3  key 2       code of a second pressed button, 0 = none
    4  feed        step/feed selector position code
    5  axis        axis selector position code
    6  wheel       signed wheel delta since the last report (int8)
    7  checksum    not verified (the algorithm is not published)

Display data (21 bytes, sent as three 8-byte HID feature reports with
report id 0x06 followed by 7 data bytes)::

    0-1    magic 0xfe 0xfd
    2      seed 0xfe
    3      flags: bits 0-1 jog mode (0 continuous, 1 step, 2 lead),
           bit 6 reset indicator, bit 7 work coordinates (X1, Y1, ...)
    4-7    row 1 position, 8-11 row 2, 12-15 row 3: each u16 LE integer
           part, then u16 LE fraction in 1/10000 with bit 15 = negative
    16-17  feed value (u16 LE)
    18-19  spindle value (u16 LE)
    20     0
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Optional

VENDOR_ID = 0x10CE
PRODUCT_ID = 0xEB93          # WHB04B-6; the 4-axis model uses the same protocol
REPORT_LENGTH = 8
HEADER = 0x04

#: button key codes -> (pin name alone, pin name together with Fn)
BUTTONS: dict[int, tuple[str, Optional[str]]] = {
    0x01: ("reset", "macro-11"),
    0x02: ("stop", "macro-12"),
    0x03: ("start-pause", "macro-13"),
    0x04: ("feed-plus", "macro-1"),
    0x05: ("feed-minus", "macro-2"),
    0x06: ("spindle-plus", "macro-3"),
    0x07: ("spindle-minus", "macro-4"),
    0x08: ("m-home", "macro-5"),
    0x09: ("safe-z", "macro-6"),
    0x0A: ("w-home", "macro-7"),
    0x0B: ("s-on-off", "macro-8"),
    0x0C: ("fn", None),
    0x0D: ("probe-z", "macro-9"),
    0x0E: ("mode-continuous", "macro-15"),
    0x0F: ("mode-step", "macro-16"),
    0x10: ("macro-10", "macro-14"),
}
FN_CODE = 0x0C

#: every button pin name, in a stable order
BUTTON_NAMES: tuple[str, ...] = tuple(
    [plain for plain, _ in BUTTONS.values()]
    + sorted({fn for _, fn in BUTTONS.values() if fn},
             key=lambda n: int(n.split("-")[1])))

#: axis selector codes -> axis name ("off" when no axis is selected)
AXES: dict[int, str] = {0x00: "off", 0x06: "off", 0x11: "x", 0x12: "y",
                        0x13: "z", 0x14: "a", 0x15: "b", 0x16: "c"}
AXIS_NAMES = ("x", "y", "z", "a", "b", "c")

#: feed selector codes -> position 1..7 (7 = Lead); 0x00 = unknown (0)
FEED_POSITIONS: dict[int, int] = {0x00: 0, 0x0D: 1, 0x0E: 2, 0x0F: 3,
                                  0x10: 4, 0x1A: 5, 0x1B: 6, 0x1C: 7}
LEAD_POSITION = 7
#: default step size (user units) and jog percentage of positions 1..6
STEP_SIZES = (0.001, 0.01, 0.1, 1.0, 5.0, 10.0)
PERCENTS = (2.0, 5.0, 10.0, 30.0, 60.0, 100.0)

# display
DISPLAY_MAGIC = b"\xfe\xfd"
DISPLAY_SEED = 0xFE
DISPLAY_LENGTH = 21
DISPLAY_REPORT_ID = 0x06
CHUNK_DATA = 7
MODE_CONTINUOUS, MODE_STEP, MODE_LEAD = 0, 1, 2
FLAG_RESET = 0x40
FLAG_WORK_COORDS = 0x80
# HID class SET_REPORT (feature report 6) on interface 0
SET_REPORT_REQUEST_TYPE = 0x21
SET_REPORT = 0x09
SET_REPORT_VALUE = 0x0300 | DISPLAY_REPORT_ID


class ReportError(ValueError):
    """An input report that does not follow the format."""


@dataclass(frozen=True)
class Report:
    """One decoded input report."""

    key1: int
    key2: int
    feed_position: int
    axis: str
    wheel: int

    @property
    def buttons(self) -> frozenset[str]:
        """Names of the button pins that are true for this report."""
        codes = {c for c in (self.key1, self.key2) if c}
        names = set()
        fn = FN_CODE in codes
        for code in codes:
            plain, with_fn = BUTTONS[code]
            names.add(with_fn if fn and with_fn else plain)
        return frozenset(names)


def parse_report(data: Sequence[int]) -> Report:
    """Decode an 8-byte input report; :class:`ReportError` if malformed."""
    raw = bytes(data)
    if len(raw) != REPORT_LENGTH:
        raise ReportError(f"report of {len(raw)} bytes, expected "
                          f"{REPORT_LENGTH}")
    if raw[0] != HEADER:
        raise ReportError(f"bad header 0x{raw[0]:02x}, expected "
                          f"0x{HEADER:02x}")
    for code in raw[2:4]:
        if code and code not in BUTTONS:
            raise ReportError(f"unknown button code 0x{code:02x}")
    if raw[4] not in FEED_POSITIONS:
        raise ReportError(f"unknown feed selector code 0x{raw[4]:02x}")
    if raw[5] not in AXES:
        raise ReportError(f"unknown axis selector code 0x{raw[5]:02x}")
    wheel = raw[6] - 256 if raw[6] >= 128 else raw[6]
    return Report(raw[2], raw[3], FEED_POSITIONS[raw[4]], AXES[raw[5]],
                  wheel)


def encode_position(value: float) -> bytes:
    """A display position: u16 integer part, u16 fraction with sign bit."""
    units = round(abs(value) * 10000)
    whole, frac = divmod(units, 10000)
    if whole > 0xFFFF:
        whole, frac = 0xFFFF, 9999
    if value < 0 and units:
        frac |= 0x8000
    return struct.pack("<HH", whole, frac)


def _u16(value: float) -> int:
    return min(max(round(value), 0), 0xFFFF)


def encode_display(rows: Sequence[float], feed: float, spindle: float,
                   mode: int = MODE_CONTINUOUS, reset: bool = False,
                   work_coords: bool = False) -> bytes:
    """The 21 display bytes for three positions and two values."""
    if len(rows) != 3:
        raise ValueError("the display shows exactly three positions")
    flags = (mode & 0x03) | (FLAG_RESET if reset else 0) \
        | (FLAG_WORK_COORDS if work_coords else 0)
    body = DISPLAY_MAGIC + bytes([DISPLAY_SEED, flags])
    body += b"".join(encode_position(v) for v in rows)
    body += struct.pack("<HH", _u16(feed), _u16(spindle)) + b"\x00"
    assert len(body) == DISPLAY_LENGTH
    return body


def display_chunks(body: bytes) -> list[bytes]:
    """Split display bytes into 8-byte feature reports (id 0x06)."""
    return [bytes([DISPLAY_REPORT_ID]) + body[i:i + CHUNK_DATA]
            .ljust(CHUNK_DATA, b"\x00")
            for i in range(0, len(body), CHUNK_DATA)]
