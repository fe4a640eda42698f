"""Board profiles: what each simulated card reports and which modules it has.

The module counts, base addresses, register counts, strides and clocks
follow the boards' standard HostMot2 firmware.  The field I/O of the
7i96S (isolated inputs and outputs) is plain GPIO here; its InM/OutM/SSR
modules, the DPLL and smart serial are not simulated.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from . import idrom
from .idrom import (
    CLOCK_HIGH,
    CLOCK_LOW,
    GPIO,
    GTAG_ENCODER,
    GTAG_IOPORT,
    GTAG_LED,
    GTAG_PWMGEN,
    GTAG_STEPGEN,
    GTAG_WATCHDOG,
    OUTPUT,
    Header,
    Module,
    Pin,
)

# the standard base addresses of the HostMot2 modules
LED_BASE = 0x0200
WATCHDOG_BASE = 0x0C00
IOPORT_BASE = 0x1000
STEPGEN_BASE = 0x2000
ENCODER_BASE = 0x3000
PWMGEN_BASE = 0x4000

# the IDROM's address in the register space (the pointer at 0x010C)
IDROM_ADDRESS = 0x0400


def _step(unit: int) -> list[Pin]:
    return [Pin(OUTPUT | 1, GTAG_STEPGEN, unit),    # step
            Pin(OUTPUT | 2, GTAG_STEPGEN, unit)]    # direction


def _dir_step(unit: int) -> list[Pin]:
    return [Pin(OUTPUT | 2, GTAG_STEPGEN, unit),    # direction
            Pin(OUTPUT | 1, GTAG_STEPGEN, unit)]    # step


def _modules(ports: int, stepgens: int, encoders: int, pwmgens: int,
             leds: int) -> list[Module]:
    mods = [Module(GTAG_WATCHDOG, 0, CLOCK_LOW, 1, WATCHDOG_BASE, 3, 0),
            Module(GTAG_IOPORT, 0, CLOCK_LOW, ports, IOPORT_BASE, 5, 0x1F)]
    if encoders:
        mods.append(Module(GTAG_ENCODER, 2, CLOCK_LOW, encoders,
                           ENCODER_BASE, 5, 0x03))
    if stepgens:
        mods.append(Module(GTAG_STEPGEN, 2, CLOCK_LOW, stepgens,
                           STEPGEN_BASE, 10, 0x1FF))
    if pwmgens:
        mods.append(Module(GTAG_PWMGEN, 0, CLOCK_HIGH, pwmgens,
                           PWMGEN_BASE, 5, 0x03))
    if leds:
        mods.append(Module(GTAG_LED, 0, CLOCK_LOW, 1, LED_BASE, 1, 0))
    return mods


@dataclass(frozen=True)
class Profile:
    """A simulated board."""

    key: str                    # the --board name
    lbp16_name: bytes           # the board name of LBP16 space 7
    description: str
    header: Header
    modules: tuple[Module, ...]
    pins: tuple[Pin, ...]
    connectors: tuple[str, ...]  # one name per I/O port
    mac: bytes                  # the Ethernet address it reports
    #: a config string with every simulated module (for hostmot2)
    config: str = ""
    #: I/O pins wired to field inputs/outputs, by name, for the docs
    notes: dict[str, str] = field(default_factory=dict)

    def module(self, gtag: int) -> Module | None:
        for m in self.modules:
            if m.gtag == gtag:
                return m
        return None

    def instances(self, gtag: int) -> int:
        m = self.module(gtag)
        return m.instances if m else 0

    def idrom_image(self) -> bytes:
        return idrom.build(self.header, list(self.modules), list(self.pins))


def _7i96s() -> Profile:
    # port 0 (TB3/TB4): 11 inputs, 6 outputs; port 1 (TB1/TB2): five
    # step/dir pairs, the encoder (A, B, index), the spindle PWM (PWM,
    # direction, enable) and one GPIO; port 2 (P1): 17 GPIO
    pins: list[Pin] = [GPIO] * 17
    for unit in range(5):
        pins += _step(unit)
    pins += [Pin(1, GTAG_ENCODER, 0), Pin(2, GTAG_ENCODER, 0),
             Pin(3, GTAG_ENCODER, 0)]
    pins += [Pin(OUTPUT | 1, GTAG_PWMGEN, 0), Pin(OUTPUT | 2, GTAG_PWMGEN, 0),
             Pin(OUTPUT | 3, GTAG_PWMGEN, 0), GPIO]
    pins += [GPIO] * 17
    header = Header(board_name=b"MESA7I96", fpga_size=20, fpga_pins=256,
                    io_ports=3, io_width=len(pins), port_width=17,
                    clock_low=100_000_000, clock_high=200_000_000)
    return Profile(
        key="7i96s", lbp16_name=b"7I96S", description="Mesa 7I96S",
        header=header, modules=tuple(_modules(3, 5, 1, 1, 1)),
        pins=tuple(pins), connectors=("TB3", "TB1", "P1"),
        mac=bytes.fromhex("00601b109601"),
        config="num_encoders=1 num_pwmgens=1 num_stepgens=5",
        notes={"inputs": "GPIO 0-10", "outputs": "GPIO 11-16",
               "stepgens": "GPIO 17-26 (step, dir per channel)",
               "encoder": "GPIO 27-29 (A, B, index)",
               "pwmgen": "GPIO 30-32 (PWM, dir, enable)"})


def _7i92() -> Profile:
    # P2 carries a 7I76 (five step/dir channels, the spindle encoder; the
    # smart serial pins are plain GPIO here); P1: 17 GPIO
    pins: list[Pin] = []
    for unit in range(5):
        pins += _dir_step(unit)
    pins += [GPIO] * 4
    pins += [Pin(3, GTAG_ENCODER, 0), Pin(2, GTAG_ENCODER, 0),
             Pin(1, GTAG_ENCODER, 0)]
    pins += [GPIO] * 17
    header = Header(board_name=b"MESA7I92", fpga_size=9, fpga_pins=144,
                    io_ports=2, io_width=len(pins), port_width=17,
                    clock_low=100_000_000, clock_high=200_000_000)
    return Profile(
        key="7i92", lbp16_name=b"7I92", description="Mesa 7I92 with a 7I76 on P2",
        header=header, modules=tuple(_modules(2, 5, 1, 0, 1)),
        pins=tuple(pins), connectors=("P2", "P1"),
        mac=bytes.fromhex("00601b109201"),
        config="num_encoders=1 num_stepgens=5",
        notes={"stepgens": "GPIO 0-9 (dir, step per channel)",
               "encoder": "GPIO 14-16 (index, B, A)",
               "gpio": "GPIO 10-13 and 17-33"})


PROFILES: dict[str, Profile] = {p.key: p for p in (_7i96s(), _7i92())}


def profile(name: str) -> Profile:
    """The profile called ``name`` (case-insensitive)."""
    try:
        return PROFILES[name.lower()]
    except KeyError:
        raise ValueError(f"unknown board {name!r}: expected one of "
                         f"{', '.join(sorted(PROFILES))}") from None
