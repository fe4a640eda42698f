"""The HostMot2 IDROM: the card's description of its firmware.

At register 0x0100 the card holds the IO cookie 0x55AACAFE, at 0x0104 the
configuration name ``HOSTMOT2`` and at 0x010C the address of the IDROM.
The IDROM starts with a header (type, offsets of the module and pin
descriptors, board name, FPGA size and pins, I/O ports and widths, the two
clock frequencies and the instance/register strides), followed by the
module descriptors (12 bytes each, a zero tag ends the list) and, at
``offset_to_pins``, one 4-byte pin descriptor per I/O pin.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

IOCOOKIE = 0x55AACAFE
COOKIE_ADDRESS = 0x0100
NAME_ADDRESS = 0x0104
IDROM_POINTER_ADDRESS = 0x010C
CONFIG_NAME = b"HOSTMOT2"
IDROM_TYPE = 3
OFFSET_TO_MODULES = 0x40
OFFSET_TO_PINS = 0x200
MAX_MODULES = 32

# module tags (GTag) of the modules the simulated card knows
GTAG_WATCHDOG = 2
GTAG_IOPORT = 3
GTAG_ENCODER = 4
GTAG_STEPGEN = 5
GTAG_PWMGEN = 6
GTAG_LED = 128
GTAG_SSERIAL = 193
GTAG_NAMES = {GTAG_WATCHDOG: "WatchDog", GTAG_IOPORT: "IOPort",
              GTAG_ENCODER: "QCount", GTAG_STEPGEN: "StepGen",
              GTAG_PWMGEN: "PWMGen", GTAG_LED: "LED",
              GTAG_SSERIAL: "SSerial"}

#: the clock tag of a module descriptor
CLOCK_LOW = 1
CLOCK_HIGH = 2

HEADER_FORMAT = "<III8s11I"
HEADER_SIZE = struct.calcsize(HEADER_FORMAT)        # 64 bytes
MODULE_FORMAT = "<BBBBHBBI"
MODULE_SIZE = struct.calcsize(MODULE_FORMAT)        # 12 bytes

#: secondary pin numbers of the pin descriptors; bit 7 marks an output
OUTPUT = 0x80


@dataclass(frozen=True)
class Header:
    """The IDROM header."""

    board_name: bytes                   # 8 bytes, e.g. b"MESA7I96"
    fpga_size: int
    fpga_pins: int
    io_ports: int
    io_width: int                       # total number of I/O pins
    port_width: int
    clock_low: int
    clock_high: int
    instance_stride0: int = 4
    instance_stride1: int = 64
    register_stride0: int = 256
    register_stride1: int = 256
    idrom_type: int = IDROM_TYPE
    offset_to_modules: int = OFFSET_TO_MODULES
    offset_to_pins: int = OFFSET_TO_PINS

    def pack(self) -> bytes:
        return struct.pack(
            HEADER_FORMAT, self.idrom_type, self.offset_to_modules,
            self.offset_to_pins, self.board_name.ljust(8, b"\0")[:8],
            self.fpga_size, self.fpga_pins, self.io_ports, self.io_width,
            self.port_width, self.clock_low, self.clock_high,
            self.instance_stride0, self.instance_stride1,
            self.register_stride0, self.register_stride1)

    @classmethod
    def unpack(cls, data: bytes) -> Header:
        (idrom_type, off_mod, off_pins, name, fpga_size, fpga_pins,
         io_ports, io_width, port_width, clock_low, clock_high, is0, is1,
         rs0, rs1) = struct.unpack_from(HEADER_FORMAT, data)
        return cls(board_name=name, fpga_size=fpga_size,
                   fpga_pins=fpga_pins, io_ports=io_ports, io_width=io_width,
                   port_width=port_width, clock_low=clock_low,
                   clock_high=clock_high, instance_stride0=is0,
                   instance_stride1=is1, register_stride0=rs0,
                   register_stride1=rs1, idrom_type=idrom_type,
                   offset_to_modules=off_mod, offset_to_pins=off_pins)


@dataclass(frozen=True)
class Module:
    """A module descriptor: ``instances`` of the module ``gtag`` whose
    ``registers`` registers start at ``base``; register ``r`` of instance
    ``i`` is at ``base + r * register_stride + i * instance_stride``.
    ``multiple`` has bit ``r`` set when register ``r`` exists per
    instance (otherwise once, for all)."""

    gtag: int
    version: int
    clock: int                          # CLOCK_LOW or CLOCK_HIGH
    instances: int
    base: int
    registers: int
    multiple: int
    register_stride_select: int = 0     # 0: register_stride0
    instance_stride_select: int = 0     # 0: instance_stride0

    def pack(self) -> bytes:
        strides = (self.register_stride_select & 0xF) | (
            (self.instance_stride_select & 0xF) << 4)
        return struct.pack(MODULE_FORMAT, self.gtag, self.version,
                           self.clock, self.instances, self.base,
                           self.registers, strides, self.multiple)

    @classmethod
    def unpack(cls, data: bytes, offset: int = 0) -> Module:
        (gtag, version, clock, instances, base, registers, strides,
         multiple) = struct.unpack_from(MODULE_FORMAT, data, offset)
        return cls(gtag=gtag, version=version, clock=clock,
                   instances=instances, base=base, registers=registers,
                   multiple=multiple, register_stride_select=strides & 0xF,
                   instance_stride_select=strides >> 4)

    @property
    def name(self) -> str:
        return GTAG_NAMES.get(self.gtag, f"gtag{self.gtag}")


@dataclass(frozen=True)
class Pin:
    """A pin descriptor: the I/O pin's secondary function, if any.

    ``sec_tag`` is the module (0: plain GPIO), ``sec_unit`` its
    instance, ``sec_pin`` the module's pin number (1-based) with
    :data:`OUTPUT` set for an output."""

    sec_pin: int = 0
    sec_tag: int = 0
    sec_unit: int = 0
    primary_tag: int = GTAG_IOPORT

    def pack(self) -> bytes:
        return bytes((self.sec_pin, self.sec_tag, self.sec_unit,
                      self.primary_tag))

    @classmethod
    def unpack(cls, data: bytes, offset: int = 0) -> Pin:
        sec_pin, sec_tag, sec_unit, primary = data[offset:offset + 4]
        return cls(sec_pin=sec_pin, sec_tag=sec_tag, sec_unit=sec_unit,
                   primary_tag=primary)

    @property
    def is_output(self) -> bool:
        return bool(self.sec_pin & OUTPUT)


GPIO = Pin()


def build(header: Header, modules: list[Module], pins: list[Pin]) -> bytes:
    """The IDROM image (header, module and pin descriptors)."""
    if len(modules) >= MAX_MODULES:
        raise ValueError(f"{len(modules)} module descriptors: at most "
                         f"{MAX_MODULES - 1}")
    if len(pins) != header.io_width:
        raise ValueError(f"{len(pins)} pin descriptors for an io_width of "
                         f"{header.io_width}")
    image = bytearray(header.offset_to_pins + 4 * len(pins))
    image[:HEADER_SIZE] = header.pack()
    at = header.offset_to_modules
    for m in modules:
        image[at:at + MODULE_SIZE] = m.pack()
        at += MODULE_SIZE
    at = header.offset_to_pins
    for p in pins:
        image[at:at + 4] = p.pack()
        at += 4
    return bytes(image)


@dataclass(frozen=True)
class Parsed:
    header: Header
    modules: list[Module]
    pins: list[Pin]


def parse(image: bytes) -> Parsed:
    """Parse an IDROM image as :func:`build` makes it (a driver's view)."""
    header = Header.unpack(image)
    modules = []
    at = header.offset_to_modules
    for _ in range(MAX_MODULES):
        m = Module.unpack(image, at)
        if m.gtag == 0:
            break
        modules.append(m)
        at += MODULE_SIZE
    pins = [Pin.unpack(image, header.offset_to_pins + 4 * i)
            for i in range(header.io_width)]
    return Parsed(header, modules, pins)
