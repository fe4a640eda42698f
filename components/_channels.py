"""Channel configuration of the stream components (sampler, streamer).

A helper of the shipped components, not a component itself: it checks the
``cfg=`` and ``depth=`` load parameters, one cfg string and one depth per
channel, and turns each cfg string into HAL types.
"""

from __future__ import annotations

from typing import Optional

from halsdk.types import HalType

MAX_ELEMENTS = 256

# cfg letters: the reference's f b s u, and l k for the 64-bit types
LETTERS = {"f": HalType.FLOAT, "b": HalType.BIT, "s": HalType.S32,
           "u": HalType.U32, "l": HalType.S64, "k": HalType.U64}

MODPARAMS = {
    "depth": ([int], None, "FIFO depth (records) of each channel"),
    "cfg": ([str], None, "pin types of each channel: letters f b s u l k"),
}


def channels(comp: str, depth: Optional[list],
             cfg: Optional[list]) -> list[tuple[str, list[HalType], int]]:
    """(cfg string, types, depth) of each channel, or ValueError naming
    the channel."""
    cfgs = [s for s in (cfg or []) if s != ""]
    depths = list(depth or [])
    if not cfgs:
        raise ValueError(f"{comp}: no channels specified (give "
                         "cfg=STRING[,STRING...])")
    out: list[tuple[str, list[HalType], int]] = []
    for i, s in enumerate(cfgs):
        if i >= len(depths):
            raise ValueError(f"{comp}.{i}: no depth given for cfg '{s}' "
                             "(give depth=D1[,D2...], one per cfg string)")
        if depths[i] < 1:
            raise ValueError(f"{comp}.{i}: depth {depths[i]} is not a "
                             "positive number of samples")
        if len(s) > MAX_ELEMENTS:
            raise ValueError(f"{comp}.{i}: cfg string has {len(s)} "
                             f"letters; at most {MAX_ELEMENTS}")
        for ch in s:
            if ch.lower() not in LETTERS:
                raise ValueError(
                    f"{comp}.{i}: unknown type '{ch}' in cfg string "
                    f"'{s}' (letters: f float, b bit, s s32, u u32, "
                    "l s64, k u64)")
        out.append((s, [LETTERS[ch.lower()] for ch in s], depths[i]))
    return out
