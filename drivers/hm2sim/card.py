"""The simulated card: its LBP16 memory spaces and the HostMot2 registers,
with a physical model behind the modules.

Time is the card's clock: :meth:`Card.advance_to` moves it (the server
does it with wall time, a test may do it explicitly).  All positions are
exact integers of clock ticks and DDS units, so a run is reproducible.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from functools import partial
from typing import Callable, Optional

from . import idrom, lbp16
from .idrom import GTAG_ENCODER, GTAG_PWMGEN, GTAG_STEPGEN
from .profiles import (
    ENCODER_BASE,
    IDROM_ADDRESS,
    IOPORT_BASE,
    LED_BASE,
    PWMGEN_BASE,
    STEPGEN_BASE,
    WATCHDOG_BASE,
    Profile,
)

#: the modules whose pins the card models
MODELLED = (GTAG_ENCODER, GTAG_PWMGEN, GTAG_STEPGEN)
REG_STRIDE = 0x100
INSTANCE_STRIDE = 4
#: one step in the stepgen's DDS accumulator (the register shows bits 47..16)
STEP_UNITS = 1 << 32
#: the stepgen mode register's table mode, and the longest step table
TABLE_MODE = 3
TABLE_ENTRIES = 16
WATCHDOG_COOKIE = 0x5A
WATCHDOG_DISABLED = 0x80000000
#: LBP16 status space: the count of UDP datagrams the card received
COMM_RX_COUNT = 0x0008

# encoder control/status bits (the low half of the latch/control register)
ENC_QUAD_ERROR = 1 << 15
ENC_LATCH_ON_INDEX = 1 << 5
ENC_CLEAR_ON_INDEX = 1 << 6
ENC_INDEX_JUSTONCE = 1 << 7
ENC_INPUT_A = 1 << 1
ENC_INPUT_B = 1 << 2
ENC_INPUT_INDEX = 1 << 3
ENC_CONTROL_MASK = 0x7FF0

# the memory space descriptions of the info area (bit 13 of a command):
# name, sizes and ranges words as LBP16 describes them; the values are
# plausible, not a real card's (hm2_eth does not read them)
_SPACE_INFO = {
    lbp16.SPACE_HM2: (b"HostMot2", 0x0201, 0x1F10),
    lbp16.SPACE_EEPROM: (b"EEPROM\0\0", 0x8202, 0x0F0F),
    lbp16.SPACE_FLASH: (b"FPGAFLSH", 0x0203, 0x1E1E),
    lbp16.SPACE_TIMER: (b"Timers\0\0", 0x0204, 0x0001),
    lbp16.SPACE_COMM: (b"LBP16RW\0", 0x0206, 0x0001),
    lbp16.SPACE_BOARD: (b"LBP16RO\0", 0x0207, 0x0001),
}


def _s32(value: int) -> int:
    value &= 0xFFFFFFFF
    return value - (1 << 32) if value & 0x80000000 else value


@dataclass
class StepGen:
    rate: int = 0                   # DDS rate, signed (register 0)
    units: int = 0                  # position; STEP_UNITS per step
    mode: int = 0
    dir_setup: int = 0
    dir_hold: int = 0
    step_len: int = 0
    step_space: int = 0
    table: int = 0                  # the last table entry written
    table_max: int = 0              # the table's last index (length - 1)
    direction: bool = False         # the direction output (True: reverse)
    #: the step table, a shift register: each write to the table data
    #: register pushes an entry in at 0 (so the last written is entry 0)
    table_data: list[int] = field(
        default_factory=lambda: [0] * TABLE_ENTRIES)
    table_index: int = 0            # the table entry on the pins

    @property
    def table_length(self) -> int:
        """Entries the table mode steps through (1..16): the width
        register holds the last index, as the reference's driver writes
        it (step_type - 1)."""
        return min(self.table_max + 1, TABLE_ENTRIES)

    @property
    def table_output(self) -> int:
        """The pins' levels in table mode (bit k: module pin k + 1)."""
        return self.table_data[self.table_index]

    @property
    def steps(self) -> float:
        return self.units / STEP_UNITS


