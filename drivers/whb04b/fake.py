"""A pyusb backend that plays a recorded WHB04B session.

The recording is a text file, one item a line::

    # comment (also after an item)
    04 3a 00 00 0d 11 01 00     an input report, hex bytes
    pause 0.5                   no reports for 0.5 s (reads time out)
    unplug                      the device goes away
    plug                        the device comes back

Reports may have any length, so that short or long ones can be replayed.
While unplugged, the script advances when the host looks for devices,
so ``unplug`` / ``pause 1`` / ``plug`` keeps the device away for a
second.  After the last line the device stays connected and idle.
Display writes (control transfers) are kept in :attr:`FakeBackend.control`.
"""

from __future__ import annotations

import array
import errno
import math
import re
import time
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Callable, Optional, Union

import usb.backend
import usb.core

from .protocol import PRODUCT_ID, VENDOR_ID

IN_ENDPOINT = 0x81
#: longest ``pause`` of a replay file, in seconds
MAX_PAUSE = 3600.0
_HEX_BYTE = re.compile(r"[0-9a-fA-F]{2}")


class ScriptError(ValueError):
    """A bad line in a replay file (the message names file and line)."""


@dataclass(frozen=True)
class Step:
    kind: str                  # "report", "pause", "unplug" or "plug"
    data: bytes = b""
    seconds: float = 0.0


