"""Reading the mb2hal INI file into links and transactions.

Every problem raises :class:`ConfigError` with ``file:line`` and the key.
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass, field
from typing import Callable, Optional, TypeVar, overload

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
VERSION_1_1 = 1001
PARITIES = {"none": "N", "even": "E", "odd": "O"}
MAX_TX_NAME = 28
#: longest SLOWDOWN, s; longest request timeout, ms; longest serial pause, ms
MAX_SLOWDOWN = 60.0
MAX_TIMEOUT_MS = 60_000
MAX_DELAY_MS = 3_600_000
#: slowest MAX_UPDATE_RATE other than 0 (once an hour) and the fastest, Hz
MIN_RATE = 1.0 / 3600.0
MAX_RATE = 1_000_000.0

INIT_KEYS = ("INIT_DEBUG", "VERSION", "HAL_MODULE_NAME", "SLOWDOWN",
             "TOTAL_TRANSACTIONS")
TRANSACTION_KEYS = (
    "LINK_TYPE", "TCP_IP", "TCP_PORT", "SERIAL_PORT", "SERIAL_BAUD",
    "SERIAL_BITS", "SERIAL_PARITY", "SERIAL_STOP", "SERIAL_DELAY_MS",
    "MB_SLAVE_ID", "FIRST_ELEMENT", "NELEMENTS", "PIN_NAMES", "MB_TX_CODE",
    "MB_RESPONSE_TIMEOUT_MS", "MB_BYTE_TIMEOUT_MS", "HAL_TX_NAME",
    "MAX_UPDATE_RATE", "DEBUG")
TRANSACTION_SECTION = re.compile(r"TRANSACTION_\d+")

T = TypeVar("T")


class ConfigError(Exception):
    """A bad INI file; the message names file:line and key."""


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
    response_timeout_ms: int = 500
    byte_timeout_ms: int = 500
    max_update_rate: float = 0.0
    serial_delay_ms: int = 0
    debug: int = 1
    line: str = ""                 # file:line of the section header

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
    version: int = 1000
    slowdown: float = 0.0
    transactions: list[Transaction] = field(default_factory=list)

    @property
    def links(self) -> list[Link]:
        seen: dict[tuple, Link] = {}
        for tx in self.transactions:
            seen.setdefault(tx.link.key, tx.link)
        return list(seen.values())


class _Reader:
    """Typed look-ups in one INI file with file:line errors."""

    def __init__(self, ini: IniFile):
        self.ini = ini

    def fail(self, section: str, key: Optional[str], text: str) -> ConfigError:
        where = self.ini.where(section, key)
        label = f"[{section}]{key}" if key else f"[{section}]"
        return ConfigError(f"{where}: {label}: {text}")

    def raw(self, section: str, key: str) -> Optional[str]:
        value = self.ini.get(section, key)
        if value is not None and value == "":
            raise self.fail(section, key, "empty value")
        return value

    def typed(self, section: str, key: str, conv: Callable[[str], T],
              what: str, default: Optional[T] = None,
              check: Optional[Callable[[T], bool]] = None,
              rule: str = "") -> Optional[T]:
        text = self.raw(section, key)
        if text is None:
            return default
        try:
            value = conv(text)
        except ValueError:
            raise self.fail(section, key, f"'{text}' is not {what}") from None
        if check is not None and not check(value):
            raise self.fail(section, key, f"'{text}' {rule}")
        return value

    @overload
    def integer(self, section: str, key: str, default: int,
                low: int = ..., high: int = ...) -> int: ...

    @overload
    def integer(self, section: str, key: str, default: None = None,
                low: int = ..., high: int = ...) -> Optional[int]: ...

    def integer(self, section: str, key: str, default: Optional[int] = None,
                low: int = 0, high: int = 2**31 - 1) -> Optional[int]:
        """The integer value of ``key`` in [low, high]; ``default`` when
        the key is absent (so never None when ``default`` is an int)."""
        return self.typed(section, key, int, "an integer", default,
                          lambda v: low <= v <= high,
                          f"is out of range {low}..{high}")

    def real(self, section: str, key: str, default: float,
             check: Callable[[float], bool], rule: str) -> float:
        value = self.typed(section, key, float, "a number", default,
                           lambda v: math.isfinite(v) and check(v), rule)
        assert value is not None
        return value

    def required(self, section: str, key: str, value: Optional[T],
                 why: str = "is required") -> T:
        if value is None:
            raise self.fail(section, None, f"{key} {why}")
        return value


def _version(reader: _Reader) -> int:
    text = reader.raw(INIT, "VERSION")
    if text is None:
        return 1000
    match = re.fullmatch(r"(\d+)\.(\d{1,3})", text)
    if not match:
        raise reader.fail(INIT, "VERSION",
                          f"'{text}' is not a version N.N[NN]")
    number = int(match[1]) * 1000 + int(match[2])
    if number < 1000 or number > VERSION_1_1:
        raise reader.fail(INIT, "VERSION",
                          f"'{text}' is not supported (1.0 or 1.1)")
    return number


def _link(reader: _Reader, sec: str, previous: Optional[Link]) -> Link:
    kind = reader.raw(sec, "LINK_TYPE")
    if kind is None:
        if previous is None:
            raise reader.fail(sec, None, "LINK_TYPE is required in the "
                              "first transaction (tcp or serial)")
        return previous
    if kind == "tcp":
        ip = reader.required(sec, "TCP_IP", reader.raw(sec, "TCP_IP"),
                             "is required when LINK_TYPE=tcp")
        port = reader.integer(sec, "TCP_PORT", 502, 1, 65535)
        return Link("tcp", ip=ip, port=port)
    if kind == "serial":
        def need(key: str, value: Optional[T]) -> T:
            return reader.required(sec, key, value,
                                   "is required when LINK_TYPE=serial")
        device = need("SERIAL_PORT", reader.raw(sec, "SERIAL_PORT"))
        baud = need("SERIAL_BAUD", reader.integer(sec, "SERIAL_BAUD",
                                                  None, 1))
        bits = need("SERIAL_BITS", reader.integer(sec, "SERIAL_BITS",
                                                  None, 5, 8))
        parity = need("SERIAL_PARITY", reader.typed(
            sec, "SERIAL_PARITY", str, "a parity", None,
            lambda v: v in PARITIES, "must be one of even, odd, none"))
        stop = need("SERIAL_STOP", reader.integer(sec, "SERIAL_STOP",
                                                  None, 1, 2))
        return Link("serial", device=device, baud=baud, bits=bits,
                    parity=parity, stop=stop)
    raise reader.fail(sec, "LINK_TYPE",
                      f"'{kind}' is not a link type (tcp or serial)")


def _pin_names(reader: _Reader, sec: str) -> list[str]:
    count = reader.integer(sec, "NELEMENTS", None, 1, 65536)
    names = reader.raw(sec, "PIN_NAMES")
    if count is not None and names is not None:
        raise reader.fail(sec, "PIN_NAMES",
                          "give either NELEMENTS or PIN_NAMES, not both")
    if names is not None:
        result = names.split(",")
        for name in result:
            if not re.fullmatch(r"[A-Za-z0-9_.\-]+", name):
                raise reader.fail(sec, "PIN_NAMES", f"bad pin name '{name}' "
                                  "(letters, digits, _ . - only, no spaces)")
        if len(set(result)) != len(result):
            raise reader.fail(sec, "PIN_NAMES", "a name is repeated")
        return result
    count = reader.required(sec, "NELEMENTS", count,
                            "(or PIN_NAMES) is required")
    return [f"{i:02d}" for i in range(count)]


def _transaction(reader: _Reader, cfg: Config, number: int,
                 prev: Optional[Transaction]) -> Transaction:
    sec = f"TRANSACTION_{number:02d}"
    if not reader.ini.has_section(sec):
        raise reader.fail(INIT, "TOTAL_TRANSACTIONS",
                          f"section [{sec}] is missing")
    link = _link(reader, sec, prev.link if prev else None)
    slave = reader.integer(sec, "MB_SLAVE_ID", None, 0, 255)
    if slave is None:
        slave = reader.required(sec, "MB_SLAVE_ID",
                                prev.slave_id if prev else None)
    first = reader.required(sec, "FIRST_ELEMENT",
                            reader.integer(sec, "FIRST_ELEMENT", None, 0,
                                           65535))
    code_name = reader.required(sec, "MB_TX_CODE",
                                reader.raw(sec, "MB_TX_CODE"))
    if code_name not in FUNCTIONS:
        raise reader.fail(sec, "MB_TX_CODE", f"unknown function "
                          f"'{code_name}' (one of {', '.join(FUNCTIONS)})")
    function = FUNCTIONS[code_name]
    if function in (1, 5) and cfg.version < VERSION_1_1:
        raise reader.fail(sec, "MB_TX_CODE", f"{code_name} needs "
                          f"VERSION=1.1 in [{INIT}]")
    names = _pin_names(reader, sec)
    key = "PIN_NAMES" if reader.ini.get(sec, "PIN_NAMES") else "NELEMENTS"
    if len(names) > MAX_ELEMENTS[function]:
        raise reader.fail(sec, key, f"{code_name} takes at most "
                          f"{MAX_ELEMENTS[function]} element(s), "
                          f"not {len(names)}")
    if first + len(names) > 65536:
        raise reader.fail(sec, key, "the elements go past address 65535")
    name = reader.raw(sec, "HAL_TX_NAME") or f"{number:02d}"
    if len(name) > MAX_TX_NAME or not re.fullmatch(r"[A-Za-z0-9_.\-]+",
                                                   name):
        raise reader.fail(sec, "HAL_TX_NAME", f"'{name}' must be at most "
                          f"{MAX_TX_NAME} letters, digits, _ . -")
    for other in cfg.transactions:
        if other.name == name:
            raise reader.fail(sec, "HAL_TX_NAME" if reader.ini.get(
                sec, "HAL_TX_NAME") else None, f"transaction name "
                f"'{name}' is already used by {other.line}")
    inherit = prev or Transaction(0, link, 0, 0, 0, [], "",
                                  debug=cfg.init_debug)
    tx = Transaction(
        number=number, link=link, slave_id=slave, first_element=first,
        function=function, pin_names=names, name=name,
        response_timeout_ms=reader.integer(
            sec, "MB_RESPONSE_TIMEOUT_MS", inherit.response_timeout_ms, 1,
            MAX_TIMEOUT_MS),
        byte_timeout_ms=reader.integer(
            sec, "MB_BYTE_TIMEOUT_MS", inherit.byte_timeout_ms, 0,
            MAX_TIMEOUT_MS),
        max_update_rate=reader.real(
            sec, "MAX_UPDATE_RATE", inherit.max_update_rate,
            lambda v: v == 0.0 or MIN_RATE <= v <= MAX_RATE,
            f"must be 0 (no limit) or from 1/3600 (once an hour) to "
            f"{MAX_RATE:.0f} Hz"),
        serial_delay_ms=reader.integer(sec, "SERIAL_DELAY_MS",
                                       inherit.serial_delay_ms, 0,
                                       MAX_DELAY_MS),
        debug=reader.integer(sec, "DEBUG", inherit.debug, 0, 4),
        line=reader.ini.where(sec))
    return tx


def parse(ini: IniFile) -> Config:
    """Build a :class:`Config` from an already read INI file."""
    reader = _Reader(ini)
    cfg = Config(path=ini.path)
    if not ini.has_section(INIT):
        raise ConfigError(f"{ini.path}: section [{INIT}] is missing")
    _check_layout(ini)
    cfg.init_debug = reader.integer(INIT, "INIT_DEBUG", 1, 0, 4)
    cfg.version = _version(reader)
    cfg.module_name = reader.raw(INIT, "HAL_MODULE_NAME") or "mb2hal"
    if not re.fullmatch(r"[A-Za-z0-9_.\-]+", cfg.module_name):
        raise reader.fail(INIT, "HAL_MODULE_NAME",
                          f"'{cfg.module_name}' is not a HAL name")
    cfg.slowdown = reader.real(
        INIT, "SLOWDOWN", 0.0, lambda v: 0.0 <= v <= MAX_SLOWDOWN,
        f"must be from 0 to {MAX_SLOWDOWN:g} seconds")
    total = reader.required(INIT, "TOTAL_TRANSACTIONS", reader.integer(
        INIT, "TOTAL_TRANSACTIONS", None, 1, 99999))
    prev: Optional[Transaction] = None
    for number in range(total):
        prev = _transaction(reader, cfg, number, prev)
        cfg.transactions.append(prev)
    serial: dict[str, Link] = {}
    for link in cfg.links:
        if link.kind == "serial":
            other = serial.setdefault(link.device, link)
            if other != link:
                raise ConfigError(f"{ini.path}: serial port {link.device} "
                                  "is configured twice with different "
                                  "settings")
    return cfg


def _ours(section: str) -> bool:
    return section == INIT or bool(TRANSACTION_SECTION.fullmatch(section))


def _check_layout(ini: IniFile) -> None:
    """Repeated sections, repeated keys and unknown keys in the mb2hal
    sections are errors (the reference ignores them silently); the first
    one in the file is reported."""
    problems = ini.repeats(sections=_ours)
    for (section, key), places in ini.every.items():
        if not _ours(section):
            continue
        known = INIT_KEYS if section == INIT else TRANSACTION_KEYS
        if key not in known:
            hint = difflib.get_close_matches(key, known, 1)
            also = f" (did you mean {hint[0]}?)" if hint else ""
            problems.append((places[0][1],
                             f"[{section}]{key}: unknown key{also}"))
    if problems:
        number, text = min(problems)
        raise ConfigError(f"{ini.path}:{number}: {text}")


def load_config(path: str) -> Config:
    """Read and check an mb2hal INI file."""
    try:
        ini = IniFile(path)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror}") from None
    return parse(ini)
