"""The I/O controller: the userspace HAL component ``iocontrol.0``.

It owns the E-stop chain, coolant and lube outputs and the toolchanger
handshakes, with the pin names of the reference ``io`` program.  Nothing in
here blocks: a command method sets outputs and starts a handshake, and
:meth:`IoControl.poll`, called once per cycle by the owner (a task loop, a
test, or a Python function run by a thread), reads the inputs and moves the
state machines on.  Timeouts are counted in poll cycles.

E-stop chain::

    ESTOP --estop_reset()--> RESETTING --emc-enable-in TRUE--> ESTOP_RESET
    ESTOP_RESET --machine_on()--> ON --machine_off()--> ESTOP_RESET
    any --estop() or emc-enable-in FALSE--> ESTOP

Tool handshakes (``tool_state``)::

    IDLE --prepare(n)--> PREPARING --tool-prepared--> IDLE (tool prepped)
    IDLE --change()--> CHANGING --tool-changed--> IDLE (table updated)
"""

from __future__ import annotations

import enum
from typing import Any, Optional

from halsdk.component import Component, component
from halsdk.errors import HalError
from halsdk.machine.tooltable import ToolTable

__all__ = ["IoControl", "IoControlError", "IoState", "PINS", "ToolState"]

#: (name, type, direction) of every pin, as the reference ``io`` has them.
PINS: tuple[tuple[str, str, str], ...] = (
    ("coolant-flood", "bit", "out"),
    ("coolant-mist", "bit", "out"),
    ("emc-enable-in", "bit", "in"),
    ("lube", "bit", "out"),
    ("lube_level", "bit", "in"),
    ("tool-change", "bit", "out"),
    ("tool-changed", "bit", "in"),
    ("tool-number", "s32", "out"),
    ("tool-prep-number", "s32", "out"),
    ("tool-prep-pocket", "s32", "out"),
    ("tool-prep-index", "s32", "out"),
    ("tool-prepare", "bit", "out"),
    ("tool-prepared", "bit", "in"),
    ("tool-from-pocket", "s32", "out"),
    ("user-enable-out", "bit", "out"),
    ("user-request-enable", "bit", "out"),
)


class IoControlError(HalError, RuntimeError):
    """A command the I/O controller cannot carry out now, or a handshake
    that timed out."""


class IoState(enum.Enum):
    ESTOP = "estop"
    RESETTING = "resetting"
    ESTOP_RESET = "estop-reset"
    ON = "on"


class ToolState(enum.Enum):
    IDLE = "idle"
    PREPARING = "preparing"
    CHANGING = "changing"


