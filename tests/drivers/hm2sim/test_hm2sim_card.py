"""The registers of the simulated card and the model behind them."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from halsdk.drivers.hm2sim import lbp16, profile
from halsdk.drivers.hm2sim.card import (
    ENC_CLEAR_ON_INDEX,
    ENC_INDEX_JUSTONCE,
    ENC_LATCH_ON_INDEX,
    Card,
)

CLOCK = 100_000_000
RATE = 0x2000
ACCUM = 0x2100
ENC_COUNT = 0x3000
ENC_CONTROL = 0x3100
PORT_DATA = 0x1000
PORT_DDR = 0x1100
PORT_ALT = 0x1200
PORT_OD = 0x1300
PORT_INV = 0x1400
WD_TIMER = 0x0C00
WD_STATUS = 0x0D00
WD_PET = 0x0E00
PWM_VALUE = 0x4000
PWM_MODE = 0x4100
PWM_ENABLE = 0x4400


@pytest.fixture
def card() -> Card:
    return Card(profile("7i96s"))


def rd(card: Card, address: int) -> int:
    (value,) = struct.unpack("<I", card.execute(lbp16.parse(lbp16.encode(
        [lbp16.read(lbp16.SPACE_HM2, address)]))))
    return value


def wr(card: Card, address: int, *values: int) -> None:
    card.execute(lbp16.parse(lbp16.encode(
        [lbp16.write(lbp16.SPACE_HM2, address, list(values))])))


def rate_of(steps_per_second: float) -> int:
    return round(steps_per_second * 2**32 / CLOCK) & 0xFFFFFFFF


@given(st.integers(-200_000, 200_000), st.integers(1, 2000))
@settings(max_examples=50, deadline=None)
def test_stepgen_rate_moves_the_axis(sps: int, millis: int) -> None:
    card = Card(profile("7i96s"))
    wr(card, RATE + 4, rate_of(sps))
    card.advance_to(millis / 1000)
    rate = rate_of(sps)
    rate -= (rate >> 31) << 32
    ticks = int(millis / 1000 * CLOCK)
    assert card.stepgens[1].units == rate * ticks        # exact DDS
    # within the rate's resolution (one LSB is CLOCK / 2**32 steps/s)
    lsb = CLOCK / 2**32
    assert abs(card.stepgens[1].steps - sps * millis / 1000) <= \
        lsb * millis / 1000
    assert card.stepgens[0].steps == 0
    # the accumulator register: position in 1/65536 steps (bits 47..16)
    acc = rd(card, ACCUM + 4)
    assert acc == (card.stepgens[1].units >> 16) & 0xFFFFFFFF


def test_stepgen_timing_registers_are_stored(card: Card) -> None:
    for reg, value in ((0x2200, 1), (0x2300, 0x111), (0x2400, 0x222),
                       (0x2500, 0x333), (0x2600, 0x444)):
        wr(card, reg + 8, value)
        assert rd(card, reg + 8) == value
        assert rd(card, reg + 4) == 0
    sg = card.stepgens[2]
    assert (sg.mode, sg.dir_setup, sg.dir_hold, sg.step_len,
            sg.step_space) == (1, 0x111, 0x222, 0x333, 0x444)


@given(st.lists(st.integers(-40_000, 40_000), min_size=1, max_size=20))
@settings(max_examples=50, deadline=None)
def test_encoder_count_follows_the_position(positions: list[int]) -> None:
    card = Card(profile("7i96s"))
    for p in positions:
        card.set_encoder(0, p)
        assert rd(card, ENC_COUNT) & 0xFFFF == p & 0xFFFF
    # any write clears the count
    wr(card, ENC_COUNT, 0)
    assert rd(card, ENC_COUNT) & 0xFFFF == 0
    card.set_encoder(0, positions[-1] + 5)
    assert rd(card, ENC_COUNT) & 0xFFFF == 5


def test_encoder_inputs_follow_quadrature(card: Card) -> None:
    seen = []
    for p in range(5):
        card.set_encoder(0, p)
        status = rd(card, ENC_CONTROL)
        seen.append(((status >> 1) & 1, (status >> 2) & 1))
        # the A and B pins (I/O 27, 28) read the same
        port1 = rd(card, PORT_DATA + 4)
        assert (port1 >> 10 & 1, port1 >> 11 & 1) == seen[-1]
    assert seen == [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0)]


def test_index_latches_and_clears_once(card: Card) -> None:
    card.encoders[0].index_period = 1000
    card.set_encoder(0, 250)
    wr(card, ENC_CONTROL, ENC_LATCH_ON_INDEX | ENC_CLEAR_ON_INDEX
       | ENC_INDEX_JUSTONCE)
    card.set_encoder(0, 1300)           # crosses the index at 1000
    status = rd(card, ENC_CONTROL)
    assert status >> 16 == 1000         # the count latched at the index
    assert not status & (ENC_LATCH_ON_INDEX | ENC_CLEAR_ON_INDEX)
    assert rd(card, ENC_COUNT) & 0xFFFF == 300
    card.set_encoder(0, 2100)           # the next index: just once
    assert rd(card, ENC_COUNT) & 0xFFFF == 1100
    assert card.encoders[0].events == 2


def test_index_backwards_and_by_pulse(card: Card) -> None:
    card.encoders[0].index_period = 100
    card.set_encoder(0, 50)
    wr(card, ENC_CONTROL, ENC_CLEAR_ON_INDEX)
    card.set_encoder(0, -30)            # crosses 0 going down
    assert rd(card, ENC_COUNT) & 0xFFFF == (-30) & 0xFFFF
    wr(card, ENC_CONTROL, ENC_LATCH_ON_INDEX)
    card.pulse_index(0)
    assert rd(card, ENC_CONTROL) >> 16 == (-30) & 0xFFFF


def test_gpio_both_ways(card: Card) -> None:
    assert rd(card, PORT_DATA) == 0x1FFFF       # inputs pulled up
    card.set_input(3, False)
    assert rd(card, PORT_DATA) == 0x1FFFF & ~(1 << 3)
    wr(card, PORT_DDR, 1 << 11 | 1 << 12)
    wr(card, PORT_DATA, 1 << 11)
    assert card.pin_level(11) and not card.pin_level(12)
    wr(card, PORT_INV, 1 << 11 | 1 << 12)
    assert not card.pin_level(11) and card.pin_level(12)
    # open drain: driven high releases the pin to its field level
    wr(card, PORT_OD, 1 << 12)
    card.set_input(12, False)
    assert not card.pin_level(12)
    card.set_input(12, True)
    assert card.pin_level(12)
    assert rd(card, PORT_DDR) == 1 << 11 | 1 << 12
    assert rd(card, PORT_DATA) >> 3 & 1 == 0


def test_alt_source_pins_show_the_module(card: Card) -> None:
    # stepgen 0's direction pin (I/O 18) shows the direction of motion
    wr(card, PORT_DDR + 4, 0x3FF)
    wr(card, PORT_ALT + 4, 0x3FF)
    wr(card, RATE, rate_of(-1000))
    card.advance_to(0.01)
    assert card.pin_level(18)
    wr(card, RATE, rate_of(1000))
    card.advance_to(0.02)
    assert not card.pin_level(18)


def test_pwm_duty(card: Card) -> None:
    wr(card, PWM_MODE, 3)                       # 12 bits
    wr(card, PWM_VALUE, 2047 << 16)
    assert card.pwm_duty(0) == 0.0              # not enabled
    wr(card, PWM_ENABLE, 1)
    assert card.pwm_duty(0) == pytest.approx(2047 / 4095)


def test_watchdog_bites_into_the_safe_state(card: Card) -> None:
    wr(card, PORT_DDR, 1 << 11)
    wr(card, PORT_DATA, 0)
    wr(card, RATE, rate_of(5000))
    wr(card, PWM_VALUE, 100 << 16)
    wr(card, PWM_ENABLE, 1)
    wr(card, WD_TIMER, CLOCK // 100)            # 10 ms
    for t in range(1, 6):                       # petted every 5 ms: fine
        card.advance_to(t * 0.005)
        wr(card, WD_PET, 0x5A000000)
    assert rd(card, WD_STATUS) == 0
    assert not card.pin_level(11)
    card.advance_to(0.025 + 0.0099)
    assert rd(card, WD_STATUS) == 0
    before = card.stepgens[0].steps
    card.advance_to(0.2)                        # no pet for 175 ms
    assert rd(card, WD_STATUS) & 1
    # it bit 10 ms after the last pet: the axis stopped there
    assert card.stepgens[0].steps == pytest.approx(
        before + 5000 * 0.0001, abs=1e-3)
    assert card.pin_level(11)                   # an input again: pulled up
    assert rd(card, PORT_DDR) == 0
    assert card.pwm_duty(0) == 0
    wr(card, RATE, rate_of(5000))               # ignored while bitten
    card.advance_to(0.3)
    assert card.stepgens[0].rate == 0
    wr(card, WD_STATUS, 0)                      # the driver resets it
    assert rd(card, WD_STATUS) == 0
    wr(card, RATE, rate_of(5000))
    assert card.stepgens[0].rate != 0


def test_a_pet_needs_the_cookie(card: Card) -> None:
    wr(card, WD_TIMER, CLOCK // 1000)           # 1 ms
    card.advance_to(0.0008)
    wr(card, WD_PET, 0x12345678)                # not a pet
    card.advance_to(0.0012)
    assert card.watchdog.bitten


def test_watchdog_disabled_by_the_top_bit(card: Card) -> None:
    wr(card, WD_TIMER, 0x80000000 | 10)
    card.advance_to(5.0)
    assert not card.watchdog.bitten


def test_leds_and_unknown_registers(card: Card) -> None:
    wr(card, 0x0200, 0xA0000000)
    assert rd(card, 0x0200) == 0xA0000000
    wr(card, 0x7000, 1234)                      # no module there
    assert rd(card, 0x7000) == 0


def test_spaces_the_reference_reads(card: Card) -> None:
    mac, name = card.execute(lbp16.parse(bytes.fromhex("83490200"))), \
        card.execute(lbp16.parse(bytes.fromhex("885d0000")))
    assert mac == bytes.fromhex("00601b109601")[::-1]
    assert name == b"7I96S".ljust(16, b"\0")
    # the scratch registers echo, the status space counts datagrams
    reply = card.execute(lbp16.parse(bytes.fromhex(
        "0159080082d110004000000084511000")))
    count, seq, _, _, _ = struct.unpack("<5H", reply)
    assert seq == 0x40
    assert count == card.rx_packets == 3


def test_without_address_a_command_continues(card: Card) -> None:
    first = card.execute(lbp16.parse(lbp16.encode(
        [lbp16.read(lbp16.SPACE_HM2, 0x0100, 2)])))
    rest = card.execute(lbp16.parse(lbp16.encode(
        [lbp16.read(lbp16.SPACE_HM2, None, 2)])))
    assert first + rest == struct.pack("<I", 0x55AACAFE) + b"HOSTMOT2" + \
        struct.pack("<I", 0x400)


def test_reset_is_power_on(card: Card) -> None:
    wr(card, RATE, rate_of(1000))
    card.advance_to(1.0)
    card.set_input(0, False)
    card.reset()
    assert card.stepgens[0].steps == 0 and card.stepgens[0].rate == 0
    assert card.pin_level(0)


def test_encoder_timestamp_of_the_last_count(card: Card) -> None:
    wr(card, 0x3200, 98)                        # timestamps at 1 MHz
    card.encoders[0].velocity = 1000.0          # counts per second
    card.advance_to(0.0105)
    value = rd(card, ENC_COUNT)
    assert value & 0xFFFF == 10
    # the last count came at 10 ms; the timestamp counter is at 10.5 ms
    assert value >> 16 == 10_000
    assert rd(card, 0x3300) == 10_500
    card.set_encoder(0, 20)                     # set now: stamped now
    assert rd(card, ENC_COUNT) >> 16 == 10_500


STEP_MODE = 0x2200
STEP_TABLE = 0x2700
STEP_TABLE_MAX = 0x2800


def load_table(card: Card, n: int, table: list[int]) -> None:
    """Table mode on stepgen ``n`` as the reference's driver sets it: the
    mode is the step type (the length) with its low bits 3, the width the
    last index, the entries written last first."""
    wr(card, STEP_MODE + 4 * n, len(table) | 3)
    wr(card, STEP_TABLE_MAX + 4 * n, len(table) - 1)
    for entry in reversed(table):
        wr(card, STEP_TABLE + 4 * n, entry)


def test_table_data_is_a_shift_register(card: Card) -> None:
    load_table(card, 1, [0x1, 0x2, 0x4, 0x8])
    sg = card.stepgens[1]
    assert sg.table_data[:4] == [0x1, 0x2, 0x4, 0x8]
    assert sg.table_length == 4 and sg.table_output == 0x1
    wr(card, STEP_TABLE + 4, 0x1FF)             # one more: a byte pushed in
    assert sg.table_data[:5] == [0xFF, 0x1, 0x2, 0x4, 0x8]
    assert card.stepgens[0].table_data == [0] * 16


@given(st.lists(st.integers(0, 0xFF), min_size=3, max_size=16),
       st.lists(st.integers(-3000, 3000), min_size=1, max_size=6))
@settings(max_examples=40, deadline=None)
def test_table_mode_steps_through_the_table(table: list[int],
                                           speeds: list[int]) -> None:
    card = Card(profile("7i96s"))
    load_table(card, 0, table)
    sg = card.stepgens[0]
    step_pin, dir_pin = (
        next(i for i, d in enumerate(card.profile.pins)
             if d.sec_tag == 5 and d.sec_unit == 0 and d.sec_pin & 0x7F == k)
        for k in (1, 2))
    wr(card, PORT_DDR, 0xFFFFFF)
    wr(card, PORT_ALT, 0xFFFFFF)
    wr(card, PORT_DDR + 4, 0xFFFFFF)
    wr(card, PORT_ALT + 4, 0xFFFFFF)
    for k, sps in enumerate(speeds):           # 10 ms at each speed
        wr(card, RATE, rate_of(sps))
        card.advance_to((k + 1) / 100)
        steps = sg.units // 2**32              # whole steps from 0
        assert sg.table_index == steps % len(table)
        entry = table[sg.table_index]
        assert sg.table_output == entry
        # the stepgen's pins show the entry's bits 0 and 1
        assert card.pin_level(step_pin) == bool(entry & 1)
        assert card.pin_level(dir_pin) == bool(entry & 2)
    # the position still counts steps
    assert rd(card, ACCUM) == (sg.units >> 16) & 0xFFFFFFFF
