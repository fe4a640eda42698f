"""The WHB04B pendant driver: USB reports in, display data out."""

from __future__ import annotations

import errno
import logging
import time
from typing import Any, Callable, Optional

import usb.core
import usb.util

from halsdk.driverkit import Driver, DriverError

from .protocol import (
    AXIS_NAMES,
    BUTTON_NAMES,
    LEAD_POSITION,
    MODE_CONTINUOUS,
    MODE_LEAD,
    MODE_STEP,
    PERCENTS,
    PRODUCT_ID,
    SET_REPORT,
    SET_REPORT_REQUEST_TYPE,
    SET_REPORT_VALUE,
    STEP_SIZES,
    VENDOR_ID,
    Report,
    ReportError,
    display_chunks,
    encode_display,
    parse_report,
)

log = logging.getLogger("halsdk.driverkit")

INTERFACE = 0
READ_SIZE = 64            # more than a report, so long ones are seen
MAX_REPORTS_PER_CYCLE = 32


def _wrap_s32(value: int) -> int:
    return (value + 0x80000000) % 0x100000000 - 0x80000000


class Whb04bDriver(Driver):
    """XHC WHB04B-6 (and -4) wireless pendant on USB.

    ``backend`` is a pyusb backend (None: pyusb's default, libusb);
    ``comp_name`` names the HAL component (default ``whb04b``) while the
    pins keep the prefix ``whb04b.<num>``.
    """

    name = "whb04b"

    def __init__(self, num: int = 0, comp_name: Optional[str] = None,
                 backend: Any = None, product_id: int = PRODUCT_ID,
                 clock: Callable[[], float] = time.monotonic,
                 read_timeout_ms: int = 10, refresh: float = 1.0,
                 instance: Optional[str] = None):
        super().__init__(num, instance, comp_name=comp_name or self.name)
        self.backend = backend
        self.product_id = product_id
        self.clock = clock
        self.read_timeout_ms = max(1, int(read_timeout_ms))
        self.refresh = refresh
        self.dev: Any = None
        self.endpoint = 0x81
        self.mode = MODE_CONTINUOUS
        self.count = 0
        self._pressed: frozenset[str] = frozenset()
        self._last_read: Optional[float] = None
        self._sent: Optional[bytes] = None
        self._sent_at = 0.0
        self._bad_logged = False

    # -- component ---------------------------------------------------------
    def setup(self) -> None:
        c = self._require()
        for name in BUTTON_NAMES:
            c.newpin(f"button.{name}", "bit", "out")
        self.enc = self.encoder(0)
        for axis in (*AXIS_NAMES, "off"):
            c.newpin(f"axis.{axis}", "bit", "out")
        c.newpin("axis.number", "s32", "out")
        for pin, type_ in (("jog.position", "s32"), ("jog.increment", "float"),
                           ("jog.percent", "float"),
                           ("jog.mode-continuous", "bit"),
                           ("jog.mode-step", "bit"), ("jog.mode-lead", "bit")):
            c.newpin(pin, type_, "out")
        for n, size in enumerate(STEP_SIZES, 1):
            c.newparam(f"jog.increment-{n}", "float", "rw")
            c[f"jog.increment-{n}"] = size
        for axis in AXIS_NAMES:
            c.newpin(f"display.{axis}", "float", "in")
        for pin, type_ in (("display.feed-override", "float"),
                           ("display.spindle-override", "float"),
                           ("display.feed", "float"),
                           ("display.spindle-speed", "float"),
                           ("display.show-speeds", "bit"),
                           ("display.work-coords", "bit"),
                           ("display.reset", "bit")):
            c.newpin(pin, type_, "in")
        c["display.feed-override"] = 1.0
        c["display.spindle-override"] = 1.0
        c.newpin("bad-reports", "u32", "out")
        c.newpin("reports", "u32", "out")
        c["axis.off"] = True
        c["axis.number"] = -1
        self._publish_mode(0)

    # -- device ------------------------------------------------------------
    def open(self) -> None:
        ident = f"USB {VENDOR_ID:04x}:{self.product_id:04x}"
        try:
            dev = usb.core.find(idVendor=VENDOR_ID, idProduct=self.product_id,
                                backend=self.backend)
        except usb.core.NoBackendError:
            raise DriverError("no pyusb backend (is libusb-1.0 installed?)"
                              ) from None
        except usb.core.USBError as exc:
            raise DriverError(f"USB device scan failed: {exc}") from None
        if dev is None:
            raise DriverError(f"no WHB04B pendant ({ident}) found")
        try:
            try:
                if dev.is_kernel_driver_active(INTERFACE):
                    dev.detach_kernel_driver(INTERFACE)
            except NotImplementedError:
                pass
            try:
                cfg = dev.get_active_configuration()
            except usb.core.USBError:
                dev.set_configuration()
                cfg = dev.get_active_configuration()
            intf = cfg[(INTERFACE, 0)]
            ep = usb.util.find_descriptor(
                intf, custom_match=lambda e: usb.util.endpoint_direction(
                    e.bEndpointAddress) == usb.util.ENDPOINT_IN)
            if ep is None:
                raise DriverError(f"{ident} has no IN endpoint")
            usb.util.claim_interface(dev, INTERFACE)
        except usb.core.USBError as exc:
            usb.util.dispose_resources(dev)
            if exc.errno == errno.EACCES:
                raise DriverError(f"no permission to use {ident}: add a "
                                  "udev rule (see the whb04b docs)") from None
            raise DriverError(f"cannot open {ident}: {exc}") from None
        self.dev = dev
        self.endpoint = ep.bEndpointAddress
        self._sent = None
        self._last_read = None

    def close(self) -> None:
        dev, self.dev = self.dev, None
        if self.comp is not None:
            for name in BUTTON_NAMES:          # nothing stays "held"
                self.comp[f"button.{name}"] = False
            self.enc["velocity"] = 0.0
        self._pressed = frozenset()
        if dev is not None:
            try:
                usb.util.dispose_resources(dev)
            except usb.core.USBError:
                pass

    # -- input -------------------------------------------------------------
    def read(self) -> None:
        if self.dev is None:
            raise DriverError("device not open")
        timeout = self.read_timeout_ms
        try:
            for _ in range(MAX_REPORTS_PER_CYCLE):
                try:
                    data = self.dev.read(self.endpoint, READ_SIZE, timeout)
                except usb.core.USBTimeoutError:
                    break
                except usb.core.USBError as exc:
                    raise DriverError(f"USB read: {exc}") from None
                self.handle(bytes(data))
                timeout = 1
        finally:              # what came before an unplug still counts
            self._update_encoder()

    def handle(self, data: bytes) -> None:
        """Apply one raw input report to the pins."""
        c = self._require()
        c["reports"] = (c["reports"] + 1) & 0xFFFFFFFF
        try:
            report = parse_report(data)
        except ReportError as exc:
            c["bad-reports"] = (c["bad-reports"] + 1) & 0xFFFFFFFF
            if not self._bad_logged:
                self._bad_logged = True
                log.warning("%s: ignoring bad report [%s]: %s (further bad "
                            "reports are only counted in bad-reports)",
                            self.prefix, data.hex(" "), exc)
            return
        self._apply(report)

    def _apply(self, report: Report) -> None:
        c = self._require()
        pressed = report.buttons
        for name in BUTTON_NAMES:
            c[f"button.{name}"] = name in pressed
        new = pressed - self._pressed
        if "mode-continuous" in new:
            self.mode = MODE_CONTINUOUS
        elif "mode-step" in new:
            self.mode = MODE_STEP
        self._pressed = pressed
        for axis in (*AXIS_NAMES, "off"):
            c[f"axis.{axis}"] = report.axis == axis
        c["axis.number"] = (AXIS_NAMES.index(report.axis)
                            if report.axis in AXIS_NAMES else -1)
        self._publish_mode(report.feed_position)
        if not self.enc["reset"]:
            self.count = _wrap_s32(self.count + report.wheel)

    def _publish_mode(self, position: int) -> None:
        c = self._require()
        c["jog.position"] = position
        if 1 <= position <= len(STEP_SIZES):
            c["jog.increment"] = c[f"jog.increment-{position}"]
            c["jog.percent"] = PERCENTS[position - 1]
        else:
            c["jog.increment"] = 0.0
            c["jog.percent"] = 0.0
        lead = position == LEAD_POSITION
        c["jog.mode-lead"] = lead
        c["jog.mode-step"] = not lead and self.mode == MODE_STEP
        c["jog.mode-continuous"] = not lead and self.mode == MODE_CONTINUOUS

    def _update_encoder(self) -> None:
        now = self.clock()
        dt = 0.0 if self._last_read is None else now - self._last_read
        self._last_read = now
        if self.enc["reset"]:
            self.count = 0
        self.enc.update(self.count, dt)

    # -- display -----------------------------------------------------------
    def display_bytes(self) -> bytes:
        """The 21 display bytes for the current pin values."""
        c = self._require()
        group = ("a", "b", "c") if c["axis.a"] or c["axis.b"] or c["axis.c"] \
            else ("x", "y", "z")
        if c["display.show-speeds"]:
            feed, spindle = c["display.feed"], c["display.spindle-speed"]
        else:
            feed = c["display.feed-override"] * 100.0
            spindle = c["display.spindle-override"] * 100.0
        mode = MODE_LEAD if c["jog.mode-lead"] else self.mode
        return encode_display([c[f"display.{a}"] for a in group], feed,
                              spindle, mode, c["display.reset"],
                              c["display.work-coords"])

    def write(self) -> None:
        if self.dev is None:
            raise DriverError("device not open")
        body = self.display_bytes()
        now = self.clock()
        if body == self._sent and now - self._sent_at < self.refresh:
            return
        try:
            for chunk in display_chunks(body):
                self.dev.ctrl_transfer(SET_REPORT_REQUEST_TYPE, SET_REPORT,
                                       SET_REPORT_VALUE, INTERFACE, chunk,
                                       timeout=100)
        except usb.core.USBError as exc:
            raise DriverError(f"display update: {exc}") from None
        self._sent = body
        self._sent_at = now
