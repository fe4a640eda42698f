"""Histograms as PNG images, with nothing but the standard library.

``halsdk latency`` writes its histograms as a picture on a default
install, where matplotlib is not there (it is only in the ``[test]``
extra).  The picture is simple: one panel per histogram, a bar per bin
(the count on a logarithmic scale), the axes, a mark at 0 and, in a small
built-in bitmap font, the panel's title and the latencies at both ends
and at 0 of its horizontal axis.  :func:`write_png` writes any RGB image.
"""

from __future__ import annotations

import math
import struct
import zlib
from collections.abc import Sequence
from dataclasses import dataclass

RGB = tuple[int, int, int]

WHITE: RGB = (255, 255, 255)
BLACK: RGB = (0, 0, 0)
GREY: RGB = (200, 200, 200)
COLOURS: tuple[RGB, ...] = ((31, 119, 180), (214, 39, 40),
                            (44, 160, 44), (148, 103, 189))

#: a 3x5 font: each glyph is 5 rows of 3 pixels ("#" on)
_FONT = {
    "0": ("###", "#.#", "#.#", "#.#", "###"),
    "1": (".#.", "##.", ".#.", ".#.", "###"),
    "2": ("###", "..#", "###", "#..", "###"),
    "3": ("###", "..#", ".##", "..#", "###"),
    "4": ("#.#", "#.#", "###", "..#", "..#"),
    "5": ("###", "#..", "###", "..#", "###"),
    "6": ("###", "#..", "###", "#.#", "###"),
    "7": ("###", "..#", ".#.", ".#.", ".#."),
    "8": ("###", "#.#", "###", "#.#", "###"),
    "9": ("###", "#.#", "###", "..#", "###"),
    "-": ("...", "...", "###", "...", "..."),
    ".": ("...", "...", "...", "...", ".#."),
    ":": ("...", ".#.", "...", ".#.", "..."),
    "(": (".#.", "#..", "#..", "#..", ".#."),
    ")": (".#.", "..#", "..#", "..#", ".#."),
    ",": ("...", "...", "...", ".#.", "#.."),
    " ": ("...", "...", "...", "...", "..."),
    "a": ("...", "##.", "..#", "###", "###"),
    "b": ("#..", "#..", "###", "#.#", "###"),
    "c": ("...", "###", "#..", "#..", "###"),
    "d": ("..#", "..#", "###", "#.#", "###"),
    "e": ("...", "###", "###", "#..", "###"),
    "g": ("...", "###", "#.#", "###", "##."),
    "h": ("#..", "#..", "###", "#.#", "#.#"),
    "i": (".#.", "...", ".#.", ".#.", ".#."),
    "l": ("##.", ".#.", ".#.", ".#.", "###"),
    "m": ("...", "###", "###", "#.#", "#.#"),
    "n": ("...", "##.", "#.#", "#.#", "#.#"),
    "o": ("...", "###", "#.#", "#.#", "###"),
    "p": ("...", "###", "#.#", "###", "#.."),
    "r": ("...", "###", "#..", "#..", "#.."),
    "s": ("...", "###", "##.", "..#", "###"),
    "t": (".#.", "###", ".#.", ".#.", ".##"),
    "u": ("...", "#.#", "#.#", "#.#", "###"),
    "v": ("...", "#.#", "#.#", "#.#", ".#."),
    "x": ("...", "#.#", ".#.", "#.#", "#.#"),
    "y": ("...", "#.#", "###", "..#", "##."),
}


def write_png(path: str, width: int, height: int,
              pixels: Sequence[bytes | bytearray]) -> None:
    """Write an 8-bit RGB PNG: ``pixels`` holds ``height`` rows of
    ``3 * width`` bytes each."""
    if len(pixels) != height or any(len(r) != 3 * width for r in pixels):
        raise ValueError("write_png: the rows do not match the size")

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return (struct.pack(">I", len(data)) + body
                + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF))

    raw = b"".join(b"\x00" + bytes(r) for r in pixels)
    data = (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2,
                                         0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6))
            + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)


