"""Canonical device interfaces: pin sets named and behaving alike in every
driver (``<device>.<num>.<io-type>.<chan>.<name>``).

Each helper creates the pins and params of one channel on a userspace
component whose prefix is ``<device>.<num>``, and converts between the raw
hardware value and the HAL values (inversion, scale/offset, limits).
"""

from __future__ import annotations

from typing import Any

from halsdk.component import Component


def channel_name(io_type: str, chan: int, width: int = 2) -> str:
    """``<io-type>.<chan>`` with the channel zero-padded to ``width``."""
    return f"{io_type}.{chan:0{width}d}"


class Channel:
    """One channel of a canonical io-type on a component."""

    io_type = ""

    def __init__(self, comp: Component, chan: int, width: int = 2):
        self.comp = comp
        self.chan = chan
        self.base = channel_name(self.io_type, chan, width)

    def _pin(self, name: str, type_: str, direction: str) -> None:
        self.comp.newpin(f"{self.base}.{name}", type_, direction)

    def _param(self, name: str, type_: str, default: Any = None) -> None:
        self.comp.newparam(f"{self.base}.{name}", type_, "rw")
        if default is not None:
            self.comp[f"{self.base}.{name}"] = default

    def __getitem__(self, name: str) -> Any:
        return self.comp[f"{self.base}.{name}"]

    def __setitem__(self, name: str, value: Any) -> None:
        self.comp[f"{self.base}.{name}"] = value


class DigIn(Channel):
    """Digital input: out pins ``in`` and ``in-not``."""

    io_type = "digin"

    def __init__(self, comp: Component, chan: int, width: int = 2):
        super().__init__(comp, chan, width)
        self._pin("in", "bit", "out")
        self._pin("in-not", "bit", "out")
        self["in-not"] = True

    def update(self, raw: bool) -> None:
        """Publish the hardware state."""
        self["in"] = bool(raw)
        self["in-not"] = not raw


class DigOut(Channel):
    """Digital output: in pin ``out``, param ``invert``."""

    io_type = "digout"

    def __init__(self, comp: Component, chan: int, width: int = 2):
        super().__init__(comp, chan, width)
        self._pin("out", "bit", "in")
        self._param("invert", "bit")

    def raw(self) -> bool:
        """The level to drive on the hardware."""
        return bool(self["out"]) != bool(self["invert"])


class AdcIn(Channel):
    """Analog input: out pin ``value``; params ``scale``, ``offset``,
    ``bit_weight``, ``hw_offset``.  value = raw * scale - offset."""

    io_type = "adcin"

    def __init__(self, comp: Component, chan: int, width: int = 2):
        super().__init__(comp, chan, width)
        self._pin("value", "float", "out")
        self._param("scale", "float", 1.0)
        self._param("offset", "float", 0.0)
        self._param("bit_weight", "float", 1.0)
        self._param("hw_offset", "float", 0.0)

    def update(self, raw: float) -> float:
        """Scale a hardware reading into ``value``; returns it."""
        value = float(raw) * self["scale"] - self["offset"]
        self["value"] = value
        return value


class DacOut(Channel):
    """Analog output: in pins ``value`` and ``enable``; params ``scale``,
    ``offset``, ``high_limit``, ``low_limit``, ``bit_weight``,
    ``hw_offset``.  raw = clamp(value * scale + offset), 0 when disabled.

    The reference manual names this io-type ``adcout`` by a slip; the
    conventional name for a digital-to-analog output is ``dacout``.
    """

    io_type = "dacout"

    def __init__(self, comp: Component, chan: int, width: int = 2,
                 low: float = -1e30, high: float = 1e30):
        super().__init__(comp, chan, width)
        self._pin("value", "float", "in")
        self._pin("enable", "bit", "in")
        self._param("scale", "float", 1.0)
        self._param("offset", "float", 0.0)
        self._param("high_limit", "float", high)
        self._param("low_limit", "float", low)
        self._param("bit_weight", "float", 1.0)
        self._param("hw_offset", "float", 0.0)

    def raw(self) -> float:
        """The value to send to the hardware."""
        if not self["enable"]:
            return 0.0
        out = self["value"] * self["scale"] + self["offset"]
        return min(max(out, self["low_limit"]), self["high_limit"])


class Encoder(Channel):
    """Encoder: out pins ``count`` (s32), ``position``, ``velocity``; in
    pin ``reset``; param ``position-scale`` (counts per unit)."""

    io_type = "encoder"

    def __init__(self, comp: Component, chan: int, width: int = 2):
        super().__init__(comp, chan, width)
        self._pin("count", "s32", "out")
        self._pin("position", "float", "out")
        self._pin("velocity", "float", "out")
        self._pin("reset", "bit", "in")
        self._param("position-scale", "float", 1.0)
        self._zero = 0
        self._last: int | None = None

    def update(self, raw_count: int, dt: float) -> None:
        """Publish a raw hardware count read ``dt`` seconds after the
        previous one; ``reset`` makes the current count the new zero.
        ``velocity`` is the counts moved over ``dt`` (0 on the first
        update), so a reset does not make it jump."""
        if self["reset"]:
            self._zero = raw_count
        count = int(raw_count - self._zero)
        scale = self["position-scale"] or 1.0
        if self._last is None:
            self["velocity"] = 0.0
        elif dt > 0:
            self["velocity"] = (raw_count - self._last) / scale / dt
        self._last = raw_count
        self["count"] = count
        self["position"] = count / scale
