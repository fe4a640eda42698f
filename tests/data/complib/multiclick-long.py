#!/usr/bin/env python3
"""Make multiclick-long.txt: a long random click sequence, one line a
cycle (1 ms), for multiclick-long.hal.

Presses and releases last 1 to 8 periods, around the instances'
max-hold-ns/max-space-ns of 4 and 5 ms, so every path (clicks 1 to 5,
holds and spaces too long, at the limits) happens many times.  Run it,
then ``python golden.py multiclick-long`` for the reference's output.
"""

import random
from pathlib import Path

CYCLES = 3000

rng = random.Random(18)
bits: list[int] = []
level = 0
while len(bits) < CYCLES:
    bits += [level] * rng.randint(1, 8)
    level ^= 1
lines = "".join(f"{b}\n" for b in bits[:CYCLES])
(Path(__file__).resolve().parent / "multiclick-long.txt").write_text(lines)