def parse_script(lines: Iterable[str], source: str = "<script>"
                 ) -> list[Step]:
    """Parse replay lines; :class:`ScriptError` names ``source:line``."""
    steps = []
    for number, line in enumerate(lines, 1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        words = text.split()
        where = f"{source}:{number}"
        if words[0] in ("unplug", "plug") and len(words) == 1:
            steps.append(Step(words[0]))
        elif words[0] == "pause":
            try:
                seconds = float(words[1]) if len(words) == 2 else -1.0
            except ValueError:
                seconds = -1.0
            if not (math.isfinite(seconds) and 0 <= seconds <= MAX_PAUSE):
                raise ScriptError(f"{where}: 'pause' needs one number of "
                                  f"seconds from 0 to {MAX_PAUSE:g}")
            steps.append(Step("pause", seconds=seconds))
        else:
            bad = [w for w in words if not _HEX_BYTE.fullmatch(w)]
            if bad and all(re.fullmatch(r"[0-9a-fA-F]+", w) for w in bad):
                raise ScriptError(f"{where}: hex bytes are two digits each, "
                                  f"not {bad[0]!r}")
            if bad:
                raise ScriptError(f"{where}: expected hex bytes, 'pause S', "
                                  f"'plug' or 'unplug', got {text!r}")
            steps.append(Step("report", data=bytes.fromhex("".join(words))))
    return steps


def load_script(path: Union[str, Path]) -> list[Step]:
    """Read a replay file; :class:`ScriptError` when unreadable or bad."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise ScriptError(f"{path}: cannot read: {exc.strerror or exc}"
                          ) from None
    except UnicodeDecodeError as exc:
        raise ScriptError(f"{path}: cannot read: not UTF-8 text (byte "
                          f"{exc.start})") from None
    return parse_script(text.splitlines(), str(path))


def _device_descriptor(product_id: int) -> SimpleNamespace:
    return SimpleNamespace(
        bLength=18, bDescriptorType=1, bcdUSB=0x0200, bDeviceClass=0,
        bDeviceSubClass=0, bDeviceProtocol=0, bMaxPacketSize0=64,
        idVendor=VENDOR_ID, idProduct=product_id, bcdDevice=0x0100,
        iManufacturer=0, iProduct=0, iSerialNumber=0, bNumConfigurations=1,
        address=7, bus=1, port_number=1, port_numbers=(1,), speed=2)


_CONFIG = SimpleNamespace(
    bLength=9, bDescriptorType=2, wTotalLength=34, bNumInterfaces=1,
    bConfigurationValue=1, iConfiguration=0, bmAttributes=0x80,
    bMaxPower=50, extra_descriptors=[])
_INTERFACE = SimpleNamespace(
    bLength=9, bDescriptorType=4, bInterfaceNumber=0, bAlternateSetting=0,
    bNumEndpoints=1, bInterfaceClass=3, bInterfaceSubClass=0,
    bInterfaceProtocol=0, iInterface=0, extra_descriptors=[])
_ENDPOINT = SimpleNamespace(
    bLength=7, bDescriptorType=5, bEndpointAddress=IN_ENDPOINT,
    bmAttributes=0x03, wMaxPacketSize=8, bInterval=2, bRefresh=0,
    bSynchAddress=0, extra_descriptors=[])


def _gone() -> usb.core.USBError:
    return usb.core.USBError("No such device (it may have been "
                             "disconnected)", -4, errno.ENODEV)


class FakeBackend(usb.backend.IBackend):
    """One simulated pendant driven by a list of :class:`Step`."""

    def __init__(self, steps: Iterable[Step] = (),
                 clock: Callable[[], float] = time.monotonic,
                 product_id: int = PRODUCT_ID):
        self.steps: deque[Step] = deque(steps)
        self.clock = clock
        self.product_id = product_id
        self.present = True
        self.claimed = False
        self.opens = 0
        #: display writes: (bmRequestType, bRequest, wValue, wIndex, data)
        self.control: list[tuple[int, int, int, int, bytes]] = []
        self._pause_until: Optional[float] = None
        self._handle = 0

    # -- script ------------------------------------------------------------
    def add(self, *steps: Step) -> None:
        self.steps.extend(steps)

    def feed(self, *reports: Union[bytes, str]) -> None:
        """Queue reports given as bytes or hex text."""
        for r in reports:
            data = bytes.fromhex(r) if isinstance(r, str) else bytes(r)
            self.steps.append(Step("report", data=data))

    def _paused(self) -> bool:
        """True while the pause at the head of the script runs."""
        step = self.steps[0]
        now = self.clock()
        if self._pause_until is None:
            self._pause_until = now + step.seconds
        if now < self._pause_until:
            return True
        self._pause_until = None
        self.steps.popleft()
        return False

    def _advance_unplugged(self) -> None:
        while not self.present and self.steps:
            step = self.steps[0]
            if step.kind == "pause":
                if self._paused():
                    return
            elif step.kind == "plug":
                self.steps.popleft()
                self.present = True
            else:          # reports sent while away are lost
                self.steps.popleft()

    def _check(self, handle: int) -> None:
        if not self.present or handle != self._handle:
            raise _gone()

    # -- enumeration and descriptors ---------------------------------------
    def enumerate_devices(self):
        if self.steps and self.steps[0].kind == "unplug":
            self.steps.popleft()
            self.present = False
        self._advance_unplugged()
        if self.present:
            yield "whb04b-fake"

    def get_device_descriptor(self, dev):
        return _device_descriptor(self.product_id)

    def get_configuration_descriptor(self, dev, config):
        if config != 0:
            raise IndexError("one configuration")
        return _CONFIG

    def get_interface_descriptor(self, dev, intf, alt, config):
        if (intf, alt, config) != (0, 0, 0):
            raise IndexError("one interface, one setting")
        return _INTERFACE

    def get_endpoint_descriptor(self, dev, ep, intf, alt, config):
        if (ep, intf, alt, config) != (0, 0, 0, 0):
            raise IndexError("one endpoint")
        return _ENDPOINT

    def get_parent(self, dev):
        return None

    # -- handle ------------------------------------------------------------
    def open_device(self, dev):
        if not self.present:
            raise _gone()
        self.opens += 1
        self._handle += 1
        return self._handle

    def close_device(self, dev_handle):
        self.claimed = False

    def set_configuration(self, dev_handle, config_value):
        self._check(dev_handle)

    def get_configuration(self, dev_handle):
        self._check(dev_handle)
        return 1

    def claim_interface(self, dev_handle, intf):
        self._check(dev_handle)
        self.claimed = True

    def release_interface(self, dev_handle, intf):
        self.claimed = False
        self._check(dev_handle)

    def is_kernel_driver_active(self, dev_handle, intf):
        self._check(dev_handle)
        return False

    def detach_kernel_driver(self, dev_handle, intf):
        self._check(dev_handle)

    def attach_kernel_driver(self, dev_handle, intf):
        self._check(dev_handle)

    # -- transfers ---------------------------------------------------------
    def intr_read(self, dev_handle, ep, intf, buff, timeout):
        self._check(dev_handle)
        while self.steps:
            step = self.steps[0]
            if step.kind == "pause":
                if self._paused():
                    break
            elif step.kind == "unplug":
                self.steps.popleft()
                self.present = False
                raise _gone()
            elif step.kind == "plug":
                self.steps.popleft()
            else:
                self.steps.popleft()
                n = min(len(step.data), len(buff) * buff.itemsize)
                buff[:n] = array.array("B", step.data[:n])
                return n
        raise usb.core.USBTimeoutError("Operation timed out", -7,
                                       errno.ETIMEDOUT)

    def ctrl_transfer(self, dev_handle, bmRequestType, bRequest, wValue,
                      wIndex, data, timeout):
        self._check(dev_handle)
        if bmRequestType & 0x80:          # no strings or reports to read
            raise usb.core.USBError("Pipe error", -9, errno.EPIPE)
        payload = bytes(data) if data is not None else b""
        self.control.append((bmRequestType, bRequest, wValue, wIndex,
                             payload))
        return len(payload)

    # -- for tests ---------------------------------------------------------
    def unplug(self) -> None:
        self.present = False

    def plug(self) -> None:
        self.present = True

    def display_writes(self) -> list[bytes]:
        """Data of the SET_REPORT transfers, in order."""
        return [c[4] for c in self.control if c[:2] == (0x21, 0x09)]
