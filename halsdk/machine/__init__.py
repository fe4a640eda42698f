"""The machine level of halsdk: the task controller (in-process
:class:`Machine`, or hosted by ``halsdk run`` and reached with
:func:`connect`), the I/O controller, the tool table and the launcher.

The names below are imported when first used, so that a small client
(``halsdk ctl``) does not load the interpreter and the task code.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from halsdk.machine.api import Machine, MachineStatus
    from halsdk.machine.client import (
        ChannelError,
        ChannelGone,
        Command,
        MachineClient,
        MachineTimeout,
        RemoteStatus,
        connect,
    )
    from halsdk.machine.controller import TaskController, Ticket
    from halsdk.machine.executor import Executor, ExecutorError
    from halsdk.machine.iocontrol import IoControl, IoControlError, IoState
    from halsdk.machine.task import (
        InterpState,
        MachineError,
        TaskMode,
        TaskState,
    )
    from halsdk.machine.tooltable import ToolEntry, ToolTable, ToolTableError

#: public name -> the module that defines it
_WHERE = {
    "Machine": "api", "MachineStatus": "api",
    "ChannelError": "client", "ChannelGone": "client", "Command": "client",
    "MachineClient": "client", "MachineTimeout": "client",
    "RemoteStatus": "remote_status", "connect": "client",
    "TaskController": "controller", "Ticket": "controller",
    "Executor": "executor", "ExecutorError": "executor",
    "IoControl": "iocontrol", "IoControlError": "iocontrol",
    "IoState": "iocontrol",
    "InterpState": "task", "MachineError": "task", "TaskMode": "task",
    "TaskState": "task",
    "ToolEntry": "tooltable", "ToolTable": "tooltable",
    "ToolTableError": "tooltable",
}

__all__ = [
    "ChannelError",
    "ChannelGone",
    "Command",
    "Executor",
    "ExecutorError",
    "InterpState",
    "IoControl",
    "IoControlError",
    "IoState",
    "Machine",
    "MachineClient",
    "MachineError",
    "MachineStatus",
    "MachineTimeout",
    "RemoteStatus",
    "TaskController",
    "TaskMode",
    "TaskState",
    "Ticket",
    "ToolEntry",
    "ToolTable",
    "ToolTableError",
    "connect",
]


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'halsdk.machine' has no attribute "
                             f"{name!r}")
    value = getattr(importlib.import_module(f"halsdk.machine.{module}"),
                    name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_WHERE))
