"""halsdk: a Python SDK of the LinuxCNC-style Hardware Abstraction Layer.

Typical use::

    import halsdk

    with halsdk.Hal() as hal:
        hal.newthread("servo", 1_000_000)
        hal.loadrt("scale", count=2)  # components shipped with halsdk
        hal.addf("scale.0", "servo")
        hal.addf("scale.1", "servo")
        hal.net("cmd", "scale.0.out", "scale.1.in")
        hal.setp("scale.0.in", 1.5)
        hal.setp("scale.0.gain", 2.0)
        hal.setp("scale.1.gain", 1.0)
        hal.step(1000)            # deterministic, simulated time
        print(hal.getp("scale.1.out"))    # 3.0
"""

try:
    __import__("halsdk.core._core")
except ModuleNotFoundError as _exc:      # a checkout, not built
    if _exc.name != "halsdk.core._core":
        raise
    raise ModuleNotFoundError(
        f"halsdk is not built here ({__path__[0]}): pip install -e .",
        name="halsdk.core._core") from None
from halsdk.component import Component, component
from halsdk.core import _core  # noqa: E402
from halsdk.core.instance import cleanup
from halsdk.errors import (
                           CapacityError,
                           ConflictError,
                           DamagedError,
                           ExistsError,
                           HalError,
                           HalTypeError,
                           HostGoneError,
                           InstanceError,
                           InvalidError,
                           LoadError,
                           LockTimeoutError,
                           NotFoundError,
                           NotPermittedError,
                           Rule,
                           StaleError,
                           TrustError,
)
from halsdk.hal import Hal, check_name
from halsdk.types import Direction, HalType

Pin = _core.Pin
Param = _core.Param
Signal = _core.Signal
Function = _core.Function
Thread = _core.Thread
Instance = _core.Instance
Stream = _core.Stream

BIT, FLOAT, S32, U32, S64, U64 = (HalType.BIT, HalType.FLOAT, HalType.S32,
                                  HalType.U32, HalType.S64, HalType.U64)
IN, OUT, IO, RO, RW = (Direction.IN, Direction.OUT, Direction.IO,
                       Direction.RO, Direction.RW)
NAME_LEN = _core.NAME_LEN
REFERENCE_NAME_LEN = 47

__version__ = "0.1.0"

__all__ = [
    "Hal", "component", "Component", "cleanup", "HalType", "Direction",
    "Pin", "Param", "Signal", "Function", "Thread", "Instance", "Stream",
    "check_name", "Rule",
    "BIT", "FLOAT", "S32", "U32", "S64", "U64", "IN", "OUT", "IO", "RO",
    "RW", "NAME_LEN", "REFERENCE_NAME_LEN",
    "HalError", "NotFoundError", "ExistsError", "HalTypeError",
    "ConflictError", "NotPermittedError", "InvalidError", "CapacityError",
    "InstanceError", "DamagedError", "StaleError", "LoadError",
    "TrustError", "LockTimeoutError", "HostGoneError",
]