class Canvas:
    """An RGB image to draw on (origin at the top left)."""

    def __init__(self, width: int, height: int, background: RGB = WHITE):
        self.width = width
        self.height = height
        self.rows = [bytearray(bytes(background) * width)
                     for _ in range(height)]

    def rect(self, x0: int, y0: int, x1: int, y1: int, colour: RGB) -> None:
        """Fill the pixels x0..x1-1, y0..y1-1 (clipped)."""
        x0, x1 = max(0, min(x0, x1)), min(self.width, max(x0, x1))
        y0, y1 = max(0, min(y0, y1)), min(self.height, max(y0, y1))
        if x0 >= x1:
            return
        run = bytes(colour) * (x1 - x0)
        for y in range(y0, y1):
            self.rows[y][3 * x0:3 * x1] = run

    def text(self, x: int, y: int, text: str, colour: RGB = BLACK,
             scale: int = 2) -> int:
        """Draw ``text`` (characters outside the font as blanks) with its
        top left corner at x, y; the x just after it."""
        for ch in text:
            glyph = _FONT.get(ch.lower(), _FONT[" "])
            for gy, row in enumerate(glyph):
                for gx, on in enumerate(row):
                    if on == "#":
                        self.rect(x + gx * scale, y + gy * scale,
                                  x + (gx + 1) * scale,
                                  y + (gy + 1) * scale, colour)
            x += 4 * scale
        return x

    @staticmethod
    def text_width(text: str, scale: int = 2) -> int:
        return 4 * scale * len(text)

    def save(self, path: str) -> None:
        write_png(path, self.width, self.height, self.rows)


@dataclass
class Panel:
    """One histogram: ``counts`` by bin number (bin b holds the values
    around ``b * binsize``), its title, and how to label the axis (the
    value of a bin's centre is divided by ``unit``)."""

    title: str
    binsize: int
    counts: dict[int, int]
    unit: float = 1000.0


def _label(value: float) -> str:
    return f"{value:.0f}" if abs(value) >= 10 or value == 0 \
        else f"{value:.1f}"


def plot(path: str, panels: Sequence[Panel], width: int = 800,
         panel_height: int = 260) -> None:
    """Write the panels, one above the other, as a PNG at ``path``."""
    canvas = Canvas(width, max(1, len(panels)) * panel_height)
    for i, panel in enumerate(panels):
        _panel(canvas, panel, i * panel_height, panel_height,
               COLOURS[i % len(COLOURS)])
    canvas.save(path)


def _panel(c: Canvas, p: Panel, top: int, height: int, colour: RGB) -> None:
    left, right = 50, c.width - 20
    plot_top, plot_bottom = top + 30, top + height - 30
    c.text(left, top + 8, p.title)
    c.text(8, plot_top, "log")
    used = [b for b, n in p.counts.items() if n > 0]
    lo = min([*used, -1])
    hi = max([*used, 1])
    span = hi - lo + 1
    peak = max([p.counts.get(b, 0) for b in used] or [1])
    scale = math.log10(peak + 1) or 1.0
    pitch = (right - left) / span
    for b in used:
        x0 = left + int((b - lo) * pitch)
        x1 = max(x0 + 1, left + int((b - lo + 1) * pitch))
        h = int((plot_bottom - plot_top)
                * math.log10(p.counts[b] + 1) / scale)
        c.rect(x0, plot_bottom - max(h, 1), x1, plot_bottom, colour)
    # the axes and the mark at 0
    c.rect(left, plot_bottom, right, plot_bottom + 1, BLACK)
    c.rect(left - 1, plot_top, left, plot_bottom + 1, BLACK)
    zero = left + int((0 - lo + 0.5) * pitch)
    c.rect(zero, plot_top, zero + 1, plot_bottom, GREY)
    for b, x in ((lo, left), (0, zero), (hi, right)):
        text = _label(b * p.binsize / p.unit)
        w = Canvas.text_width(text)
        tx = min(max(x - w // 2, 0), c.width - w)
        c.rect(x, plot_bottom, x + 1, plot_bottom + 5, BLACK)
        c.text(tx, plot_bottom + 8, text)
