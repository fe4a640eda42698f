"""Text formats of ``show``, ``list``, ``getp`` and ``gets``.

Widths and words are those the reference halcmd prints.  Values a
process cannot reproduce are printed in the same shape: function code
and argument addresses are made-up 12-digit hex numbers, and the thread
times are nanoseconds (the reference prints CPU clock counts).
"""

from __future__ import annotations

import fnmatch
import os
from collections.abc import Sequence
from typing import Any, Callable

from halsdk.types import DIR_WORDS, HalType, dir_word
from halsdk.types import type_word as _type_word

Out = Callable[[str], None]
NAME_LEN = 47
_IN, _OUT, _IO = (d for d in DIR_WORDS if d.word in ("IN", "OUT", "I/O"))
_ARROW_PIN = {_IN: "<==", _OUT: "==>", _IO: "<=>"}
_ARROW_SIG = {_IN: "==>", _OUT: "<==", _IO: "<=>"}


def type_name(t: int) -> str:
    return _type_word(t)


def value_text(t: int, v: Any) -> str:
    """A value as ``getp``/``gets`` print it."""
    if t == HalType.BIT:
        return "TRUE" if v else "FALSE"
    if t == HalType.FLOAT:
        return f"{v:.7g}"
    return f"{v:d}"


def value_cell(t: int, v: Any) -> str:
    """A value as the 12-character column of ``show``."""
    if t == HalType.BIT:
        return f"{'TRUE' if v else 'FALSE':>12}"
    if t == HalType.FLOAT:
        return f"{v:12.7g}"
    if t == HalType.U32:
        return f"  0x{v:08X}"
    if t == HalType.U64:
        return f"0x{v:016X}"
    return f"  {v:10d}"


def match(patterns: Sequence[str], name: str) -> bool:
    """True when no pattern is given, or one is a prefix or glob of name."""
    if not patterns:
        return True
    return any(name.startswith(p) or fnmatch.fnmatchcase(name, p)
               for p in patterns)


def sorted_items(hal, kind: str) -> list:
    """Records of every object of a kind, by name.  A snapshot
    (:meth:`halsdk.Hal.snapshot`): names, metadata and values taken in one
    pass, so a listing never fails half-way because another process
    loads or unloads components meanwhile."""
    return sorted(hal.snapshot(kind, sort=False),
                  key=lambda it: it.name.encode())


def components(hal) -> list:
    """Components newest first (the reference's list order)."""
    return sorted(hal.snapshot("component", sort=False), key=lambda c: -c.id)


def threads(hal) -> list:
    return list(reversed(hal.snapshot("thread", sort=False)))


