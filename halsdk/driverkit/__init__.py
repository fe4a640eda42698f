"""SDK for userspace HAL drivers written in Python: the :class:`Driver`
base class, canonical channel helpers and the :class:`IOLoop`."""

from halsdk.driverkit.backoff import Backoff
from halsdk.driverkit.base import (
                                FAULT_NONE,
                                FAULT_OPEN,
                                FAULT_READ,
                                FAULT_WRITE,
                                Driver,
                                DriverError,
)
from halsdk.driverkit.canonical import AdcIn, DacOut, DigIn, DigOut, Encoder
from halsdk.driverkit.loop import STAT_PINS, IOLoop

__all__ = ["Backoff", "Driver", "DriverError", "IOLoop", "STAT_PINS", "DigIn", "DigOut",
           "AdcIn", "DacOut", "Encoder", "FAULT_NONE", "FAULT_OPEN",
           "FAULT_READ", "FAULT_WRITE"]
