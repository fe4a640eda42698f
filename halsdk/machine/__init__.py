"""The machine level of halsdk: tool table, toolchanger model and I/O
controller (more pieces follow)."""

from halsdk.machine.iocontrol import IoControl, IoControlError, IoState
from halsdk.machine.tooltable import ToolEntry, ToolTable, ToolTableError

__all__ = ["IoControl", "IoControlError", "IoState", "ToolEntry",
           "ToolTable", "ToolTableError"]
