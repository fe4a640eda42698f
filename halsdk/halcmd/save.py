"""``save`` (HAL commands that rebuild a configuration) and ``status``."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Callable

from halsdk.halcmd.show import sorted_items, threads, type_name, value_cell
from halsdk.types import Direction

Out = Callable[[str], None]

SAVE_ALL = ("comp", "alias", "sigu", "netla", "param", "thread")
SAVE_ALLU = ("comp", "alias", "sigu", "netla", "param",
             "unconnectedinpins", "thread")
_PIN_ARROW = {Direction.IN: "<==", Direction.OUT: "==>",
              Direction.IO: "<=>"}
_SIG_ARROW = {Direction.IN: "==>", Direction.OUT: "<==",
              Direction.IO: "<=>"}
_LOCK_LINES = (
    (1, "  HAL_LOCK_LOAD    - loading of new components is locked"),
    (2, "  HAL_LOCK_CONFIG  - link and addf is locked"),
    (4, "  HAL_LOCK_PARAMS  - setting params is locked"),
    (8, "  HAL_LOCK_RUN     - running/stopping HAL is locked"),
)


def _linked(sig) -> list:
    """The pins of a signal record, by name."""
    return sorted(sig.pins, key=lambda p: p.name.encode())


class Saver:
    """Writes ``save`` output; ``loadrt_args`` maps component names to the
    words of the ``loadrt`` line that made them."""

    def __init__(self, hal, out: Out, loadrt_args: Mapping[str, str]):
        self.hal = hal
        self.out = out
        self.loadrt_args = loadrt_args

    def save(self, what: str) -> bool:
        """Write one item (or a group); False for an unknown word."""
        if what in ("all", ""):
            items: Sequence[str] = SAVE_ALL
        elif what == "allu":
            items = SAVE_ALLU
        else:
            items = (what,)
        handlers = {
            "comp": self.comps, "alias": self.aliases,
            "sig": lambda: self.signals(False),
            "signal": lambda: self.signals(False),
            "sigu": lambda: self.signals(True),
            "link": lambda: self.links(False),
            "linka": lambda: self.links(True),
            "net": lambda: self.nets(False),
            "neta": lambda: self.nets(True),
            "netl": lambda: self.netl(False),
            "netla": lambda: self.netl(True),
            "netal": lambda: self.netl(True),
            "param": self.params, "parameter": self.params,
            "thread": self.threads,
            "unconnectedinpins": self.unconnected,
        }
        if any(i not in handlers for i in items):
            return False
        for item in items:
            handlers[item]()
        return True

    def comps(self) -> None:
        self.out("# components\n")
        comps = sorted((c for c in self.hal.snapshot("component",
                                                     sort=False)
                        if c.realtime), key=lambda c: c.id)
        for c in comps:
            args = self.loadrt_args.get(c.name)
            if args is None:
                self.out(f"#loadrt {c.name}  (not loaded by loadrt, no args "
                         "saved)\n")
            else:
                self.out(f"loadrt {c.name} {args}\n")

    def aliases(self) -> None:
        for kind, title in (("pin", "pin"), ("param", "param")):
            self.out(f"# {title} aliases\n")
            for it in sorted_items(self.hal, kind):
                if it.alias_of is not None:
                    self.out(f"alias {kind} {it.alias_of} {it.name}\n")

    def signals(self, unlinked_only: bool) -> None:
        self.out("# signals\n")
        for sig in sorted_items(self.hal, "signal"):
            if unlinked_only and sig.pins:
                continue
            self.out(f"newsig {sig.name} {type_name(sig.type):<5}\n")

    def links(self, arrows: bool) -> None:
        self.out("# links\n")
        for pin in sorted_items(self.hal, "pin"):
            if pin.signal is not None:
                arrow = _PIN_ARROW[pin.direction] if arrows else ""
                self.out(f"linkps {pin.name} {arrow} {pin.signal}\n")

    def nets(self, arrows: bool) -> None:
        self.out("# nets\n")
        for sig in sorted_items(self.hal, "signal"):
            self.out(f"newsig {sig.name} {type_name(sig.type):<5}\n")
            for pin in _linked(sig):
                arrow = _SIG_ARROW[pin.direction] if arrows else ""
                self.out(f"linksp {sig.name} {arrow} {pin.name}\n")

    def netl(self, arrows: bool) -> None:
        self.out("# nets\n")
        for sig in sorted_items(self.hal, "signal"):
            linked = _linked(sig)
            if not linked:
                continue
            if not arrows:
                words = [p.name for p in linked]
            else:
                writers = [p.name for p in linked
                           if p.direction == Direction.OUT]
                others = [p.name for p in linked
                          if p.direction != Direction.OUT]
                words = writers + (["=>"] if writers and others else []) \
                    + others
            self.out(f"net {sig.name} {' '.join(words)}\n")

    def params(self) -> None:
        self.out("# parameter values\n")
        for par in sorted_items(self.hal, "param"):
            if par.direction != Direction.RO:
                self.out(f"setp {par.name} "
                         f"{value_cell(par.type, par.value)}\n")

    def threads(self) -> None:
        self.out("# realtime thread/function links\n")
        for t in threads(self.hal):
            for f in t.functions:
                self.out(f"addf {f} {t.name}\n")

    def unconnected(self) -> None:
        self.out("# unconnected pin values\n")
        for pin in sorted_items(self.hal, "pin"):
            # I/O pins are inputs too (the IN bit is set in IO)
            if pin.direction & Direction.IN and pin.signal is None:
                self.out(f"setp {pin.name} "
                         f"{value_cell(pin.type, pin.value)}\n")


def status(hal, out: Out, what: str) -> bool:
    """``status [lock|mem|all]``; False for an unknown word."""
    if what not in ("", "all", "lock", "mem"):
        return False
    if what in ("", "all", "lock"):
        level = hal.lock_level
        out("HAL locking status:\n")
        out(f"  current lock value {level} ({level:02x})\n")
        if level == 0:
            out("  HAL_LOCK_NONE - nothing is locked\n")
        for bit, line in _LOCK_LINES:
            if level & bit:
                out(line + "\n")
    if what in ("", "all", "mem"):
        info = hal.info()
        counts = info["counts"]
        used = info["heap_top"]
        out("HAL memory status\n")
        out(f"  used/total shared memory:   {used}/{info['size']}\n")
        for word, key in (("components", "component"), ("pins", "pin"),
                          ("parameters", "param")):
            out(f"  active/recycled {word + ':':<11} {counts[key]}/0\n")
        aliases = sum(1 for kind in ("pin", "param")
                      for it in hal.snapshot(kind, sort=False)
                      if it.alias_of is not None)
        out(f"  active/recycled aliases:    {aliases}/0\n")
        for word, key in (("signals", "signal"), ("functions", "function"),
                          ("threads", "thread")):
            out(f"  active/recycled {word + ':':<11} {counts[key]}/0\n")
    return True
