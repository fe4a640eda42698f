"""The drive configuration INI file of the ``cia402`` program."""

from __future__ import annotations

import math
import os
import re
import struct
from dataclasses import dataclass, field
from typing import Optional

import can
import canopen
from canopen.objectdictionary import ObjectDictionary, ODVariable

from halsdk.ini import IniFile

from . import DEFAULT_EDS
from .statemachine import MODES

BUS = "BUS"
BUS_KEYS = {"INTERFACE", "CHANNEL", "BITRATE", "PERIOD", "SIMULATE",
            "SDO_TIMEOUT"}
DRIVE_KEYS = {"NODE_ID", "EDS", "MODE", "POSITION_SCALE", "VELOCITY_SCALE",
              "HEARTBEAT_TIMEOUT", "HEARTBEAT_PERIOD", "PROFILE_VELOCITY",
              "PROFILE_ACCELERATION", "PROFILE_DECELERATION", "SDO",
              *(f"{d}PDO{n}" for d in "RT" for n in range(1, 5))}

#: objects the driver fills in an RPDO
RPDO_OBJECTS = {0x6040, 0x607A, 0x60FF, 0x6081, 0x6060}
#: type names of SDO lines for objects the EDS does not describe
SDO_TYPES = {"u8": 0x5, "u16": 0x6, "u32": 0x7, "i8": 0x2, "i16": 0x3,
             "i32": 0x4, "f32": 0x8}
DEFAULT_RPDO = {1: [(0x6040, 0), (0x607A, 0)], 2: [(0x60FF, 0)]}
DEFAULT_TPDO = {1: [(0x6041, 0), (0x6064, 0)], 2: [(0x606C, 0)]}
#: keys that may be given more than once in a section
REPEATABLE = {"SDO"}
#: the longest driver cycle (PERIOD), in seconds
MAX_PERIOD = 1.0
#: the longest SDO and heartbeat time, in seconds
MAX_TIMEOUT = 60.0
#: the fastest nominal bit rate of classic CAN, in bit/s
MAX_BITRATE = 1_000_000
#: the largest profile value in drive units (0x6081, 0x6083, 0x6084: u32)
MAX_COUNTS = 0xFFFFFFFF


class ConfigError(Exception):
    """A bad configuration; the message starts with ``file:line:``."""


@dataclass
class SdoWrite:
    index: int
    subindex: int
    value: int | float
    data: bytes
    where: str


@dataclass
class PdoEntry:
    index: int
    subindex: int
    var: ODVariable

    @property
    def bits(self) -> int:
        return len(self.var)

    @property
    def mapping(self) -> int:
        """The value of a mapping entry (0x16xx/0x1Axx sub-object)."""
        return (self.index << 16) | (self.subindex << 8) | self.bits


@dataclass
class DriveConfig:
    num: int
    node_id: int
    eds: str
    od: ObjectDictionary
    mode: str = "csp"
    position_scale: float = 1.0
    velocity_scale: float = 1.0
    heartbeat_timeout: float = 0.5
    heartbeat_period: float = 0.1
    profile_velocity: float = 0.0
    profile_acceleration: float = 0.0
    profile_deceleration: float = 0.0
    sdo_writes: list[SdoWrite] = field(default_factory=list)
    rpdo: dict[int, list[PdoEntry]] = field(default_factory=dict)
    tpdo: dict[int, list[PdoEntry]] = field(default_factory=dict)

    def rpdo_cob(self, n: int) -> int:
        return 0x100 + 0x100 * n + self.node_id

    def tpdo_cob(self, n: int) -> int:
        return 0x80 + 0x100 * n + self.node_id


@dataclass
class BusConfig:
    interface: str = "socketcan"
    channel: str = "can0"
    bitrate: int = 1000000
    period: float = 0.01
    simulate: bool = False
    sdo_timeout: float = 0.3
    drives: list[DriveConfig] = field(default_factory=list)
    path: str = ""