@dataclass
class Encoder:
    position: int = 0               # the simulated position, in counts
    offset: int = 0                 # position where the counter reads 0
    control: int = 0
    latch: int = 0
    change_ts: int = 0
    velocity: float = 0.0           # counts per second (driven position)
    carry: float = 0.0              # fraction of a count of the velocity
    index_period: int = 0           # counts between index pulses (0: none)
    index_level: bool = False
    events: int = 0                 # index events seen

    @property
    def count(self) -> int:
        return (self.position - self.offset) & 0xFFFF


@dataclass
class Coupling:
    """An encoder on the axis of a stepgen (positions of the world)."""

    encoder: int
    stepgen: int
    counts_per_step: float
    origin_steps: float
    origin_counts: int


@dataclass
class Switch:
    """A switch on a stepgen's axis, wired to an input pin: on when the
    axis is at or beyond ``at`` steps (above it, or below it); the pin
    then reads ``on_level``, otherwise the opposite."""

    pin: int
    stepgen: int
    at: float
    above: bool = True
    on_level: bool = True


@dataclass
class Watchdog:
    timeout: int = WATCHDOG_DISABLED | 0x7FFFFFFF
    pet_at: int = 0                 # clock tick of the last pet/timer write
    bitten: bool = False
    bites: int = 0


@dataclass
class Registers:
    """Plain storage of the registers without a model (master rates)."""

    values: dict[int, int] = field(default_factory=dict)


