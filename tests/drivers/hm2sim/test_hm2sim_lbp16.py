"""LBP16 command words and datagrams of the simulated Mesa card."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from halsdk.drivers.hm2sim import lbp16
from halsdk.drivers.hm2sim.lbp16 import Command, Lbp16Error


@st.composite
def commands(draw: st.DrawFn) -> Command:
    write = draw(st.booleans())
    size = draw(st.sampled_from(lbp16.SIZES))
    count = draw(st.integers(1, 127))
    return Command(
        write=write, space=draw(st.integers(0, 7)), size=size, count=count,
        address=draw(st.none() | st.integers(0, 0xFFFF)),
        increment=draw(st.booleans()), info=draw(st.booleans()),
        data=draw(st.binary(min_size=size * count, max_size=size * count))
        if write else b"")


@given(commands())
def test_command_word_round_trip(c: Command) -> None:
    f = lbp16.decode_word(c.word)
    assert (f.write, f.space, f.size, f.count, f.increment, f.info) == (
        c.write, c.space, c.size, c.count, c.increment, c.info)
    assert f.has_address == (c.address is not None)


@given(st.lists(commands(), max_size=8))
def test_datagram_round_trip(cs: list[Command]) -> None:
    assert lbp16.decode(lbp16.encode(cs)) == cs


@given(st.lists(commands(), min_size=1, max_size=4), st.data())
def test_truncated_datagram_is_refused(cs: list[Command],
                                       data: st.DataObject) -> None:
    packet = lbp16.encode(cs)
    cut = data.draw(st.integers(1, len(packet)))
    short = packet[:len(packet) - cut]
    try:
        decoded = lbp16.decode(short)
    except Lbp16Error:
        return
    # a cut exactly between commands leaves whole commands
    assert decoded == cs[:len(decoded)]
    assert lbp16.encode(decoded) == short


def test_the_words_the_reference_sends() -> None:
    # recorded from hm2_eth (tests/data/hm2/*/packets.txt)
    (mac,) = lbp16.decode(bytes.fromhex("83490200"))
    assert (mac.write, mac.space, mac.size, mac.count, mac.address) == (
        False, lbp16.SPACE_EEPROM, 2, 3, 2)
    (name,) = lbp16.decode(bytes.fromhex("885d0000"))
    assert (name.space, name.size, name.count, name.address) == (
        lbp16.SPACE_BOARD, 2, 8, 0)
    (cookie,) = lbp16.decode(bytes.fromhex("81420001"))
    assert (cookie.space, cookie.size, cookie.count, cookie.address) == (
        lbp16.SPACE_HM2, 4, 1, 0x100)
    (wd,) = lbp16.decode(bytes.fromhex("81c2000c01000000"))
    assert wd.write and wd.address == 0x0C00 and wd.data == b"\1\0\0\0"


@pytest.mark.parametrize("packet, message", [
    (b"\x81", "truncated command word"),
    (b"\x81\x42\x00", "truncated address"),
    (b"\x80\x42\x00\x01", "zero count"),
    (bytes.fromhex("81c2000c0100"), "needs 4 data bytes"),
])
def test_malformed_datagrams(packet: bytes, message: str) -> None:
    with pytest.raises(Lbp16Error, match=message):
        lbp16.decode(packet)


@pytest.mark.parametrize("kwargs, message", [
    ({"space": 8}, "memory space"),
    ({"size": 3}, "transfer size"),
    ({"count": 0}, "transfer count"),
    ({"count": 128}, "transfer count"),
    ({"address": 0x10000}, "16-bit"),
])
def test_bad_commands(kwargs: dict[str, int], message: str) -> None:
    args = {"write": False, "space": 0, "size": 4, "count": 1, **kwargs}
    with pytest.raises(Lbp16Error, match=message):
        Command(**args)  # type: ignore[arg-type]


def test_write_data_must_match_its_size() -> None:
    with pytest.raises(Lbp16Error, match="carries 3 bytes"):
        Command(write=True, space=0, size=4, count=1, address=0, data=b"abc")