class IoControl:
    """The ``iocontrol.0`` component driving a :class:`ToolTable`.

    ``timeout`` (poll cycles, None: wait forever) bounds each handshake:
    the E-stop reset waiting for ``emc-enable-in``, the tool prepare and the
    tool change.  A timed-out handshake drops its request pin, records the
    reason in :attr:`error` and returns to idle.
    """

    def __init__(self, table: Optional[ToolTable] = None, *,
                 name: str = "iocontrol", prefix: str = "iocontrol.0",
                 timeout: Optional[int] = None,
                 instance: Optional[str] = None) -> None:
        self.table = table if table is not None else ToolTable()
        self.timeout = timeout
        self.comp: Component = component(name, prefix, instance)
        try:
            for pin, type_, direction in PINS:
                self.comp.newpin(pin, type_, direction)
            self.comp.ready()
        except BaseException:
            self.comp.exit()
            raise
        self.state = IoState.ESTOP
        self.tool_state = ToolState.IDLE
        #: internal pocket whose prepare the toolchanger confirmed, or None
        self.prepped_pocket: Optional[int] = None
        #: the last handshake failure (or external E-stop), None if none
        self.error: Optional[str] = None
        #: completed tool changes
        self.changes = 0
        self._cycles = 0
        self._pulse = False
        self.comp["tool-number"] = self.table.tool_in_spindle

    # -- helpers -------------------------------------------------------------

    def __getitem__(self, pin: str) -> Any:
        return self.comp[pin]

    def _set(self, pin: str, value: Any) -> None:
        self.comp[pin] = value

    def close(self) -> None:
        """Remove the component and its pins."""
        self.comp.exit()

    def __enter__(self) -> IoControl:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    @property
    def busy(self) -> bool:
        """True while a tool handshake or the E-stop reset is under way."""
        return (self.tool_state is not ToolState.IDLE
                or self.state is IoState.RESETTING)

    def _timed_out(self) -> bool:
        self._cycles += 1
        return self.timeout is not None and self._cycles > self.timeout

    # -- E-stop chain ------------------------------------------------------

    def estop(self, reason: Optional[str] = None) -> None:
        """Enter E-stop: drop user-enable-out, lube and coolant, abort any
        tool handshake."""
        self.state = IoState.ESTOP
        self._set("user-enable-out", False)
        self._set("user-request-enable", False)
        self._pulse = False
        for pin in ("lube", "coolant-mist", "coolant-flood"):
            self._set(pin, False)
        self.abort()
        if reason is not None:
            self.error = reason

    def estop_reset(self) -> None:
        """Ask to leave E-stop: raise user-enable-out and pulse
        user-request-enable for one cycle; the reset completes in
        :meth:`poll` once emc-enable-in reads TRUE."""
        if self.state is not IoState.ESTOP:
            return
        self.error = None
        self.state = IoState.RESETTING
        self._cycles = 0
        self._set("user-enable-out", True)
        self._set("user-request-enable", True)
        self._pulse = True

    def machine_on(self) -> None:
        if self.state is IoState.ON:
            return
        if self.state is not IoState.ESTOP_RESET:
            raise IoControlError(f"cannot turn the machine on from "
                                 f"{self.state.value}")
        self.state = IoState.ON

    def machine_off(self) -> None:
        if self.state is IoState.ON:
            self.abort()
            self._set("coolant-mist", False)
            self._set("coolant-flood", False)
            self.state = IoState.ESTOP_RESET

    # -- coolant and lube ----------------------------------------------------

    def _outputs_allowed(self, what: str) -> None:
        if self.state in (IoState.ESTOP, IoState.RESETTING):
            raise IoControlError(f"{what} refused: the machine is in E-stop")

    def mist(self, on: bool) -> None:
        """M7 (on) / M9 (off)."""
        if on:
            self._outputs_allowed("mist coolant")
        self._set("coolant-mist", bool(on))

    def flood(self, on: bool) -> None:
        """M8 (on) / M9 (off)."""
        if on:
            self._outputs_allowed("flood coolant")
        self._set("coolant-flood", bool(on))

    def lube(self, on: bool) -> None:
        if on:
            self._outputs_allowed("lube")
        self._set("lube", bool(on))

    @property
    def lube_level_ok(self) -> bool:
        return bool(self.comp["lube_level"])

    # -- tools ---------------------------------------------------------------

    def _check_tool_command(self, what: str) -> None:
        if self.state is not IoState.ON:
            raise IoControlError(f"{what} refused: the machine is not on")
        if self.tool_state is not ToolState.IDLE:
            raise IoControlError(f"{what} refused: the tool handshake "
                                 f"'{self.tool_state.value}' is under way")

    def prepare(self, tool: int) -> None:
        """Txxx: set tool-prep-number/-pocket/-index and raise
        tool-prepare; :meth:`poll` completes it on tool-prepared."""
        self._check_tool_command(f"T{tool}")
        pocket = self.table.prepare(tool)
        self._set("tool-prep-number", tool)
        self._set("tool-prep-pocket", self.table.file_pocket(pocket))
        self._set("tool-prep-index", pocket)
        self._set("tool-prepare", True)
        self.prepped_pocket = None
        self.tool_state = ToolState.PREPARING
        self._cycles = 0

    def change(self) -> None:
        """M6: raise tool-change; :meth:`poll` updates the table and
        tool-number on tool-changed."""
        self._check_tool_command("M6")
        if self.prepped_pocket is None:
            raise IoControlError("M6 refused: no tool prepared (T word)")
        self._set("tool-change", True)
        self.tool_state = ToolState.CHANGING
        self._cycles = 0

    def set_tool_number(self, tool: int) -> None:
        """M61 Qn: record ``tool`` as loaded, without a handshake."""
        self._check_tool_command(f"M61 Q{tool}")
        self.table.set_tool_number(tool)
        self._set("tool-number", self.table.tool_in_spindle)
        if tool == 0:
            self._set("tool-from-pocket", 0)

    def set_offsets(self, tool: int, **data: Any) -> int:
        """G10 L1/L10/L11: see :meth:`ToolTable.set_offsets`."""
        return self.table.set_offsets(tool, **data)

    def abort(self) -> None:
        """Drop any tool handshake in progress."""
        self._set("tool-prepare", False)
        self._set("tool-change", False)
        self.tool_state = ToolState.IDLE
        if self.state is IoState.RESETTING:
            self.state = IoState.ESTOP

    # -- the cycle -------------------------------------------------------------

    def attach(self, hal: Any, thread: str,
               function: str = "iocontrol.0.poll") -> None:
        """Run :meth:`poll` as a (non-realtime) Python function of HAL
        thread ``thread``; ``hal`` is the hosting :class:`halsdk.Hal`."""
        hal.add_python_function(function, lambda period: self.poll(),
                                thread=thread)

    def poll(self) -> None:
        """One cycle: read the inputs and advance the state machines."""
        if self._pulse:
            self._set("user-request-enable", False)
            self._pulse = False
        enabled = bool(self.comp["emc-enable-in"])
        if self.state is IoState.RESETTING:
            if enabled:
                self.state = IoState.ESTOP_RESET
                self._set("lube", True)
            elif self._timed_out():
                self.estop("E-stop reset timed out: emc-enable-in stayed "
                           "FALSE")
            return
        if self.state is not IoState.ESTOP and not enabled:
            self.estop("external E-stop (emc-enable-in FALSE)")
            return
        if self.tool_state is ToolState.PREPARING:
            if self.comp["tool-prepared"]:
                self._set("tool-prepare", False)
                self.prepped_pocket = self.table.selected_pocket
                self.tool_state = ToolState.IDLE
            elif self._timed_out():
                self._fail("tool prepare timed out (tool-prepared never "
                           "came)")
        elif self.tool_state is ToolState.CHANGING:
            if self.comp["tool-changed"]:
                self._set("tool-change", False)
                from_pocket = self.table.file_pocket(
                    self.table.selected_pocket or 0)
                try:
                    self.table.change()
                except OSError as e:
                    # the tool did change; only writing the file failed
                    self.error = f"tool table not saved: {e}"
                self._set("tool-number", self.table.tool_in_spindle)
                self._set("tool-from-pocket", from_pocket)
                for pin in ("tool-prep-number", "tool-prep-pocket",
                            "tool-prep-index"):
                    self._set(pin, 0)
                self.prepped_pocket = None
                self.tool_state = ToolState.IDLE
                self.changes += 1
            elif self._timed_out():
                self._fail("tool change timed out (tool-changed never "
                           "came)")

    def _fail(self, message: str) -> None:
        self.abort()
        self.error = message