class _Reader:
    def __init__(self, ini: IniFile):
        self.ini = ini

    def fail(self, section: str, key: Optional[str], msg: str) -> ConfigError:
        return ConfigError(f"{self.ini.where(section, key)}: {msg}")

    def text(self, section: str, key: str, default: str) -> str:
        value = self.ini.get(section, key)
        return default if value is None or value == "" else value

    def number(self, section: str, key: str, default: float,
               low: float = float("-inf"), positive: bool = False,
               high: float = float("inf")) -> float:
        """A finite number in [low, high] (> 0 when ``positive``)."""
        raw = self.ini.get(section, key)
        if raw is None or raw == "":
            return default
        try:
            value = float(int(raw, 0)) if raw.lower().startswith("0x") \
                else float(raw)
        except ValueError:
            raise self.fail(section, key,
                            f"{key} = {raw!r} is not a number") from None
        if not math.isfinite(value):
            raise self.fail(section, key,
                            f"{key} = {raw!r} is not a finite number")
        if value < low or (positive and value <= 0):
            bound = "> 0" if positive else f">= {low:g}"
            raise self.fail(section, key, f"{key} must be {bound}, "
                            f"not {raw}")
        if value > high:
            raise self.fail(section, key, f"{key} must be at most "
                            f"{high:g}, not {raw}")
        return value

    def check_keys(self, section: str, allowed: set[str]) -> None:
        for key, _ in self.ini.items(section):
            if key not in allowed:
                raise self.fail(section, key,
                                f"unknown key {key} in [{section}]")


_OBJ = re.compile(r"^(0x)?([0-9a-fA-F]{1,4})(?::(0x)?([0-9a-fA-F]{1,2}))?$")


def parse_object(text: str) -> Optional[tuple[int, int]]:
    """``6040``, ``0x6040`` or ``0x1018:02`` (hexadecimal) → (index, sub)."""
    m = _OBJ.match(text)
    if not m:
        return None
    return int(m.group(2), 16), int(m.group(4) or "0", 16)


def find_var(od: ObjectDictionary, index: int, sub: int
             ) -> Optional[ODVariable]:
    if index not in od:
        return None
    obj = od[index]
    if isinstance(obj, ODVariable):
        return obj if sub == 0 else None
    return obj[sub] if sub in obj else None


def _pdos(r: _Reader, section: str, od: ObjectDictionary, kind: str,
          defaults: dict[int, list[tuple[int, int]]]
          ) -> dict[int, list[PdoEntry]]:
    given = {n: v for n in range(1, 5)
             if (v := r.ini.get(section, f"{kind}{n}")) is not None}
    source = ({n: [(i, s) for i, s in objs] for n, objs in defaults.items()}
              if not given else None)
    out: dict[int, list[PdoEntry]] = {}
    if source is None:
        source = {}
        for n, value in given.items():
            objs = []
            for word in value.split():
                obj = parse_object(word)
                if obj is None:
                    raise r.fail(section, f"{kind}{n}",
                                 f"{word!r} is not an object (write "
                                 "INDEX or INDEX:SUB in hexadecimal)")
                objs.append(obj)
            source[n] = objs
    for n, objs in source.items():
        key = f"{kind}{n}" if given else None
        entries = []
        for index, sub in objs:
            var = find_var(od, index, sub)
            if var is None:
                raise r.fail(section, key, f"{kind}{n}: object "
                             f"0x{index:04X}:{sub:02X} is not in the EDS")
            if kind == "RPDO" and index not in RPDO_OBJECTS:
                names = ", ".join(f"0x{i:04X}" for i in sorted(RPDO_OBJECTS))
                raise r.fail(section, key, f"{kind}{n}: the driver cannot "
                             f"fill 0x{index:04X} (it fills {names})")
            entries.append(PdoEntry(index, sub, var))
        if sum(e.bits for e in entries) > 64:
            raise r.fail(section, key, f"{kind}{n}: more than 8 bytes")
        if entries:
            out[n] = entries
    need = 0x6040 if kind == "RPDO" else 0x6041
    if not any(e.index == need for es in out.values() for e in es):
        raise r.fail(section, next((f"{kind}{n}" for n in given), None),
                     f"the {kind}s must map 0x{need:04X}")
    return out


