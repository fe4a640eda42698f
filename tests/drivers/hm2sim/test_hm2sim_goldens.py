"""The reference's recorded load against each board profile
(tests/data/hm2/<board>/, made by tests/data/hm2/regen.sh): the card still
answers the reference's load conversation byte for byte, and the
reference's listings have the profile's pins."""

from __future__ import annotations

import re

import pytest
from helpers import data_path

from halsdk.drivers.hm2sim import PROFILES, idrom, lbp16, profile
from halsdk.drivers.hm2sim.card import Card

BOARDS = sorted(PROFILES)
_REQUEST = re.compile(r"^\s*[0-9.]+ <- ([0-9a-f]+)")
_REPLY = re.compile(r"^\s*-> ([0-9a-f]*)")


def _conversation(board: str) -> list[tuple[bytes, bytes]]:
    """(request, reply) datagrams of the recorded load, up to the first
    servo cycle (its replies carry timestamps)."""
    pairs: list[tuple[bytes, bytes]] = []
    text = data_path("hm2", board, "packets.txt").read_text()
    for line in text.splitlines():
        if m := _REQUEST.match(line):
            request = bytes.fromhex(m.group(1))
            if any(c[2] == lbp16.SPACE_COMM for c in lbp16.parse(request)):
                break
            pairs.append((request, b""))
        elif (m := _REPLY.match(line)) and pairs:
            pairs[-1] = (pairs[-1][0], bytes.fromhex(m.group(1)))
    return pairs


@pytest.mark.parametrize("board", BOARDS)
def test_the_card_answers_the_recorded_load(board: str) -> None:
    pairs = _conversation(board)
    assert len(pairs) > 50
    card = Card(profile(board))
    for n, (request, reply) in enumerate(pairs):
        assert card.execute(lbp16.parse(request)) == reply, \
            f"datagram {n}: {request.hex()}"


@pytest.mark.parametrize("board", BOARDS)
def test_the_reference_loaded_without_error(board: str) -> None:
    text = data_path("hm2", board, "load.txt").read_text()
    name = f"hm2_{board}.0"
    assert f"hm2/{name}: registered" in text
    assert f"discovered {board.upper()}" in text
    assert "ERROR" not in text and "fails" not in text


@pytest.mark.parametrize("board", BOARDS)
def test_the_reference_made_the_profile_pins(board: str) -> None:
    p = profile(board)
    pins = data_path("hm2", board, "show-pin.txt").read_text()
    names = re.findall(r"\s(hm2_\S+)$", pins, re.M)
    prefix = f"hm2_{board}.0."

    def units(kind: str) -> set[str]:
        return {n.split(".")[3] for n in names
                if n.startswith(prefix + kind + ".")
                and n.split(".")[3].isdigit()}

    assert len(units("gpio")) == p.header.io_width
    assert len(units("stepgen")) == p.instances(idrom.GTAG_STEPGEN)
    assert len(units("encoder")) == p.instances(idrom.GTAG_ENCODER)
    assert len(units("pwmgen")) == p.instances(idrom.GTAG_PWMGEN)
    assert prefix + "watchdog.has_bit" in names
    functs = data_path("hm2", board, "show-funct.txt").read_text()
    for f in ("read", "read-request", "write"):
        assert f" {prefix}{f}\n" in functs
