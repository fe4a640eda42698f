"""The task thread of ``halsdk run``: the machine operated from any process.

:class:`TaskRunner` owns the :class:`~halsdk.machine.controller.TaskController`
of a started machine and runs it on a thread of its own, at the fixed
rate of ``[TASK]CYCLE_TIME`` (default 10 ms).  Every cycle it

1. serves the command channel (a Unix socket, :mod:`halsdk.channels.cmdserver`)
   until the cycle is due, issuing each command as it arrives, so a
   command is taken at once rather than at the next cycle;
2. runs one controller cycle (interpreter, canon queue, tickets); when the
   machine's threads are stepped rather than realtime, steps the servo
   thread by one task cycle's worth of servo periods;
3. posts new messages to the error channel and publishes the status
   snapshot (both in the ``task.channel`` shared block,
   :mod:`halsdk.channels.shmchannel`); the tool table only when it changed;
4. answers the commands that finished (RCS_DONE or RCS_ERROR with the
   reason), after the status that shows their effect.

One task per instance: a second one finds the shared block and is refused
with the pid of the first.  An unexpected error inside a cycle is
reported on the error channel once and puts the machine in E-stop (fail
safe); the thread goes on so that clients can see what happened.
"""

from __future__ import annotations

import os
import sys
import threading
import time
import traceback
from typing import Any, Optional

from halsdk.channels.cmdserver import CommandServer
from halsdk.channels.shmchannel import (
    BLOCK_NAME,
    StatusReader,
    StatusWriter,
    block_size,
)
from halsdk.errors import HalError, NotFoundError
from halsdk.machine.controller import OPERATOR_ERROR, TaskController, Ticket
from halsdk.machine.task import MachineError, TaskState

__all__ = ["TaskRunner", "TaskError", "DEFAULT_CYCLE_TIME"]

DEFAULT_CYCLE_TIME = 0.010


class TaskError(HalError):
    """The task could not start (another task runs on the instance, ...)."""


def _cycle_time(ini: Any) -> float:
    text = ini.get("TASK", "CYCLE_TIME")
    if text is None or not str(text).strip():
        return DEFAULT_CYCLE_TIME
    try:
        value = float(str(text).split()[0])
    except ValueError:
        raise TaskError(f"{ini.where('TASK', 'CYCLE_TIME')}: CYCLE_TIME "
                        f"'{text}' is not a number of seconds") from None
    if not 0.0005 <= value <= 1.0:
        raise TaskError(f"{ini.where('TASK', 'CYCLE_TIME')}: CYCLE_TIME "
                        f"{value:g} s is outside 0.0005 to 1 s")
    return value