class Card:
    """One simulated HostMot2 Ethernet card (not thread-safe: the server
    serialises access with its lock)."""

    def __init__(self, profile: Profile) -> None:
        self.profile = profile
        self.clock = profile.header.clock_low
        self.idrom = profile.idrom_image()
        self.reset()

    # --- state -------------------------------------------------------
    def reset(self) -> None:
        """Power-on state of the card and of its world (no switches, axes
        at 0)."""
        p = self.profile
        self.ticks = 0                  # clock_low ticks since power-on
        self.time = 0.0
        nports = p.header.io_ports
        self.port_width = p.header.port_width
        self.npins = p.header.io_width
        self.data = [0] * nports
        self.ddr = [0] * nports
        self.alt = [0] * nports
        self.open_drain = [0] * nports
        self.invert = [0] * nports
        width_mask = (1 << self.port_width) - 1
        # the field levels of the pins, a bit mask per port (pull-ups: 1)
        self.field = [width_mask] * nports
        # per port, the pins whose level a module makes: (pin, bit)
        self._module_pins: list[list[tuple[int, int]]] = [
            [] for _ in range(nports)]
        for i, d in enumerate(p.pins):
            if d.sec_tag in MODELLED:
                port, bit = divmod(i, self.port_width)
                self._module_pins[port].append((i, bit))
        self.stepgens = [StepGen() for _ in range(p.instances(GTAG_STEPGEN))]
        self.encoders = [Encoder() for _ in range(p.instances(GTAG_ENCODER))]
        npwm = p.instances(GTAG_PWMGEN)
        self.pwm_value = [0] * npwm
        self.pwm_mode = [0] * npwm
        self.pwm_enable = 0
        self.watchdog = Watchdog()
        self.leds = 0
        self.misc = Registers()
        self.couplings: list[Coupling] = []
        self.switches: list[Switch] = []
        self.axis_offset = [0.0] * len(self.stepgens)
        self.address = [0] * 8           # current address of each space
        self.eeprom = bytearray(256)
        self.eeprom[2:8] = p.mac[::-1]   # the MAC, last byte first
        self.eeprom[0x20:0x24] = bytes((2, 7, 96, 10))   # 10.96.7.2
        self.ram = {lbp16.SPACE_TIMER: bytearray(256),
                    lbp16.SPACE_COMM: bytearray(256)}
        self.rx_packets = 0
        self._build_maps()

    def power_cycle(self) -> None:
        """The card powers off and on: its registers start again (the
        stepgen accumulators and encoder counts read 0), the world stays
        (axis and encoder positions, field inputs, switches, couplings,
        index pulses)."""
        axes = [self.axis_steps(n) for n in range(len(self.stepgens))]
        field = list(self.field)
        encoders = self.encoders
        couplings, switches = self.couplings, self.switches
        self.reset()
        self.axis_offset = axes
        self.field = field
        for old, new in zip(encoders, self.encoders):
            new.position = new.offset = old.position
            new.velocity, new.carry = old.velocity, old.carry
            new.index_period = old.index_period
        self.couplings, self.switches = couplings, switches
        self._build_maps()

    def axis_steps(self, n: int) -> float:
        """The position of stepgen ``n``'s axis, in steps (the world's:
        it survives a power cycle of the card)."""
        return self.axis_offset[n] + self.stepgens[n].units / STEP_UNITS

    def add_switch(self, switch: Switch) -> None:
        if not 0 <= switch.pin < self.npins:
            raise IndexError(f"I/O pin {switch.pin}: the {self.profile.key} "
                             f"has pins 0..{self.npins - 1}")
        if not 0 <= switch.stepgen < len(self.stepgens):
            raise IndexError(f"stepgen {switch.stepgen}: the "
                             f"{self.profile.key} has {len(self.stepgens)}")
        self.switches.append(switch)
        self._build_maps()

    # --- time --------------------------------------------------------
    def advance_to(self, seconds: float) -> None:
        """Move the card's clock to ``seconds`` since power-on."""
        if seconds <= self.time:
            return
        ticks = int(seconds * self.clock)
        self.time = seconds
        if ticks <= self.ticks:
            return
        wd = self.watchdog
        if not wd.bitten and not wd.timeout & WATCHDOG_DISABLED:
            deadline = wd.pet_at + wd.timeout
            if ticks > deadline:
                # run up to the bite, then bite
                self._run_to(deadline)
                self.bite()
        self._run_to(ticks)

    def _run_to(self, ticks: int) -> None:
        delta = ticks - self.ticks
        if delta <= 0:
            return
        for sg in self.stepgens:
            if sg.rate:
                before = sg.units // STEP_UNITS
                sg.units += sg.rate * delta
                sg.direction = sg.rate < 0
                if (sg.mode & 3) == TABLE_MODE:
                    # each step moves one entry, forward or back
                    sg.table_index = ((sg.table_index + sg.units // STEP_UNITS
                                       - before) % sg.table_length)
        # the encoders move at the end of the interval (their timestamps)
        self.ticks = ticks
        for n, enc in enumerate(self.encoders):
            if enc.velocity:
                enc.carry += enc.velocity * delta / self.clock
                whole = int(enc.carry)
                if whole:
                    enc.carry -= whole
                    # the last count came |carry| counts ago
                    ago = int(abs(enc.carry / enc.velocity) * self.clock)
                    self._move_encoder(n, enc.position + whole,
                                       max(ticks - ago, ticks - delta))
        for c in self.couplings:
            steps = self.axis_steps(c.stepgen) - c.origin_steps
            self._move_encoder(c.encoder, c.origin_counts
                               + round(steps * c.counts_per_step))

    def bite(self) -> None:
        """The watchdog bites: outputs to their safe state."""
        wd = self.watchdog
        wd.bitten = True
        wd.bites += 1
        self.ddr[:] = [0] * len(self.ddr)   # every pin an input (pulled up)
        for sg in self.stepgens:
            sg.rate = 0
        self.pwm_value[:] = [0] * len(self.pwm_value)
        self.pwm_enable = 0

    # --- encoders ----------------------------------------------------
    def _timestamp(self, ticks: Optional[int] = None) -> int:
        div = self.misc.values.get(ENCODER_BASE + 2 * REG_STRIDE, 0) & 0xFFFF
        if ticks is None:
            ticks = self.ticks
        return (ticks // (div + 2)) & 0xFFFF

    def _move_encoder(self, n: int, position: int,
                      at: Optional[int] = None) -> None:
        """Move encoder ``n``; ``at``: the clock tick of its last count
        (default now)."""
        enc = self.encoders[n]
        old = enc.position
        if position == old:
            return
        if enc.index_period:
            # index positions crossed on the way, in order
            p = enc.index_period
            if position > old:
                first, last, step = (old // p) + 1, position // p, 1
            else:
                first, last, step = (old - 1) // p, -(-position // p), -1
            for k in range(first, last + step, step):
                if (position - k * p) * step < 0:
                    break
                enc.position = k * p
                self._index(n)
        enc.position = position
        enc.change_ts = self._timestamp(at)

    def _index(self, n: int) -> None:
        enc = self.encoders[n]
        enc.events += 1
        if enc.control & ENC_LATCH_ON_INDEX:
            enc.latch = enc.count
        if enc.control & ENC_CLEAR_ON_INDEX:
            enc.offset = enc.position
        if enc.control & ENC_INDEX_JUSTONCE:
            enc.control &= ~(ENC_LATCH_ON_INDEX | ENC_CLEAR_ON_INDEX)

    def pulse_index(self, n: int) -> None:
        """An index pulse of encoder ``n`` at its current position."""
        self._index(n)

    def set_encoder(self, n: int, position: int) -> None:
        self._move_encoder(n, int(position))

    # --- GPIO --------------------------------------------------------
    def _module_output(self, pin: int) -> bool:
        d = self.profile.pins[pin]
        num = d.sec_pin & 0x7F
        if d.sec_tag == GTAG_STEPGEN and d.sec_unit < len(self.stepgens):
            sg = self.stepgens[d.sec_unit]
            if (sg.mode & 3) == TABLE_MODE:
                return bool(sg.table_output >> (num - 1) & 1)
            return sg.direction if num == 2 else False
        if d.sec_tag == GTAG_PWMGEN and d.sec_unit < len(self.pwm_value):
            on = bool(self.pwm_enable >> d.sec_unit & 1)
            if num == 1:
                return on and self.pwm_duty(d.sec_unit) > 0
            if num == 3:
                return not on               # /enable, active low
            return False
        return False

    def _encoder_input(self, pin: int) -> Optional[bool]:
        d = self.profile.pins[pin]
        if d.sec_tag != GTAG_ENCODER or d.sec_unit >= len(self.encoders):
            return None
        enc = self.encoders[d.sec_unit]
        phase = enc.position & 3            # A leads B counting up
        num = d.sec_pin & 0x7F
        if num == 1:
            return phase in (1, 2)
        if num == 2:
            return phase in (2, 3)
        if num == 3:
            return enc.index_level
        return None

    def set_input(self, pin: int, level: bool) -> None:
        port, bit = divmod(pin, self.port_width)
        if level:
            self.field[port] |= 1 << bit
        else:
            self.field[port] &= ~(1 << bit)

    def port_levels(self, port: int) -> int:
        """The levels of a port's pins as the outside world sees them."""
        field = self.field[port]
        for bit, sw in self._switches[port]:
            axis = self.axis_steps(sw.stepgen)
            on = axis >= sw.at if sw.above else axis <= sw.at
            if on == sw.on_level:
                field |= 1 << bit
            else:
                field &= ~(1 << bit)
        module = 0
        for pin, bit in self._module_pins[port]:
            enc = self._encoder_input(pin)
            if enc is not None:
                field = field | (1 << bit) if enc else field & ~(1 << bit)
            elif self._module_output(pin):
                module |= 1 << bit
        ddr, alt, od = self.ddr[port], self.alt[port], self.open_drain[port]
        driven = ((self.data[port] & ~alt) | (module & alt)) ^ self.invert[port]
        # an open-drain output driven high is released: the field decides
        out = (driven & ~od) | (driven & od & field)
        return (field & ~ddr) | (out & ddr)

    def pin_level(self, pin: int) -> bool:
        """The level of I/O pin ``pin`` as the outside world sees it."""
        port, bit = divmod(pin, self.port_width)
        return bool(self.port_levels(port) >> bit & 1)

    def is_output(self, pin: int) -> bool:
        port, bit = divmod(pin, self.port_width)
        return bool(self.ddr[port] >> bit & 1)

    # --- PWM ---------------------------------------------------------
    def pwm_duty(self, n: int) -> float:
        """Duty cycle 0..1 of PWM generator ``n`` (0 when disabled)."""
        if not self.pwm_enable >> n & 1:
            return 0.0
        bits = 9 + (self.pwm_mode[n] & 3)
        value = (self.pwm_value[n] >> 16) & ((1 << bits) - 1)
        return value / ((1 << bits) - 1)

    # --- the register space ------------------------------------------
    def _build_maps(self) -> None:
        """The register map: constants (cookie, name, IDROM) and a reader
        and a writer per module register address."""
        const: dict[int, int] = {
            idrom.COOKIE_ADDRESS: idrom.IOCOOKIE,
            idrom.IDROM_POINTER_ADDRESS: IDROM_ADDRESS}
        for at in range(0, 8, 4):
            const[idrom.NAME_ADDRESS + at] = int.from_bytes(
                idrom.CONFIG_NAME[at:at + 4], "little")
        image = self.idrom + bytes(-len(self.idrom) % 4)
        for at in range(0, len(image), 4):
            const[IDROM_ADDRESS + at] = int.from_bytes(image[at:at + 4],
                                                       "little")
        rd: dict[int, Callable[[], int]] = {}
        wr: dict[int, Callable[[int], None]] = {}

        def reg(base: int, r: int, i: int = 0) -> int:
            return base + r * REG_STRIDE + i * INSTANCE_STRIDE

        def attr(address: int, obj: object, name: str,
                 writable: bool = True) -> None:
            rd[address] = lambda: int(getattr(obj, name))
            if writable:
                wr[address] = lambda v: setattr(obj, name, v)

        def item(address: int, lst: list[int], i: int, mask: int,
                 readable: bool = True) -> None:
            if readable:
                rd[address] = lambda: lst[i]

            def put(v: int) -> None:
                lst[i] = v & mask
            wr[address] = put

        def store(address: int) -> None:
            values = self.misc.values
            rd[address] = lambda: values.get(address, 0)

            def put(v: int) -> None:
                values[address] = v
            wr[address] = put

        attr(LED_BASE, self, "leds")
        attr(reg(WATCHDOG_BASE, 0), self.watchdog, "timeout", False)
        attr(reg(WATCHDOG_BASE, 1), self.watchdog, "bitten", False)
        wr[reg(WATCHDOG_BASE, 0)] = self._wd_timer
        wr[reg(WATCHDOG_BASE, 1)] = self._wd_status
        wr[reg(WATCHDOG_BASE, 2)] = self._wd_pet
        mask = (1 << self.port_width) - 1
        full = 0xFFFFFFFF
        for port in range(len(self.data)):
            rd[reg(IOPORT_BASE, 0, port)] = partial(self.port_levels, port)
            for r, lst in enumerate((self.data, self.ddr, self.alt,
                                     self.open_drain, self.invert)):
                item(reg(IOPORT_BASE, r, port), lst, port, mask, r > 0)
        for n, sg in enumerate(self.stepgens):
            rd[reg(STEPGEN_BASE, 0, n)] = partial(self._sg_get_rate, sg)
            wr[reg(STEPGEN_BASE, 0, n)] = partial(self._sg_rate, sg)
            rd[reg(STEPGEN_BASE, 1, n)] = partial(self._sg_get_acc, sg)
            wr[reg(STEPGEN_BASE, 1, n)] = partial(self._sg_acc, sg)
            for r, name in enumerate(("mode", "dir_setup", "dir_hold",
                                      "step_len", "step_space", "table",
                                      "table_max"), 2):
                attr(reg(STEPGEN_BASE, r, n), sg, name)
            wr[reg(STEPGEN_BASE, 7, n)] = partial(self._sg_table, sg)
        if self.stepgens:
            store(reg(STEPGEN_BASE, 9))                 # master rate (DDS)
        for n, enc in enumerate(self.encoders):
            rd[reg(ENCODER_BASE, 0, n)] = partial(self._enc_count, enc)
            wr[reg(ENCODER_BASE, 0, n)] = partial(self._enc_clear, enc)
            rd[reg(ENCODER_BASE, 1, n)] = partial(self._encoder_status, n)
            wr[reg(ENCODER_BASE, 1, n)] = partial(self._enc_control, enc)
        if self.encoders:
            store(reg(ENCODER_BASE, 2))                 # timestamp divider
            rd[reg(ENCODER_BASE, 3)] = self._timestamp  # timestamp count
            store(reg(ENCODER_BASE, 4))                 # filter rate
        for n in range(len(self.pwm_value)):
            rd[reg(PWMGEN_BASE, 0, n)] = partial(self.pwm_value.__getitem__, n)
            wr[reg(PWMGEN_BASE, 0, n)] = partial(self._pwm_set, n)
            item(reg(PWMGEN_BASE, 1, n), self.pwm_mode, n, full)
        if self.pwm_value:
            store(reg(PWMGEN_BASE, 2))                  # PWM master rate
            store(reg(PWMGEN_BASE, 3))                  # PDM master rate
            attr(reg(PWMGEN_BASE, 4), self, "pwm_enable", False)
            wr[reg(PWMGEN_BASE, 4)] = self._pwm_enable
        self._const, self._rd, self._wr = const, rd, wr
        self._switches: list[list[tuple[int, Switch]]] = [
            [] for _ in range(len(self.data))]
        for sw in self.switches:
            port, bit = divmod(sw.pin, self.port_width)
            self._switches[port].append((bit, sw))

    def _wd_timer(self, value: int) -> None:
        self.watchdog.timeout = value
        self.watchdog.pet_at = self.ticks

    def _wd_status(self, value: int) -> None:
        wd = self.watchdog
        wd.bitten = bool(value & 1)
        if not wd.bitten:
            wd.pet_at = self.ticks

    def _wd_pet(self, value: int) -> None:
        if value >> 24 == WATCHDOG_COOKIE:
            self.watchdog.pet_at = self.ticks

    def _sg_rate(self, sg: StepGen, value: int) -> None:
        sg.rate = 0 if self.watchdog.bitten else _s32(value)

    @staticmethod
    def _sg_table(sg: StepGen, value: int) -> None:
        sg.table = value & 0xFF
        sg.table_data[1:] = sg.table_data[:-1]
        sg.table_data[0] = sg.table

    @staticmethod
    def _sg_get_rate(sg: StepGen) -> int:
        return sg.rate & 0xFFFFFFFF

    @staticmethod
    def _sg_get_acc(sg: StepGen) -> int:
        return (sg.units >> 16) & 0xFFFFFFFF

    @staticmethod
    def _sg_acc(sg: StepGen, value: int) -> None:
        sg.units = value << 16

    @staticmethod
    def _enc_count(enc: Encoder) -> int:
        return enc.count | (enc.change_ts << 16)

    @staticmethod
    def _enc_clear(enc: Encoder, value: int) -> None:
        enc.offset = enc.position           # any write clears the count

    @staticmethod
    def _enc_control(enc: Encoder, value: int) -> None:
        enc.control = value & ENC_CONTROL_MASK

    def _pwm_set(self, n: int, value: int) -> None:
        self.pwm_value[n] = 0 if self.watchdog.bitten else value

    def _pwm_enable(self, value: int) -> None:
        self.pwm_enable = 0 if self.watchdog.bitten else value

    def read_register(self, address: int) -> int:
        """The 32-bit register at byte ``address`` (4-aligned)."""
        value = self._const.get(address)
        if value is not None:
            return value
        f = self._rd.get(address)
        return f() if f is not None else 0

    def _encoder_status(self, n: int) -> int:
        enc = self.encoders[n]
        value = (enc.latch << 16) | (enc.control & ENC_CONTROL_MASK)
        phase = enc.position & 3
        if phase in (1, 2):
            value |= ENC_INPUT_A
        if phase in (2, 3):
            value |= ENC_INPUT_B
        if enc.index_level:
            value |= ENC_INPUT_INDEX
        return value

    def write_register(self, address: int, value: int) -> None:
        """Write the 32-bit register at byte ``address`` (writes where
        there is no register are ignored, as the card does)."""
        f = self._wr.get(address)
        if f is not None:
            f(value & 0xFFFFFFFF)

    # --- LBP16 -------------------------------------------------------
    def _space_read(self, space: int, address: int, size: int) -> bytes:
        if space == lbp16.SPACE_HM2:
            base = address & ~3
            words = b"".join(
                struct.pack("<I", self.read_register(a))
                for a in range(base, address + size, 4))
            at = address - base
            return words[at:at + size]
        if space == lbp16.SPACE_EEPROM:
            return bytes(self.eeprom[address:address + size]).ljust(size, b"\0")
        if space == lbp16.SPACE_BOARD:
            name = self.profile.lbp16_name.ljust(16, b"\0")
            return name[address:address + size].ljust(size, b"\0")
        if space == lbp16.SPACE_COMM and address == COMM_RX_COUNT:
            return (self.rx_packets & 0xFFFF).to_bytes(8, "little")[:size]
        if space in (lbp16.SPACE_TIMER, lbp16.SPACE_COMM):
            ram = self.ram[space]
            return bytes(ram[address:address + size]).ljust(size, b"\0")
        return bytes(size)

    def _space_write(self, space: int, address: int, data: bytes) -> None:
        if space in (lbp16.SPACE_TIMER, lbp16.SPACE_COMM):
            self.ram[space][address:address + len(data)] = data
            del self.ram[space][256:]
            return
        if space != lbp16.SPACE_HM2:
            return                          # read-only here
        size = len(data)
        if size == 4 and not address & 3:
            self.write_register(address, int.from_bytes(data, "little"))
            return
        base = address & ~3
        for a in range(base, address + size, 4):
            word = bytearray(struct.pack("<I", self.read_register(a)))
            for i in range(4):
                j = a + i - address
                if 0 <= j < size:
                    word[i] = data[j]
            self.write_register(a, int.from_bytes(word, "little"))

    def _info(self, space: int, address: int, size: int) -> bytes:
        name, sizes, ranges = _SPACE_INFO.get(space, (b"\0" * 8, 0, 0))
        area = struct.pack("<HHHH", 0x5A00 | space, sizes, ranges,
                           self.address[space] & 0xFFFF) + name
        return area[address:address + size].ljust(size, b"\0")

    def execute(self, commands: list[lbp16.Raw]) -> bytes:
        """Run the commands of one datagram (:func:`lbp16.parse`); the
        reply data."""
        self.rx_packets += 1
        reply = bytearray()
        read_register = self.read_register
        for write, info, space, size, inc, count, address, data in commands:
            if address is None:
                address = self.address[space]
            step = size if inc else 0
            if (space == lbp16.SPACE_HM2 and size == 4 and not info
                    and not address & 3):
                if write:
                    values = struct.unpack(f"<{count}I", data)
                    for i in range(count):
                        self.write_register((address + i * step) & 0xFFFF,
                                            values[i])
                else:
                    reply += struct.pack(
                        f"<{count}I", *[read_register(
                            (address + i * step) & 0xFFFF)
                            for i in range(count)])
            else:
                for i in range(count):
                    at = (address + i * step) & 0xFFFF
                    if write:
                        if not info:
                            self._space_write(
                                space, at, data[i * size:(i + 1) * size])
                    elif info:
                        reply += self._info(space, at, size)
                    else:
                        reply += self._space_read(space, at, size)
            self.address[space] = (address + count * step) & 0xFFFF
        return bytes(reply)
