"""The :class:`Driver` base class: a userspace component for one device,
its canonical channels and its fault pins."""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Optional

from halsdk.component import Component, component
from halsdk.driverkit.canonical import AdcIn, DacOut, DigIn, DigOut, Encoder

log = logging.getLogger("halsdk.driverkit")

#: values of the ``fault-code`` pin
FAULT_NONE = 0
FAULT_OPEN = 1
FAULT_READ = 2
FAULT_WRITE = 3
FAULT_NAMES = {FAULT_NONE: "ok", FAULT_OPEN: "open failed",
               FAULT_READ: "read failed", FAULT_WRITE: "write failed"}


class DriverError(Exception):
    """A device problem with a message meant for the integrator (raise it
    from :meth:`Driver.open`, :meth:`Driver.read` or :meth:`Driver.write`;
    any other exception is reported the same way)."""


class Driver:
    """Base of a userspace driver for device ``<name>.<num>``.

    Subclasses set :attr:`name` and override:

    - :meth:`setup` -- create the channels (``self.digin(n)`` …), once;
    - :meth:`open` / :meth:`close` -- connect to and release the device;
    - :meth:`read` / :meth:`write` -- move values between device and pins;
    - :meth:`safe_state` -- outputs off when the loop ends (any reason,
      the host's death included).

    :meth:`start` creates the component ``<name>.<num>`` (component name
    and pin prefix alike, so several devices can run at once; pass
    ``comp_name`` to name the component otherwise, for example after the
    program, so that ``loadusr -W program`` waits for it) with the pins
    ``fault`` (bit), ``fault-code`` (u32, one of ``FAULT_*``),
    ``fault-count`` (u32, faults since start) and ``connected`` (bit), calls
    :meth:`setup` and marks the component ready.  A loop
    (:class:`halsdk.driverkit.IOLoop`) then drives the device.
    """

    name = "driver"

    def __init__(self, num: int = 0, instance: Optional[str] = None,
                 comp_name: Optional[str] = None):
        self.num = num
        self.prefix = f"{self.name}.{num}"
        self.comp_name = comp_name or self.prefix
        self._instance = instance
        self.comp: Optional[Component] = None
        self._fault_text = ""

    # -- to override -------------------------------------------------------
    def setup(self) -> None:
        """Create the channels and any extra pins."""

    def open(self) -> None:
        """Connect to the device; raise when it is not there."""

    def close(self) -> None:
        """Release the device (must not raise when already gone)."""

    def read(self) -> None:
        """Read the device and update the input pins."""

    def write(self) -> None:
        """Write the output pins to the device."""

    def safe_state(self) -> None:
        """Put the device in its safe state: outputs off, drives
        disabled, brakes on, "offline" published.  Called once, while the
        device is open, when the loop ends for any reason -- SIGTERM,
        ``unloadusr``, :meth:`IOLoop.stop`, or the instance's host gone
        (the process gets SIGTERM then) -- before :meth:`close`.  It must
        not rely on HAL values (the host may be dead: the pins hold
        stale values) and should take well under a second.  The default
        does nothing."""

    # -- channels ----------------------------------------------------------
    def _require(self) -> Component:
        if self.comp is None:
            raise DriverError(f"{self.prefix}: create channels in setup(), "
                              "after start()")
        return self.comp

    def digin(self, chan: int, width: int = 2) -> DigIn:
        return DigIn(self._require(), chan, width)

    def digout(self, chan: int, width: int = 2) -> DigOut:
        return DigOut(self._require(), chan, width)

    def adcin(self, chan: int, width: int = 2) -> AdcIn:
        return AdcIn(self._require(), chan, width)

    def dacout(self, chan: int, width: int = 2, **limits: float) -> DacOut:
        return DacOut(self._require(), chan, width, **limits)

    def encoder(self, chan: int, width: int = 2) -> Encoder:
        return Encoder(self._require(), chan, width)

    # -- lifecycle ---------------------------------------------------------
    def start(self, extra_pins: Sequence[tuple[str, str]] = ()
              ) -> Component:
        """Create the component, its fault pins, ``extra_pins`` (out pins
        as (name, type) pairs) and channels; ready it."""
        self.comp = component(self.comp_name, self.prefix, self._instance)
        try:
            for pin, type_ in (("fault", "bit"), ("fault-code", "u32"),
                               ("fault-count", "u32"), ("connected", "bit"),
                               *extra_pins):
                self.comp.newpin(pin, type_, "out")
            self.setup()
            self.comp.ready()
        except BaseException:
            self.comp.exit()
            self.comp = None
            raise
        return self.comp

    def shutdown(self) -> None:
        """Close the device (errors only logged) and remove the component."""
        self.safe_close()
        if self.comp is not None:
            self.comp.exit()
            self.comp = None

    def safe_close(self) -> None:
        try:
            self.close()
        except Exception as exc:  # the device is gone anyway
            log.debug("%s: close: %s", self.prefix, exc)

    # -- faults ------------------------------------------------------------
    @property
    def fault_text(self) -> str:
        """The message of the current fault ('' when healthy)."""
        return self._fault_text

    def set_fault(self, code: int, exc: BaseException) -> None:
        """Enter (or stay in) a fault; the message is logged once per
        distinct fault, never with a traceback."""
        detail = str(exc) or type(exc).__name__
        text = f"{self.prefix}: {FAULT_NAMES.get(code, 'fault')}: {detail}"
        comp = self.comp
        if comp is not None:
            if not comp["fault"] or comp["fault-code"] != code:
                comp["fault-count"] = (comp["fault-count"] + 1) & 0xFFFFFFFF
            comp["fault"] = True
            comp["fault-code"] = code
        if text != self._fault_text:
            log.error("%s", text)
            self._fault_text = text

    def clear_fault(self) -> None:
        if self._fault_text:
            log.warning("%s: recovered", self.prefix)
            self._fault_text = ""
        if self.comp is not None:
            self.comp["fault"] = False
            self.comp["fault-code"] = FAULT_NONE
