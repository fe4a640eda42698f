#!/usr/bin/env python3
"""Make limit3-runaway.txt, the input of limit3-runaway.hal: one line a
cycle (1 ms), an input that runs away upwards ever faster (up to
1.5e6 units/s, far above every maxv of the file), then back down at
2e7 units/s.  Run it, then ``python golden.py limit3-runaway``."""

from pathlib import Path

x, lines = 0.0, []
for k in range(600):
    x = x + 5.0 * k if k < 300 else x - 20000.0
    lines.append(f"{x:.6f}\n")
(Path(__file__).resolve().parent / "limit3-runaway.txt").write_text(
    "".join(lines))
