"""The machine level of halsdk: tool table, toolchanger model and I/O
controller (more pieces follow)."""

from halsdk.machine.api import Machine, MachineStatus
from halsdk.machine.executor import Executor, ExecutorError
from halsdk.machine.iocontrol import IoControl, IoControlError, IoState
from halsdk.machine.task import InterpState, MachineError, TaskMode, TaskState
from halsdk.machine.tooltable import ToolEntry, ToolTable, ToolTableError

__all__ = ["IoControl", "IoControlError", "IoState", "ToolEntry",
           "ToolTable", "ToolTableError",
           "Executor", "ExecutorError", "InterpState", "Machine",
           "MachineError", "MachineStatus", "TaskMode", "TaskState"]
