"""Modal groups of G and M codes and the per-block group checks."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .block import code_key

if TYPE_CHECKING:  # pragma: no cover
    from .block import Block


def _key(value: float) -> int:
    """G/M numbers as integers in tenths: 38.2 -> 382, 1 -> 10."""
    return int(round(value * 10))


# group number -> codes (tenths). Group 0 is non-modal.
G_GROUPS: dict[int, tuple[int, ...]] = {
    0: (40, 100, 280, 281, 300, 301, 530, 920, 921, 922, 923),
    1: (0, 10, 20, 30, 50, 51, 52, 53, 330, 382, 383, 384, 385, 730, 760,
        800, 810, 820, 830, 840, 850, 860, 870, 880, 890),
    2: (170, 180, 190),
    3: (900, 910),
    4: (901, 911),
    5: (930, 940, 950),
    6: (200, 210),
    7: (400, 410, 420),
    8: (430, 431, 432, 490),
    10: (980, 990),
    12: (540, 550, 560, 570, 580, 590, 591, 592, 593),
    13: (610, 611, 640),
    14: (960, 970),
    15: (70, 80),
}
M_GROUPS: dict[int, tuple[int, ...]] = {
    4: (0, 10, 20, 300, 600),
    5: (620, 630, 640, 650, 660, 670, 680),
    6: (60, 610),
    7: (30, 40, 50, 190, 700, 710, 720, 730),
    8: (70, 80, 90),
    9: (480, 490, 500, 510, 520, 530),
    10: tuple(range(1000, 2000, 10)),      # user M-codes M100-M199
}
_G_OF = {code: group for group, codes in G_GROUPS.items() for code in codes}
_M_OF = {code: group for group, codes in M_GROUPS.items() for code in codes}

#: G codes that consume the axis words of a block (besides motion).
AXIS_USERS_GROUP0 = (100, 280, 300, 920)


def group_codes(block: Block) -> tuple[dict[int, int], dict[int, int]]:
    """Map group -> code (tenths) for the G and M codes of ``block``.

    Raises the block's error for an unknown code or two codes of one modal
    group, pointing at the second one.
    """
    return (_by_group(block, "g", block.g, _G_OF),
            _by_group(block, "m", block.m, _M_OF))


def _by_group(block: Block, letter: str, values: Iterable[float],
              groups: dict[int, int]) -> dict[int, int]:
    """Map group -> code (tenths) of the ``letter`` codes ``values``."""
    found: dict[int, int] = {}
    for value in values:
        code = int(round(value * 10))
        name = code_key(letter, value)
        if code not in groups:
            raise block.error(f"Unknown m code used: M{name[1:]}"
                              if letter == "m" else "Unknown g code used",
                              name)
        group = groups[code]
        if letter == "g" and group == 1 and 1 in found and \
                800 in (code, found[1]):
            # G80 beside another motion code: the other one, as the
            # reference does
            if code == 800:
                continue
            del found[1]
        if group in found and letter == "g" and group == 1 and \
                53 in (code, found[1]):
            # G5.3 beside another motion code (the reference's words)
            raise block.error("Between G5.2 and G5.3 codes, only "
                              "additional G5.2 codes are allowed.", name)
        if group in found:
            raise block.error(f"Two {letter} codes used from same modal "
                              "group", name)
        found[group] = code
    return found


@dataclass
class ModalState:
    """The modal settings in effect (codes in tenths, e.g. motion 10 = G1)."""

    motion: int = 10            # G1 after start-up as after M2
    plane: int = 170
    distance: int = 900
    arc_distance: int = 911
    feed_mode: int = 940
    units: int = 210
    cutter_comp: int = 400
    tool_length: int = 490
    retract: int = 980
    coord_system: int = 540
    control: int = 640
    spindle: int = 50           # M5
    spindle_mode: int = 970     # G97 (G96: constant surface speed)
    mist: bool = False
    flood: bool = False

    def gcodes(self) -> tuple[float, ...]:
        """The active G codes as numbers (like the reference status)."""
        return tuple(c / 10 for c in (
            self.motion, self.plane, self.distance, self.arc_distance,
            self.feed_mode, self.units, self.cutter_comp, self.tool_length,
            self.retract, self.coord_system, self.control))