class TaskRunner:
    """The task of a started :class:`~halsdk.machine.launcher.Launcher`.

    ``realtime``: the HAL threads run by themselves (``hal.start()`` was
    called); otherwise every task cycle steps the servo thread.
    ``controller``: an existing controller to serve (default: one made
    for the launcher's machine).
    """

    def __init__(self, launcher: Any, *, realtime: bool = True,
                 cycle_time: Optional[float] = None,
                 controller: Optional[TaskController] = None,
                 thread: str = "servo-thread") -> None:
        self.hal = launcher.hal
        self.ini = launcher.ini
        self.realtime = realtime
        self.thread_name = thread
        self.cycle_time = cycle_time or _cycle_time(self.ini)
        self._refuse_second_task()
        if controller is None:
            hal, motion, io, units = launcher.controller_parts(thread=thread)
            controller = TaskController(hal, motion, io, units=units,
                                        thread=thread)
            controller.configure_from_ini(self.ini)
        self.ctl = controller
        self._comp = self.hal.new_component("task")
        self._comp.ready()
        address, size = self.hal.new_shared_block(BLOCK_NAME, block_size(),
                                                  self._comp)
        self.status = StatusWriter(address, size, os.getpid())
        self._pending: list[Ticket] = []
        self._reported: set[str] = set()
        self._stop = threading.Event()
        self._steps = 1
        if not realtime:
            period = self.ctl.motion.status().servo_period or 0.001
            self._steps = max(1, round(self.cycle_time / period))
        self._take_io_poll()
        self._publish()                 # a client never sees an empty one
        self.server = CommandServer(self.hal.private_socket_path("task"),
                                    submit=self._submit,
                                    report=self._report,
                                    task_pid=os.getpid())
        self._thread = threading.Thread(target=self._run, name="halsdk-task",
                                        daemon=True)

    def _take_io_poll(self) -> None:
        """The I/O controller is polled by the task cycle, as LinuxCNC's
        ``io`` runs beside its task, not in the servo thread: a Python
        function in the realtime thread would wait for the interpreter
        lock the task thread holds (a priority inversion of milliseconds
        every cycle)."""
        for function in self.hal.functions("iocontrol.0.poll"):
            for thread in self.hal.threads():
                if function.name in getattr(thread, "functions", ()):
                    self.hal.delf(function.name, thread.name)

    def _refuse_second_task(self) -> None:
        try:
            address, size = self.hal.shared_block(BLOCK_NAME)
        except NotFoundError:
            return
        try:
            pid = StatusReader(address, size).poll().task_pid
            who = f" (pid {pid})"
        except HalError:
            who = ""
        raise TaskError(f"instance '{self.hal.instance}' has a task "
                        f"already{who}: one machine per instance (stop "
                        "it first, or use another HALSDK_INSTANCE)")

    # ------------------------------------------------------------ control

    def start(self) -> None:
        """Start the task thread."""
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop the thread, tell the clients (the status channel says
        ``closed``, the socket closes) and save the parameters."""
        self._stop.set()
        if self._thread.is_alive() and \
                threading.current_thread() is not self._thread:
            self._thread.join(timeout)
        try:
            self.server.close()
        finally:
            self.status.close()
            self.ctl.executor.shutdown()
            try:
                self.ctl.save_parameters()
            except (OSError, HalError) as e:
                print(f"halsdk run: saving the parameters: {e}",
                      file=sys.stderr)

    @property
    def running(self) -> bool:
        return self._thread.is_alive()

    # ------------------------------------------------------------ the loop

    def _submit(self, peer: Any, serial: int, name: str, args: dict) -> None:
        try:
            ticket = self.ctl.issue(name, args, serial=serial, owner=peer)
        except Exception as e:          # a bug must not kill the task
            self._internal(e)
            self.server.reply(peer, serial, 3, f"{name}: internal error: "
                              f"{e}")
            return
        if ticket.done:
            try:
                self._publish()         # the effect is visible first
            except Exception as e:
                self._internal(e)
            self.server.reply(peer, serial, ticket.state, ticket.error)
        else:
            self._pending.append(ticket)

    def _report(self, text: str) -> None:
        self.ctl.post(OPERATOR_ERROR, f"task: {text}")

    def _internal(self, e: BaseException) -> None:
        text = f"task: internal error: {type(e).__name__}: {e}"
        if text not in self._reported:
            self._reported.add(text)
            traceback.print_exc(file=sys.stderr)
            self.ctl.post(OPERATOR_ERROR, text + " (machine put in E-stop)")
        try:
            self.ctl.issue("state", {"state": int(TaskState.ESTOP)})
        except Exception:
            pass

    def _run(self) -> None:
        due = time.monotonic()
        while not self._stop.is_set():
            now = time.monotonic()
            if now < due:
                try:
                    self.server.service(due - now)
                except Exception as e:
                    self._internal(e)
                    time.sleep(min(due - now, self.cycle_time))
                continue
            due += self.cycle_time
            if due < now:               # fell behind: do not catch up
                due = now + self.cycle_time
            self.cycle()

    def cycle(self) -> None:
        """One task cycle (steps 2 to 4 of the module docstring)."""
        try:
            self.ctl.io.poll()
            self.ctl.cycle()
        except MachineError:
            pass                        # posted by the controller
        except Exception as e:
            self._internal(e)
        if not self.realtime:
            try:
                self.hal.step(self._steps, thread=self.thread_name)
            except HalError as e:
                self._internal(e)
        # the status first: a client that sees its command done and then
        # polls finds the state the command left
        try:
            self._publish()
        except Exception as e:
            self._internal(e)
        still = []
        for ticket in self._pending:
            if ticket.done:
                self.server.reply(ticket.owner, ticket.serial, ticket.state,
                                  ticket.error)
            else:
                still.append(ticket)
        self._pending = still

    def _publish(self) -> None:
        for kind, text in self.ctl.take_messages():
            self.status.post(kind, text)
        if self.ctl.tool_table_changed():
            self.status.publish_tools(self.ctl.tool_generation,
                                      self.ctl.tool_entries())
        self.status.publish(self.ctl.snapshot())
