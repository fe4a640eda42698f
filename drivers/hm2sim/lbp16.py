"""The LBP16 protocol of Mesa's Ethernet cards: command words and packets.

An LBP16 datagram (UDP, port 27181) is a sequence of commands.  Each
command starts with a 16-bit little-endian command word::

    bit 15      write (1) or read (0)
    bit 14      a 16-bit address follows the command word
    bit 13      info area access (the memory space's description)
    bits 12-10  memory space (0 HostMot2 registers, 2 Ethernet EEPROM,
                3 FPGA flash, 4 timers, 6 LBP16 status/control,
                7 board information)
    bits 9-8    transfer size: 8, 16, 32 or 64 bits
    bit 7       increment the address after each transfer
    bits 6-0    number of transfers (1..127)

A write command is followed by its data (count x size bytes).  The card
answers the read commands of a datagram with one datagram holding their
data, in order; writes are not answered.  Without an address the command
continues at the space's current address.  Addresses are byte addresses.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Optional

#: the UDP port of LBP16
PORT = 27181

WRITE = 0x8000
ADDRESS = 0x4000
INFO = 0x2000
SPACE_SHIFT = 10
SIZE_SHIFT = 8
INCREMENT = 0x0080
COUNT_MASK = 0x007F

SPACE_HM2 = 0
SPACE_ETH_CHIP = 1
SPACE_EEPROM = 2
SPACE_FLASH = 3
SPACE_TIMER = 4
SPACE_COMM = 6
SPACE_BOARD = 7

#: transfer size in bytes for the size field
SIZES = (1, 2, 4, 8)


class Lbp16Error(ValueError):
    """A malformed LBP16 command or datagram."""


@dataclass(frozen=True)
class Command:
    """One LBP16 command (its data for a write)."""

    write: bool
    space: int
    size: int                   # bytes per transfer: 1, 2, 4 or 8
    count: int                  # 1..127
    address: Optional[int] = None
    increment: bool = True
    info: bool = False
    data: bytes = b""

    def __post_init__(self) -> None:
        if not 0 <= self.space <= 7:
            raise Lbp16Error(f"memory space {self.space} is not 0..7")
        if self.size not in SIZES:
            raise Lbp16Error(f"transfer size {self.size} is not 1, 2, 4 or 8")
        if not 1 <= self.count <= COUNT_MASK:
            raise Lbp16Error(f"transfer count {self.count} is not 1..127")
        if self.address is not None and not 0 <= self.address <= 0xFFFF:
            raise Lbp16Error(f"address {self.address:#x} is not 16-bit")
        if self.write and len(self.data) != self.size * self.count:
            raise Lbp16Error(
                f"write of {self.count} x {self.size} bytes carries "
                f"{len(self.data)} bytes")
        if not self.write and self.data:
            raise Lbp16Error("a read carries no data")

    @property
    def word(self) -> int:
        """The 16-bit command word."""
        return ((WRITE if self.write else 0)
                | (ADDRESS if self.address is not None else 0)
                | (INFO if self.info else 0)
                | (self.space << SPACE_SHIFT)
                | (SIZES.index(self.size) << SIZE_SHIFT)
                | (INCREMENT if self.increment else 0)
                | self.count)

    @property
    def reply_length(self) -> int:
        """Bytes this command adds to the reply (0 for a write)."""
        return 0 if self.write else self.size * self.count

    def encode(self) -> bytes:
        out = struct.pack("<H", self.word)
        if self.address is not None:
            out += struct.pack("<H", self.address)
        return out + self.data

    def describe(self) -> str:
        """One line for the packet log, e.g. ``read hm2 0x0100 4x1 inc``."""
        kind = "write" if self.write else "read"
        where = (f"{self.address:#06x}" if self.address is not None
                 else "(cont)")
        text = (f"{kind} {SPACE_NAMES.get(self.space, str(self.space))}"
                f"{' info' if self.info else ''} {where} "
                f"{self.size * 8}bit x{self.count}"
                f"{' inc' if self.increment else ''}")
        if self.write:
            text += " = " + self.data.hex()
        return text


SPACE_NAMES = {SPACE_HM2: "hm2", SPACE_ETH_CHIP: "eth-chip",
               SPACE_EEPROM: "eeprom", SPACE_FLASH: "flash",
               SPACE_TIMER: "timer", 5: "space5", SPACE_COMM: "comm",
               SPACE_BOARD: "board"}


@dataclass(frozen=True)
class Fields:
    """The fields of a command word."""

    write: bool
    has_address: bool
    info: bool
    space: int
    size: int
    increment: bool
    count: int


def decode_word(word: int) -> Fields:
    """The fields of a command word."""
    if not 0 <= word <= 0xFFFF:
        raise Lbp16Error(f"command word {word:#x} is not 16-bit")
    return Fields(write=bool(word & WRITE), has_address=bool(word & ADDRESS),
                  info=bool(word & INFO), space=(word >> SPACE_SHIFT) & 7,
                  size=SIZES[(word >> SIZE_SHIFT) & 3],
                  increment=bool(word & INCREMENT), count=word & COUNT_MASK)


#: a command as the card runs it: (write, info, space, size, increment,
#: count, address or None, data)
Raw = tuple[bool, bool, int, int, bool, int, Optional[int], bytes]


def parse(packet: bytes) -> list[Raw]:
    """The commands of a datagram as plain tuples (the card's fast path);
    :class:`Lbp16Error` if it is malformed (a truncated command, a zero
    count)."""
    out: list[Raw] = []
    i = 0
    n = len(packet)
    unpack = struct.unpack_from
    while i < n:
        if i + 2 > n:
            raise Lbp16Error(f"truncated command word at byte {i}")
        (word,) = unpack("<H", packet, i)
        i += 2
        address = None
        if word & ADDRESS:
            if i + 2 > n:
                raise Lbp16Error(f"truncated address at byte {i}")
            (address,) = unpack("<H", packet, i)
            i += 2
        count = word & COUNT_MASK
        if count == 0:
            raise Lbp16Error(f"command {word:#06x} has a zero count")
        size = SIZES[(word >> SIZE_SHIFT) & 3]
        data = b""
        write = bool(word & WRITE)
        if write:
            length = size * count
            if i + length > n:
                raise Lbp16Error(
                    f"write {word:#06x} needs {length} data bytes, "
                    f"{n - i} left")
            data = packet[i:i + length]
            i += length
        out.append((write, bool(word & INFO), (word >> SPACE_SHIFT) & 7, size,
                    bool(word & INCREMENT), count, address, data))
    return out


def decode(packet: bytes) -> list[Command]:
    """The commands of a datagram; :class:`Lbp16Error` if it is malformed
    (a truncated command, a zero count)."""
    return [Command(write=w, space=space, size=size, count=count,
                    address=address, increment=inc, info=info, data=data)
            for w, info, space, size, inc, count, address, data
            in parse(packet)]


def encode(commands: list[Command]) -> bytes:
    """A datagram of commands."""
    return b"".join(c.encode() for c in commands)


def read(space: int, address: Optional[int], count: int = 1, size: int = 4,
         increment: bool = True, info: bool = False) -> Command:
    """A read command."""
    return Command(write=False, space=space, size=size, count=count,
                   address=address, increment=increment, info=info)


def write(space: int, address: Optional[int], values: list[int],
          size: int = 4, increment: bool = True) -> Command:
    """A write command of little-endian values."""
    fmt = {1: "B", 2: "H", 4: "I", 8: "Q"}[size]
    data = struct.pack(f"<{len(values)}{fmt}", *values)
    return Command(write=True, space=space, size=size, count=len(values),
                   address=address, increment=increment, data=data)