class Shower:
    """Prints HAL items; ``script`` selects the ``-s`` formats."""

    def __init__(self, hal, out: Out, script: bool = False):
        self.hal = hal
        self.out = out
        self.script = script

    def cell(self, t: int, v: Any) -> str:
        """The value column: padded, or bare in script mode."""
        text = value_cell(t, v)
        return text.strip() if self.script else text

    def section(self, *titles: str) -> None:
        """Titles are left out in script mode."""
        if not self.script:
            self.out("".join(t + "\n" for t in titles))

    # -------------------------------------------------------- show

    def comps(self, patterns: Sequence[str]) -> None:
        if not self.script:
            self.out("Loaded HAL Components:\n")
            self.out("ID      Type  Name                                  "
                     "          PID   State\n")
        for c in components(self.hal):
            if not match(patterns, c.name):
                continue
            kind = "RT" if c.realtime else "User"
            pid = "" if c.realtime else str(c.pid)
            state = ("dead" if not c.realtime and (c.dead or not c.alive)
                     else "ready" if c.ready else "initializing")
            self.out(f" {c.id:5d}  {kind:<4}  {c.name:<{NAME_LEN}} "
                     f"{pid:>5} {state}\n")
        self.out("\n")

    def _values(self, kind: str, patterns: Sequence[str]) -> None:
        for it in sorted_items(self.hal, kind):
            if not match(patterns, it.name):
                continue
            tname = type_name(it.type)
            dname = dir_word(it.direction)
            cell = self.cell(it.type, it.value)
            if not self.script:
                line = (f" {it.owner_id:5d}  {tname:<5} {dname:<3}  {cell}"
                        f"  {it.name}")
            else:
                line = f"{it.owner} {tname:<5} {dname} {cell} {it.name}"
            if kind == "pin" and it.signal is not None:
                line += f" {_ARROW_PIN[it.direction]} {it.signal}"
            self.out(line + "\n")

    def pins(self, patterns: Sequence[str]) -> None:
        if not self.script:
            self.out("Component Pins:\n")
            self.out("Owner   Type  Dir         Value  Name\n")
        self._values("pin", patterns)
        self.out("\n")

    def params(self, patterns: Sequence[str]) -> None:
        if not self.script:
            self.out("Parameters:\n")
            self.out("Owner   Type  Dir         Value  Name\n")
        self._values("param", patterns)
        self.out("\n")

    def signals(self, patterns: Sequence[str]) -> None:
        if not self.script:
            self.out("Signals:\n")
            self.out("Type          Value  Name     (linked to)\n")
        for sig in sorted_items(self.hal, "signal"):
            if not match(patterns, sig.name):
                continue
            linked = sorted(sig.pins, key=lambda p: p.name.encode())
            head = (f"{type_name(sig.type):<5}  "
                    f"{self.cell(sig.type, sig.value)}  {sig.name}")
            if self.script:
                self.out(head + "".join(
                    f" {_ARROW_SIG[p.direction]} {p.name}"
                    for p in linked) + "\n")
            else:
                self.out(head + "\n")
                for p in linked:
                    self.out(f"{'':25}{_ARROW_SIG[p.direction]} {p.name}\n")
        self.out("\n")

    def functs(self, patterns: Sequence[str]) -> None:
        if not self.script:
            self.out("Exported Functions:\n")
            self.out("Owner   CodeAddr  Arg       FP   Users  Name\n")
        for n, f in enumerate(sorted_items(self.hal, "function")):
            if not match(patterns, f.name):
                continue
            code, arg = fake_addresses(f.owner_id, n)
            fp = "YES" if f.uses_fp else "NO"
            if self.script:
                self.out(f"{f.owner} {code:x} {arg:x} {fp} {f.users:3d} "
                         f"{f.name}\n")
            else:
                self.out(f" {f.owner_id:05d}  {code:12x}  {arg:12x}  "
                         f"{fp:<3}  {f.users:5d}   {f.name}\n")
        self.out("\n")

    def thread_list(self, patterns: Sequence[str]) -> None:
        if not self.script:
            self.out("Realtime Threads:\n")
            self.out("     Period  FP     Name               "
                     "(     Time, Max-Time )\n")
        for t in threads(self.hal):
            if not match(patterns, t.name):
                continue
            fp = "YES" if t.uses_fp else "NO"
            functs = t.functions
            now, tmax = t.time, t.tmax      # its .time pin, .tmax param
            if self.script:
                self.out(f"{t.period} {fp} {t.name} {now:8d} {tmax}"
                         + "".join(" " + f for f in functs) + "\n")
                continue
            self.out(f"{t.period:11d}  {fp:<3}  {t.name:>20} ( {now:8d}, "
                     f"{tmax:8d} )\n")
            for n, f in enumerate(functs, 1):
                self.out(f"{'':17}{n:2d} {f}\n")
        self.out("\n")

    def aliases(self, kind: str, patterns: Sequence[str]) -> None:
        if not self.script:
            self.out("Pin Aliases:\n" if kind == "pin"
                     else "Parameter Aliases:\n")
            self.out(" Alias                                            "
                     "Original Name\n")
        for it in sorted_items(self.hal, kind):
            orig = it.alias_of
            if orig is None or not match(patterns, it.name):
                continue
            if self.script:
                self.out(f" {it.name}  {orig}\n")
            else:
                self.out(f" {it.name:<{NAME_LEN}}  {orig}\n")
        self.out("\n")

    def show(self, what: str, patterns: Sequence[str]) -> bool:
        """Print one ``show`` item; False for an unknown item word."""
        if what == "comp":
            self.comps(patterns)
        elif what == "pin":
            self.pins(patterns)
        elif what in ("sig", "signal"):
            self.signals(patterns)
        elif what in ("param", "parameter"):
            self.params(patterns)
        elif what in ("funct", "function"):
            self.functs(patterns)
        elif what == "thread":
            self.thread_list(patterns)
        elif what == "alias":
            self.aliases("pin", patterns)
            self.aliases("param", patterns)
        elif what == "all":
            self.comps(patterns)
            self.pins(patterns)
            self.aliases("pin", patterns)
            self.signals(patterns)
            self.params(patterns)
            self.aliases("param", patterns)
            self.functs(patterns)
            self.thread_list(patterns)
        else:
            return False
        return True

    # -------------------------------------------------------- list

    def names(self, what: str, patterns: Sequence[str]) -> bool:
        """Print one ``list`` line; False for an unknown item word."""
        if what == "comp":
            names = [c.name for c in components(self.hal)]
        elif what == "pin":
            names = [p.name for p in sorted_items(self.hal, "pin")]
        elif what in ("sig", "signal"):
            names = [s.name for s in sorted_items(self.hal, "signal")]
        elif what in ("param", "parameter"):
            names = [p.name for p in sorted_items(self.hal, "param")]
        elif what in ("funct", "function"):
            names = [f.name for f in sorted_items(self.hal, "function")]
        elif what == "thread":
            names = [t.name for t in threads(self.hal)]
        else:
            return False
        self.out("".join(n + " " for n in names if match(patterns, n))
                 + "\n")
        return True


def fake_addresses(owner_id: int, n: int) -> tuple[int, int]:
    """Stand-ins for the code and argument addresses the reference shows."""
    base = 0x7F0000000000 + (os.getpid() & 0xFFFF) * 0x1000000
    return base + owner_id * 0x1000 + 0x189, base + 0x800000 + n * 0x20
