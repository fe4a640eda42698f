"""The IDROM of each simulated board, read as a driver reads it."""

from __future__ import annotations

import struct

import pytest

from halsdk.drivers.hm2sim import PROFILES, idrom, lbp16, profile
from halsdk.drivers.hm2sim.card import Card

BOARDS = sorted(PROFILES)


def _read(card: Card, address: int, words: int) -> bytes:
    return card.execute(lbp16.parse(lbp16.encode(
        [lbp16.read(lbp16.SPACE_HM2, address, words)])))


def _idrom_from_registers(card: Card) -> idrom.Parsed:
    """The IDROM the way hostmot2 finds it: cookie, name, pointer, then the
    header, the module descriptors and the pin descriptors."""
    (cookie,) = struct.unpack("<I", _read(card, idrom.COOKIE_ADDRESS, 1))
    assert cookie == idrom.IOCOOKIE
    assert _read(card, idrom.NAME_ADDRESS, 2) == b"HOSTMOT2"
    (base,) = struct.unpack("<I", _read(card, idrom.IDROM_POINTER_ADDRESS, 1))
    header = idrom.Header.unpack(_read(card, base, 16))
    size = header.offset_to_pins + 4 * header.io_width
    image = b"".join(_read(card, base + at, min(64, (size - at) // 4))
                     for at in range(0, size, 256))
    return idrom.parse(image)


@pytest.mark.parametrize("board", BOARDS)
def test_idrom_parses_back(board: str) -> None:
    p = profile(board)
    parsed = _idrom_from_registers(Card(p))
    assert parsed.header == p.header
    assert parsed.modules == list(p.modules)
    assert parsed.pins == list(p.pins)
    h = parsed.header
    assert h.io_width == h.io_ports * h.port_width == len(p.pins)
    assert len(p.connectors) == h.io_ports


@pytest.mark.parametrize("board", BOARDS)
def test_pin_descriptors_match_the_module_counts(board: str) -> None:
    p = profile(board)
    for m in p.modules:
        if m.gtag in (idrom.GTAG_STEPGEN, idrom.GTAG_ENCODER,
                      idrom.GTAG_PWMGEN):
            units = {pin.sec_unit for pin in p.pins if pin.sec_tag == m.gtag}
            assert units == set(range(m.instances)), m.name
    steps = [pin for pin in p.pins if pin.sec_tag == idrom.GTAG_STEPGEN]
    assert all(pin.is_output for pin in steps)
    assert len(steps) == 2 * p.instances(idrom.GTAG_STEPGEN)
    encoder = [pin for pin in p.pins if pin.sec_tag == idrom.GTAG_ENCODER]
    assert not any(pin.is_output for pin in encoder)
    assert sorted(pin.sec_pin for pin in encoder) == [1, 2, 3]


@pytest.mark.parametrize("board", BOARDS)
def test_modules_as_the_standard_firmware(board: str) -> None:
    p = profile(board)
    # register counts, versions and the per-instance register masks the
    # reference's hostmot2 accepts (it refused the card otherwise)
    expected = {idrom.GTAG_WATCHDOG: (0, 3, 0x0C00, 0),
                idrom.GTAG_IOPORT: (0, 5, 0x1000, 0x1F),
                idrom.GTAG_STEPGEN: (2, 10, 0x2000, 0x1FF),
                idrom.GTAG_ENCODER: (2, 5, 0x3000, 0x03),
                idrom.GTAG_PWMGEN: (0, 5, 0x4000, 0x03),
                idrom.GTAG_LED: (0, 1, 0x0200, 0)}
    for m in p.modules:
        assert (m.version, m.registers, m.base, m.multiple) == \
            expected[m.gtag], m.name
    assert p.header.clock_low == 100_000_000
    assert p.header.clock_high == 200_000_000
    assert p.instances(idrom.GTAG_STEPGEN) == 5
    assert p.instances(idrom.GTAG_ENCODER) == 1
    assert p.instances(idrom.GTAG_IOPORT) == p.header.io_ports


def test_board_specific_layout() -> None:
    s = profile("7i96s")
    assert (s.header.io_ports, s.header.io_width) == (3, 51)
    assert s.instances(idrom.GTAG_PWMGEN) == 1
    assert s.lbp16_name == b"7I96S"
    n = profile("7i92")
    assert (n.header.io_ports, n.header.io_width) == (2, 34)
    assert n.instances(idrom.GTAG_PWMGEN) == 0
    assert n.lbp16_name == b"7I92"
    # the 7I76 on P2: direction, then step
    assert n.pins[0] == idrom.Pin(idrom.OUTPUT | 2, idrom.GTAG_STEPGEN, 0)
    assert n.pins[1] == idrom.Pin(idrom.OUTPUT | 1, idrom.GTAG_STEPGEN, 0)


def test_unknown_board() -> None:
    with pytest.raises(ValueError, match="unknown board '7i99'.*7i92, 7i96s"):
        profile("7i99")


def test_build_refuses_a_wrong_pin_count() -> None:
    p = profile("7i92")
    with pytest.raises(ValueError, match="33 pin descriptors"):
        idrom.build(p.header, list(p.modules), list(p.pins[:-1]))
