"""Reading the mb2hal INI file into links and transactions.

Files that LinuxCNC's mb2hal runs are accepted: what it reads differently
from what the file seems to say (an unknown or repeated key, a value that
is not a number, a count a single write cannot send ...) gives a warning
in :attr:`Config.warnings`; ``strict=True`` turns the warnings into a
:class:`ConfigError`. What the reference refuses too is an error. Every
message names ``file:line``, the section and the key.
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass, field
from typing import Optional

from halsdk.ini import IniFile

INIT = "MB2HAL_INIT"

#: MB_TX_CODE name -> Modbus function code
FUNCTIONS = {
    "fnct_01_read_coils": 1,
    "fnct_02_read_discrete_inputs": 2,
    "fnct_03_read_holding_registers": 3,
    "fnct_04_read_input_registers": 4,
    "fnct_05_write_single_coil": 5,
    "fnct_06_write_single_register": 6,
    "fnct_15_write_multiple_coils": 15,
    "fnct_16_write_multiple_registers": 16,
}
#: most elements one request of each function may carry (Modbus limits)
MAX_ELEMENTS = {1: 2000, 2: 2000, 3: 125, 4: 125, 5: 1, 6: 1, 15: 1968,
                16: 123}
VERSION_1_0 = 1000
VERSION_1_1 = 1001
PARITIES = {"none": "N", "even": "E", "odd": "O"}
MAX_TX_NAME = 28
#: longest SLOWDOWN, s; longest request timeout, ms; longest serial pause, ms
MAX_SLOWDOWN = 60.0
MAX_TIMEOUT_MS = 60_000
MAX_DELAY_MS = 3_600_000
DEFAULT_TIMEOUT_MS = 500
#: slowest MAX_UPDATE_RATE other than 0 that is not suspicious (once an
#: hour) and the fastest, Hz
MIN_RATE = 1.0 / 3600.0
MAX_RATE = 1_000_000.0
#: device ids the reference can address (255 only on TCP)
MAX_SLAVE_ID = 247
TCP_SLAVE_ID = 255

INIT_KEYS = ("INIT_DEBUG", "VERSION", "HAL_MODULE_NAME", "SLOWDOWN",
             "TOTAL_TRANSACTIONS")
TRANSACTION_KEYS = (
    "LINK_TYPE", "TCP_IP", "TCP_PORT", "SERIAL_PORT", "SERIAL_BAUD",
    "SERIAL_BITS", "SERIAL_PARITY", "SERIAL_STOP", "SERIAL_DELAY_MS",
    "MB_SLAVE_ID", "FIRST_ELEMENT", "NELEMENTS", "PIN_NAMES", "MB_TX_CODE",
    "MB_RESPONSE_TIMEOUT_MS", "MB_BYTE_TIMEOUT_MS", "HAL_TX_NAME",
    "MAX_UPDATE_RATE", "DEBUG")
TRANSACTION_SECTION = re.compile(r"TRANSACTION_\d+")
INTEGER = re.compile(r"[+-]?\d+")
NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


class ConfigError(Exception):
    """A bad INI file; the message names file:line and key (one line per
    problem when ``--strict`` refuses several warnings). ``warnings``
    are those found before the error."""

    def __init__(self, text: str, warnings: Optional[list[str]] = None):
        super().__init__(text)
        self.warnings = list(warnings or [])


@dataclass(frozen=True)
class Link:
    """One connection, shared by the transactions that name it."""

    kind: str                      # "tcp" or "serial"
    ip: str = ""
    port: int = 502
    device: str = ""
    baud: int = 0
    bits: int = 8
    parity: str = "none"
    stop: int = 1

    @property
    def key(self) -> tuple:
        if self.kind == "tcp":
            return ("tcp", self.ip, self.port)
        return ("serial", self.device)

    def describe(self) -> str:
        if self.kind == "tcp":
            return f"tcp {self.ip}:{self.port}"
        return (f"serial {self.device} {self.baud} {self.bits}"
                f"{PARITIES[self.parity]}{self.stop}")


@dataclass
class Transaction:
    """One [TRANSACTION_NN] section."""

    number: int
    link: Link
    slave_id: int
    first_element: int
    function: int
    pin_names: list[str]
    name: str
    response_timeout_ms: int = DEFAULT_TIMEOUT_MS
    byte_timeout_ms: int = DEFAULT_TIMEOUT_MS
    max_update_rate: float = 0.0
    serial_delay_ms: int = 0
    debug: int = 1
    line: str = ""                 # file:line of the section header
    #: why no request can be sent (as in the reference, every repetition
    #: then counts one error and nothing is sent); "" when it can
    unusable: str = ""

    @property
    def count(self) -> int:
        return len(self.pin_names)

    @property
    def is_write(self) -> bool:
        return self.function in (5, 6, 15, 16)

    @property
    def is_bits(self) -> bool:
        return self.function in (1, 2, 5, 15)


@dataclass
class Config:
    """The whole file: init values and the transactions in order."""

    path: str
    module_name: str = "mb2hal"
    init_debug: int = 1
    version: int = VERSION_1_0
    slowdown: float = 0.0
    transactions: list[Transaction] = field(default_factory=list)
    #: ``file:line: [SECTION]KEY: text`` of each suspicious entry
    warnings: list[str] = field(default_factory=list)

    @property
    def links(self) -> list[Link]:
        seen: dict[tuple, Link] = {}
        for tx in self.transactions:
            seen.setdefault(tx.link.key, tx.link)
        return list(seen.values())


def _ours(section: str) -> bool:
    return section == INIT or bool(TRANSACTION_SECTION.fullmatch(section))


class _Reader:
    """Look-ups as the reference makes them (only the first copy of a
    repeated section is read, the first value of a repeated key wins),
    with file:line errors and warnings."""

    def __init__(self, ini: IniFile):
        self.ini = ini
        self.notes: list[tuple[int, str]] = []
        # the line range of the first copy of each section
        ends: dict[str, tuple[int, int]] = {}
        headers = ini.headers
        for i, (name, number) in enumerate(headers):
            if name not in ends:
                end = headers[i + 1][1] if i + 1 < len(headers) else 1 << 30
                ends[name] = (number, end)
        self.blocks = ends

    def _entry(self, section: str, key: str) -> Optional[tuple[str, int]]:
        start, end = self.blocks.get(section, (0, 0))
        for value, number in self.ini.every.get((section, key), []):
            if start < number < end:
                return value, number
        return None

    def line(self, section: str, key: Optional[str] = None) -> int:
        if key is not None:
            found = self._entry(section, key)
            if found:
                return found[1]
        return self.ini.line(section)

    def label(self, section: str, key: Optional[str]) -> str:
        number = self.line(section, key)
        where = f"{self.ini.path}:{number}" if number else self.ini.path
        return f"{where}: [{section}]{key or ''}"

    def fail(self, section: str, key: Optional[str], text: str) -> ConfigError:
        return ConfigError(f"{self.label(section, key)}: {text}")

    def warn(self, section: str, key: Optional[str], text: str) -> None:
        self.notes.append((self.line(section, key),
                           f"{self.label(section, key)}: {text}"))

    def raw(self, section: str, key: str) -> Optional[str]:
        """The value; an empty value counts as absent (as in the
        reference), with a warning."""
        found = self._entry(section, key)
        if found is None:
            return None
        if found[0] == "":
            self.warn(section, key, "empty value, ignored")
            return None
        return found[0]

    def integer(self, section: str, key: str,
                required: bool = False) -> Optional[int]:
        """The integer value; a value that is not an integer is ignored
        with a warning (the reference takes it as absent), or is an
        error when the key is ``required``."""
        text = self.raw(section, key)
        if text is None:
            return None
        if INTEGER.fullmatch(text):
            return int(text)
        if required:
            raise self.fail(section, key, f"'{text}' is not an integer")
        self.warn(section, key, f"'{text}' is not an integer, ignored")
        return None

    def real(self, section: str, key: str) -> Optional[float]:
        text = self.raw(section, key)
        if text is None:
            return None
        if NUMBER.fullmatch(text):
            value = float(text)
            if math.isfinite(value):
                return value
        self.warn(section, key, f"'{text}' is not a number, ignored")
        return None

    def choice(self, section: str, key: str,
               names: dict[str, int] | dict[str, str]) -> Optional[str]:
        """A name from ``names``, any case (as in the reference)."""
        text = self.raw(section, key)
        if text is None:
            return None
        low = text.lower()
        if low in names:
            return low
        raise self.fail(section, key, f"'{text}' is not one of "
                        f"{', '.join(names)}")

    def clamp(self, section: str, key: str, value: int, low: int,
              high: int, why: str = "") -> int:
        if low <= value <= high:
            return value
        limit = low if value < low else high
        self.warn(section, key, f"{value} is out of range {low}..{high}, "
                  f"{limit} used{why}")
        return limit


def _version(reader: _Reader) -> int:
    """VERSION as the reference reads it: N.N[NN] -> N*1000+N; 1.1 and
    later enable the 1.1 functions and pin names."""
    text = reader.raw(INIT, "VERSION")
    if text is None:
        return VERSION_1_0
    match = re.match(r"(\d+)\.(\d+)", text)
    if not match:
        reader.warn(INIT, "VERSION", f"'{text}' is not a version N.N, "
                    "1.0 used")
        return VERSION_1_0
    number = int(match[1]) * 1000 + int(match[2])
    if match.end() != len(text) or number not in (VERSION_1_0,
                                                  VERSION_1_1):
        used = "1.1" if number >= VERSION_1_1 else "1.0"
        reader.warn(INIT, "VERSION", f"'{text}' is not 1.0 or 1.1, "
                    f"read as {number // 1000}.{number % 1000} "
                    f"({used} used)")
    return VERSION_1_1 if number >= VERSION_1_1 else VERSION_1_0


@dataclass
class _Carry:
    """Values the reference copies from the previous transaction when a
    transaction does not give them (link keys included)."""

    kind: Optional[str] = None
    ip: Optional[str] = None
    port: int = 502
    device: Optional[str] = None
    baud: Optional[int] = None
    bits: Optional[int] = None
    parity: Optional[str] = None
    stop: Optional[int] = None
    link: Optional[Link] = None
    slave: Optional[int] = None
    response_timeout_ms: int = DEFAULT_TIMEOUT_MS
    byte_timeout_ms: int = DEFAULT_TIMEOUT_MS
    max_update_rate: float = 0.0
    serial_delay_ms: int = 0
    debug: int = 1


def _link(reader: _Reader, sec: str, carry: _Carry) -> Link:
    kind = reader.choice(sec, "LINK_TYPE", {"tcp": 0, "serial": 0})
    if kind is None:
        if carry.link is None:
            raise reader.fail(sec, None, "LINK_TYPE is required in the "
                              "first transaction (tcp or serial)")
        return carry.link
    # a link key that is absent keeps the value of an earlier transaction
    # ("required the first time" in the reference)
    if kind == "tcp":
        carry.ip = reader.raw(sec, "TCP_IP") or carry.ip
        if carry.ip is None:
            raise reader.fail(sec, None, "TCP_IP is required when "
                              "LINK_TYPE=tcp")
        port = reader.integer(sec, "TCP_PORT")
        if port is not None:
            carry.port = port
            if not 1 <= port <= 65535:
                reader.warn(sec, "TCP_PORT", f"{port} is out of range "
                            "1..65535: the link cannot connect")
        carry.link = Link("tcp", ip=carry.ip, port=carry.port)
        return carry.link

    def need(key: str, value: Optional[object]) -> None:
        if value is None:
            raise reader.fail(sec, None, f"{key} is required when "
                              "LINK_TYPE=serial")
    carry.device = reader.raw(sec, "SERIAL_PORT") or carry.device
    need("SERIAL_PORT", carry.device)
    baud = reader.integer(sec, "SERIAL_BAUD")
    if baud is not None:
        if baud <= 0:
            raise reader.fail(sec, "SERIAL_BAUD", f"{baud} is not a baud "
                              "rate")
        carry.baud = baud
    need("SERIAL_BAUD", carry.baud)
    bits = reader.integer(sec, "SERIAL_BITS")
    if bits is not None:
        if not 5 <= bits <= 8:
            raise reader.fail(sec, "SERIAL_BITS", f"{bits} is out of range "
                              "5..8")
        carry.bits = bits
    need("SERIAL_BITS", carry.bits)
    carry.parity = reader.choice(sec, "SERIAL_PARITY", PARITIES) or \
        carry.parity
    need("SERIAL_PARITY", carry.parity)
    stop = reader.integer(sec, "SERIAL_STOP")
    if stop is not None:
        if stop not in (1, 2):
            raise reader.fail(sec, "SERIAL_STOP", f"{stop} is not 1 or 2")
        carry.stop = stop
    need("SERIAL_STOP", carry.stop)
    assert carry.device is not None and carry.baud is not None
    assert carry.bits is not None and carry.parity is not None
    assert carry.stop is not None
    carry.link = Link("serial", device=carry.device, baud=carry.baud,
                      bits=carry.bits, parity=carry.parity, stop=carry.stop)
    return carry.link


def _name_ok(reader: _Reader, sec: str, key: str, name: str) -> None:
    if not name or re.search(r"\s", name):
        raise reader.fail(sec, key, f"'{name}': a name with spaces cannot "
                          "be used in a HAL file")


def _pin_names(reader: _Reader, sec: str) -> tuple[list[str], str]:
    """The element names and the key that gave their number."""
    count = reader.integer(sec, "NELEMENTS")
    if count is not None and count <= 0:
        raise reader.fail(sec, "NELEMENTS", f"{count} is out of range "
                          "(1 or more)")
    text = reader.raw(sec, "PIN_NAMES")
    if text is None:
        if count is None:
            raise reader.fail(sec, None, "NELEMENTS (or PIN_NAMES) is "
                              "required")
        return [f"{i:02d}" for i in range(count)], "NELEMENTS"
    items = text.split(",")
    names = [item.strip() for item in items if item.strip()]
    if len(names) != len(items):
        reader.warn(sec, "PIN_NAMES", "empty names are skipped")
    if any(item != item.strip() for item in items):
        reader.warn(sec, "PIN_NAMES", "spaces around the names are "
                    "removed")
    for name in names:
        _name_ok(reader, sec, "PIN_NAMES", name)
    if len(set(names)) != len(names):
        raise reader.fail(sec, "PIN_NAMES", "a name is repeated")
    if not names:
        raise reader.fail(sec, "PIN_NAMES", "no name")
    if count is None:
        return names, "PIN_NAMES"
    # the reference takes the number from NELEMENTS and the first names
    if count == len(names):
        reader.warn(sec, "PIN_NAMES", "NELEMENTS is given too: give one "
                    "of the two")
    else:
        reader.warn(sec, "PIN_NAMES", f"NELEMENTS={count} and "
                    f"{len(names)} names: {count} element(s), "
                    + ("the names past NELEMENTS are ignored"
                       if count < len(names) else
                       "the elements without a name are numbered"))
    names = names[:count] + [f"{i:02d}" for i in range(len(names), count)]
    if len(set(names)) != len(names):
        raise reader.fail(sec, "PIN_NAMES", "a name is repeated")
    return names, "NELEMENTS"


def _slave(reader: _Reader, sec: str, carry: _Carry, link: Link) -> \
        tuple[int, str]:
    slave = reader.integer(sec, "MB_SLAVE_ID")
    given = slave is not None
    if slave is None:
        if carry.slave is None:
            raise reader.fail(sec, None, "MB_SLAVE_ID is required in the "
                              "first transaction")
        slave = carry.slave
    carry.slave = slave
    if 0 <= slave <= MAX_SLAVE_ID or (slave == TCP_SLAVE_ID
                                      and link.kind == "tcp"):
        return slave, ""
    if given:
        allowed = "0..247" + (" or 255" if link.kind == "tcp" else "")
        reader.warn(sec, "MB_SLAVE_ID", f"{slave} is not a device id "
                    f"({allowed}): nothing is sent and each repetition "
                    "counts an error")
    return slave, f"device id {slave} cannot be addressed"


def _transaction(reader: _Reader, cfg: Config, number: int,
                 carry: _Carry) -> Transaction:
    sec = f"TRANSACTION_{number:02d}"
    if not reader.ini.has_section(sec):
        like = [name for name, _ in reader.ini.headers
                if name.strip().upper() == sec]
        also = (f" ([{like[0]}] is not it: section names are case "
                "sensitive, without spaces)" if like else "")
        raise reader.fail(INIT, "TOTAL_TRANSACTIONS",
                          f"section [{sec}] is missing{also}")
    link = _link(reader, sec, carry)
    slave, unusable = _slave(reader, sec, carry, link)
    first = reader.integer(sec, "FIRST_ELEMENT", required=True)
    if first is None:
        raise reader.fail(sec, None, "FIRST_ELEMENT is required")
    if first < 0:
        raise reader.fail(sec, "FIRST_ELEMENT", f"{first} is out of range "
                          "0..65535")
    if first > 65535:
        reader.warn(sec, "FIRST_ELEMENT", f"{first} is out of range "
                    f"0..65535: address {first & 0xFFFF} is sent")
        first &= 0xFFFF
    code_name = reader.choice(sec, "MB_TX_CODE", FUNCTIONS)
    if code_name is None:
        raise reader.fail(sec, None, "MB_TX_CODE is required")
    function = FUNCTIONS[code_name]
    if function in (1, 5) and cfg.version < VERSION_1_1:
        raise reader.fail(sec, "MB_TX_CODE", f"{code_name} needs "
                          f"VERSION=1.1 in [{INIT}]")
    names, key = _pin_names(reader, sec)
    if len(names) > MAX_ELEMENTS[function]:
        reader.warn(sec, key, f"{code_name} sends at most "
                    f"{MAX_ELEMENTS[function]} element(s), not "
                    f"{len(names)}: nothing is sent and each repetition "
                    "counts an error")
        unusable = unusable or (f"{len(names)} elements, {code_name} "
                                f"takes at most {MAX_ELEMENTS[function]}")
    elif first + len(names) > 65536:
        reader.warn(sec, key, "the elements go past address 65535")
    given = reader.raw(sec, "HAL_TX_NAME")
    name = given or f"{number:02d}"
    _name_ok(reader, sec, "HAL_TX_NAME", name)
    if len(name) > MAX_TX_NAME:
        raise reader.fail(sec, "HAL_TX_NAME", f"'{name}' is longer than "
                          f"{MAX_TX_NAME} characters")
    for other in cfg.transactions:
        if other.name == name:
            raise reader.fail(sec, "HAL_TX_NAME" if given else None,
                              f"transaction name "
                f"'{name}' is already used by {other.line}")
    _timing(reader, sec, carry)
    return Transaction(
        number=number, link=link, slave_id=slave, first_element=first,
        function=function, pin_names=names, name=name,
        response_timeout_ms=carry.response_timeout_ms,
        byte_timeout_ms=carry.byte_timeout_ms,
        max_update_rate=carry.max_update_rate,
        serial_delay_ms=carry.serial_delay_ms, debug=carry.debug,
        line=f"{reader.ini.path}:{reader.ini.line(sec)}", unusable=unusable)


def _timing(reader: _Reader, sec: str, carry: _Carry) -> None:
    """The optional keys that follow the previous transaction."""
    for key, low, attr in (("MB_RESPONSE_TIMEOUT_MS", 1,
                            "response_timeout_ms"),
                           ("MB_BYTE_TIMEOUT_MS", 0, "byte_timeout_ms")):
        value = reader.integer(sec, key)
        if value is None:
            continue
        if value < low:
            reader.warn(sec, key, f"{value} is out of range {low}.."
                        f"{MAX_TIMEOUT_MS}, {DEFAULT_TIMEOUT_MS} used")
            value = DEFAULT_TIMEOUT_MS
        setattr(carry, attr, reader.clamp(sec, key, value, low,
                                          MAX_TIMEOUT_MS))
    rate = reader.real(sec, "MAX_UPDATE_RATE")
    if rate is not None:
        if rate < 0:
            reader.warn(sec, "MAX_UPDATE_RATE", f"{rate:g} is negative, "
                        "0 (no limit) used")
            rate = 0.0
        elif rate and not MIN_RATE <= rate <= MAX_RATE:
            reader.warn(sec, "MAX_UPDATE_RATE", f"{rate:g} Hz is outside "
                        f"1/3600 (once an hour) .. {MAX_RATE:.0f} Hz")
        carry.max_update_rate = rate
    delay = reader.integer(sec, "SERIAL_DELAY_MS")
    if delay is not None:
        carry.serial_delay_ms = reader.clamp(sec, "SERIAL_DELAY_MS", delay,
                                             0, MAX_DELAY_MS)
    debug = reader.integer(sec, "DEBUG")
    if debug is not None:
        carry.debug = reader.clamp(sec, "DEBUG", debug, 0, 4)


def parse(ini: IniFile, strict: bool = False) -> Config:
    """Build a :class:`Config` from an already read INI file; with
    ``strict`` the warnings are a :class:`ConfigError`."""
    reader = _Reader(ini)
    try:
        cfg = _parse(reader)
    except ConfigError as exc:
        # the warnings found so far often explain the error (a key
        # written in lower case, then "MB_SLAVE_ID is required")
        exc.warnings = [text for _, text in sorted(reader.notes)]
        raise
    if strict and cfg.warnings:
        raise ConfigError("\n".join(f"{text} (refused by --strict)"
                                    for text in cfg.warnings))
    return cfg


def _parse(reader: _Reader) -> Config:
    ini = reader.ini
    cfg = Config(path=ini.path)
    if not ini.has_section(INIT):
        raise ConfigError(f"{ini.path}: section [{INIT}] is missing")
    _check_layout(reader)
    debug = reader.integer(INIT, "INIT_DEBUG")
    if debug is not None:
        cfg.init_debug = reader.clamp(INIT, "INIT_DEBUG", debug, 0, 4)
    cfg.version = _version(reader)
    cfg.module_name = reader.raw(INIT, "HAL_MODULE_NAME") or "mb2hal"
    if not re.fullmatch(r"[A-Za-z0-9_.\-]+", cfg.module_name):
        raise reader.fail(INIT, "HAL_MODULE_NAME",
                          f"'{cfg.module_name}' is not a HAL name")
    slowdown = reader.real(INIT, "SLOWDOWN")
    if slowdown is not None:
        if slowdown < 0:
            reader.warn(INIT, "SLOWDOWN", f"{slowdown:g} is negative, 0 "
                        "used")
            slowdown = 0.0
        elif slowdown > MAX_SLOWDOWN:
            reader.warn(INIT, "SLOWDOWN", f"{slowdown:g} s is more than "
                        f"{MAX_SLOWDOWN:g} s, {MAX_SLOWDOWN:g} used")
            slowdown = MAX_SLOWDOWN
        cfg.slowdown = slowdown
    total = reader.integer(INIT, "TOTAL_TRANSACTIONS", required=True)
    if total is None:
        raise reader.fail(INIT, None, "TOTAL_TRANSACTIONS is required")
    if total < 1:
        raise reader.fail(INIT, "TOTAL_TRANSACTIONS", f"{total} is out of "
                          "range (1 or more)")
    _check_sections(reader, total)
    carry = _Carry(debug=cfg.init_debug)
    for number in range(total):
        cfg.transactions.append(_transaction(reader, cfg, number, carry))
    serial: dict[str, Link] = {}
    for tx in cfg.transactions:
        link = tx.link
        if link.kind == "serial":
            other = serial.setdefault(link.device, link)
            if other != link:
                reader.warn(f"TRANSACTION_{tx.number:02d}", "LINK_TYPE",
                            f"serial port {link.device} is already "
                            f"configured as {other.describe()}: those "
                            "settings are used")
                tx.link = other
    cfg.warnings = [text for _, text in sorted(reader.notes)]
    return cfg


def _check_layout(reader: _Reader) -> None:
    """Repeated sections and keys and unknown keys in the mb2hal sections:
    the reference reads the first copy of a section and the first value
    of a key and ignores unknown keys, silently."""
    ini = reader.ini
    for number, text in ini.repeats(sections=_ours):
        section = text[1:text.index("]")]
        key = text[text.index("]") + 1:].split(" ")[0]
        label = f"{ini.path}:{number}: [{section}]{key}"
        rest = text[text.index(" is given again"):]
        also = (", ignored: the first one is used" if key else
                ", ignored: only the first copy is read")
        reader.notes.append((number, label + rest + also))
    for (section, key), places in ini.every.items():
        if not _ours(section):
            continue
        known = INIT_KEYS if section == INIT else TRANSACTION_KEYS
        if key not in known:
            if key.upper() in known:
                also = f" (keys are case sensitive: {key.upper()}?)"
            else:
                hint = difflib.get_close_matches(key, known, 1)
                also = f" (did you mean {hint[0]}?)" if hint else ""
            reader.notes.append((places[0][1], f"{ini.path}:{places[0][1]}"
                                 f": [{section}]{key}: unknown key, "
                                 f"ignored{also}"))


def _check_sections(reader: _Reader, total: int) -> None:
    """Transaction sections past TOTAL_TRANSACTIONS are not read."""
    wanted = {f"TRANSACTION_{i:02d}" for i in range(total)}
    for name, number in reader.ini.headers:
        if (TRANSACTION_SECTION.fullmatch(name) and name not in wanted
                and reader.ini.line(name) == number):
            reader.warn(name, None, f"section not read: "
                        f"TOTAL_TRANSACTIONS={total} reads TRANSACTION_00"
                        f" to TRANSACTION_{total - 1:02d}")


def load_config(path: str, strict: bool = False) -> Config:
    """Read and check an mb2hal INI file."""
    try:
        ini = IniFile(path)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror}") from None
    return parse(ini, strict)