def _sdo_write(r: _Reader, section: str, od: ObjectDictionary, raw: str,
               line: int) -> SdoWrite:
    where = f"{r.ini.path}:{line}"
    words = raw.split()
    obj = parse_object(words[0]) if words else None
    if obj is None or len(words) not in (2, 3):
        raise ConfigError(f"{where}: SDO = {raw!r}: write SDO = INDEX:SUB "
                          "VALUE [TYPE] (INDEX, SUB in hexadecimal)")
    index, sub = obj
    var = find_var(od, index, sub)
    if len(words) == 3:
        dtype = SDO_TYPES.get(words[2].lower())
        if dtype is None:
            raise ConfigError(f"{where}: unknown type {words[2]!r} (one of "
                              f"{', '.join(SDO_TYPES)})")
        var = ODVariable("sdo", index, sub)
        var.data_type = dtype
    if var is None:
        raise ConfigError(f"{where}: object 0x{index:04X}:{sub:02X} is not "
                          "in the EDS; give its type (SDO = INDEX:SUB VALUE "
                          "TYPE)")
    try:
        value: int | float = float(words[1]) if var.data_type in (0x8, 0x11) \
            else int(words[1], 0)
        data = var.encode_raw(value)
    except (ValueError, struct.error, TypeError):
        raise ConfigError(f"{where}: value {words[1]!r} does not fit object "
                          f"0x{index:04X}:{sub:02X}") from None
    return SdoWrite(index, sub, value, data, where)


def _drive(r: _Reader, num: int, base: str) -> DriveConfig:
    section = f"DRIVE_{num}"
    r.check_keys(section, DRIVE_KEYS)
    node_raw = r.ini.get(section, "NODE_ID")
    if node_raw is None:
        raise r.fail(section, None, f"[{section}] needs NODE_ID")
    node_id = r.number(section, "NODE_ID", 0)
    if node_id != int(node_id) or not 1 <= node_id <= 127:
        raise r.fail(section, "NODE_ID", "NODE_ID must be 1 to 127")
    eds = r.text(section, "EDS", DEFAULT_EDS)
    if not os.path.isabs(eds):
        eds = os.path.join(base, eds)
    try:
        od = canopen.import_od(eds, int(node_id))
    except Exception as exc:  # a missing file or a broken EDS
        raise r.fail(section, "EDS", f"cannot read EDS {eds}: "
                     f"{exc}") from None
    mode = r.text(section, "MODE", "csp").lower()
    if mode not in MODES:
        raise r.fail(section, "MODE", f"MODE must be one of "
                     f"{', '.join(MODES)}, not {mode!r}")
    pscale = r.number(section, "POSITION_SCALE", 1.0)
    if pscale == 0:
        raise r.fail(section, "POSITION_SCALE", "POSITION_SCALE is 0")
    vscale = r.number(section, "VELOCITY_SCALE", pscale)
    if vscale == 0:
        raise r.fail(section, "VELOCITY_SCALE", "VELOCITY_SCALE is 0")
    accel = r.number(section, "PROFILE_ACCELERATION", 0.0, 0.0)
    drive = DriveConfig(
        num=num, node_id=int(node_id), eds=eds, od=od, mode=mode,
        position_scale=pscale, velocity_scale=vscale,
        heartbeat_timeout=r.number(section, "HEARTBEAT_TIMEOUT", 0.5, 0.0,
                                   high=MAX_TIMEOUT),
        heartbeat_period=r.number(section, "HEARTBEAT_PERIOD", 0.1, 0.0,
                                  high=MAX_TIMEOUT),
        profile_velocity=r.number(section, "PROFILE_VELOCITY", 0.0, 0.0),
        profile_acceleration=accel,
        profile_deceleration=r.number(section, "PROFILE_DECELERATION",
                                      accel, 0.0))
    for key, value in (("PROFILE_VELOCITY", drive.profile_velocity),
                       ("PROFILE_ACCELERATION", drive.profile_acceleration),
                       ("PROFILE_DECELERATION", drive.profile_deceleration)):
        if abs(value * pscale) > MAX_COUNTS:
            raise r.fail(section, key, f"{key} times POSITION_SCALE must "
                         f"be at most {MAX_COUNTS} drive units")
    if 0 < drive.heartbeat_timeout <= drive.heartbeat_period:
        raise r.fail(section, "HEARTBEAT_TIMEOUT", "HEARTBEAT_TIMEOUT must "
                     "be larger than HEARTBEAT_PERIOD")
    for raw, line in r.ini.every.get((section, "SDO"), []):
        drive.sdo_writes.append(_sdo_write(r, section, od, raw, line))
    drive.rpdo = _pdos(r, section, od, "RPDO", DEFAULT_RPDO)
    drive.tpdo = _pdos(r, section, od, "TPDO", DEFAULT_TPDO)
    return drive


