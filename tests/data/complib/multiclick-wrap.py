#!/usr/bin/env python3
"""Make multiclick-wrap.txt, for multiclick-wrap.hal: a click, a
release of 4.6 s, a click, a press held 4.6 s, clicks.  In 20 ms
periods, 4.6 s is 230 periods, past the 4.295 s at which the 32-bit
click timer of the reference wraps (a max-space-ns or max-hold-ns
above 2^32 - period is then never exceeded).  Run it, then ``python
golden.py multiclick-wrap`` for the reference's output.
"""

from pathlib import Path

bits = ([1] * 2 + [0] * 230 + [1] * 2 + [0] * 2 + [1] * 230
        + [0] * 3 + [1] * 2 + [0] * 15)
lines = "".join(f"{b}\n" for b in bits)
(Path(__file__).resolve().parent / "multiclick-wrap.txt").write_text(lines)