def _check_repeats(ini: IniFile) -> None:
    """Reject a repeated section header, a repeated key (but ``SDO``) and
    a key before the first section; the error names the later line."""
    problems = ini.repeats(repeatable=REPEATABLE)
    for (section, key), found in ini.every.items():
        if section == "":
            problems.append((found[0][1], f"{key} is outside a section"))
    if problems:
        number, text = min(problems)
        raise ConfigError(f"{ini.path}:{number}: {text}")


def load(path: str) -> BusConfig:
    """Read and check a drive configuration file."""
    try:
        ini = IniFile(path)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror}") from None
    _check_repeats(ini)
    r = _Reader(ini)
    base = os.path.dirname(os.path.abspath(path))
    for section in ini.section_lines:
        if section != BUS and not re.fullmatch(r"DRIVE_\d+", section):
            raise r.fail(section, None, f"unknown section [{section}] "
                         "(BUS, DRIVE_0, DRIVE_1, ...)")
    r.check_keys(BUS, BUS_KEYS)
    simulate = r.text(BUS, "SIMULATE", "0").lower()
    if simulate not in ("0", "1", "yes", "no", "true", "false"):
        raise r.fail(BUS, "SIMULATE", "SIMULATE must be 0 or 1")
    interface = r.text(BUS, "INTERFACE", "socketcan")
    if interface not in can.VALID_INTERFACES:
        raise r.fail(BUS, "INTERFACE", f"unknown INTERFACE {interface!r} "
                     f"(one of {', '.join(sorted(can.VALID_INTERFACES))})")
    bitrate = r.number(BUS, "BITRATE", MAX_BITRATE, positive=True,
                       high=MAX_BITRATE)
    if bitrate != int(bitrate):
        raise r.fail(BUS, "BITRATE", "BITRATE must be a whole number")
    bus = BusConfig(
        interface=interface,
        channel=r.text(BUS, "CHANNEL", "can0"),
        bitrate=int(bitrate),
        period=r.number(BUS, "PERIOD", 0.01, positive=True,
                        high=MAX_PERIOD),
        simulate=simulate in ("1", "yes", "true"),
        sdo_timeout=r.number(BUS, "SDO_TIMEOUT", 0.3, positive=True,
                             high=MAX_TIMEOUT),
        path=path)
    nums = sorted(int(s[6:]) for s in ini.section_lines
                  if s.startswith("DRIVE_"))
    if not nums:
        raise ConfigError(f"{path}: no [DRIVE_0] section")
    if nums != list(range(len(nums))):
        missing = next(n for n in range(len(nums) + 1) if n not in nums)
        raise ConfigError(f"{path}: drives are numbered from 0 without "
                          f"gaps: [DRIVE_{missing}] is missing")
    seen: dict[int, int] = {}
    for num in nums:
        drive = _drive(r, num, base)
        if drive.node_id in seen:
            raise r.fail(f"DRIVE_{num}", "NODE_ID", f"node {drive.node_id} "
                         f"is also DRIVE_{seen[drive.node_id]}")
        seen[drive.node_id] = num
        bus.drives.append(drive)
    return bus
