"""A client's end of the task's command channel.

:class:`CommandClient` connects to the socket of a running machine, sends
commands with serial numbers (1, 2, ... per connection, as the reference's
``linuxcnc.command().serial``) and follows their replies: received
(``RCS_EXEC``), done (``RCS_DONE``) or refused with the reason
(``RCS_ERROR``).

Nothing waits for ever unless asked to: the connection, the handshake and
each send have the client's ``timeout``; :meth:`CommandClient.wait` has
its own. When the task goes away, the next call raises
:class:`ChannelGone`.

One client may be shared by threads: sends are serialized, and a thread
waiting for a reply reads the replies of the others too.
"""

from __future__ import annotations

import errno
import os
import select
import socket
import threading
import time
from typing import Any, NoReturn, Optional

from halsdk.channels import cmdproto, sockfile
from halsdk.channels.cmdproto import (
    PROTOCOL_VERSION,
    RCS_DONE,
    RCS_ERROR,
    RCS_EXEC,
    CommandError,
    FrameError,
    FrameReader,
)
from halsdk.channels.errors import ChannelError, ChannelGone
from halsdk.errors import InvalidError

__all__ = ["CommandClient"]

#: replies remembered: older serials are forgotten
KEEP = 10000
_RECV_SIZE = 1 << 16
_FINAL = (RCS_DONE, RCS_ERROR)
_TAKEN = (RCS_EXEC, RCS_DONE, RCS_ERROR)
_GONE_ERRNOS = (errno.EPIPE, errno.ECONNRESET, errno.ECONNREFUSED,
                errno.ENOTCONN, errno.ESHUTDOWN)


def _instance_of(path: str) -> str:
    """The instance a task socket belongs to, in words: its file is
    ``halsdk-UID[-NAME].task.sock`` (``Hal.private_socket_path``)."""
    base = os.path.basename(path)
    for suffix in (".task.sock", ".sock"):
        if base.endswith(suffix):
            base = base[:-len(suffix)]
            break
    prefix = f"halsdk-{os.getuid()}"
    if base == prefix:
        return "default"
    if base.startswith(prefix + "-"):
        return base[len(prefix) + 1:]
    return base


class CommandClient:
    """A connection to the command channel of a running task.

    :param path: the task's socket (``Hal.private_socket_path("task")``).
    :param name: how the task's reports name this client.
    :param timeout: seconds for the connection, the handshake and each
        send.
    :raises ChannelError: no machine runs there, the task refused this
        client (another protocol version: the message says which), or it
        did not answer in time.
    """

    def __init__(self, path: str, name: str = "client",
                 timeout: float = 5.0) -> None:
        self.path = path
        self.name = name
        self.timeout = timeout
        self.serial = 0                 # last serial sent
        self.task_pid = 0
        self._states: dict[int, int] = {}
        self._errors: dict[int, str] = {}
        self._forgotten = 0             # serials up to this one forgotten
        self._reader = FrameReader()
        self._send_lock = threading.Lock()
        # one thread at a time reads (the "reader"); the others wait on the
        # condition, notified each time replies came in
        self._cond = threading.Condition()
        self._reading = False
        self._failure: Optional[ChannelError] = None
        self._closed = False
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            self._connect()
        except BaseException:
            self._sock.close()
            raise

    # ------------------------------------------------------------ setup

    def _connect(self) -> None:
        path, instance = self.path, _instance_of(self.path)
        refused = sockfile.refusal(path)
        if refused is not None:
            raise ChannelError(f"cannot reach the task of instance "
                               f"{instance}: {refused}")
        self._sock.settimeout(self.timeout)
        try:
            self._sock.connect(path)
        except FileNotFoundError:
            raise ChannelError(
                f"no machine is running on instance {instance} (no task "
                f"socket at {path}); start one with `halsdk run "
                "MACHINE.ini`") from None
        except ConnectionRefusedError:
            raise ChannelGone(
                f"no machine is running on instance {instance}: the task "
                f"that served {path} is gone (nothing listens there)"
            ) from None
        except socket.timeout:
            raise ChannelError(
                f"the task of instance {instance} did not accept the "
                f"connection within {self.timeout:g} s (is it stuck?)"
            ) from None
        except OSError as exc:
            raise ChannelError(
                f"cannot reach the task of instance {instance} at {path}: "
                f"{exc.strerror or exc}") from None
        # from here on the socket never blocks: waits are poll()s with a
        # deadline, so threads sharing the client do not disturb each other
        self._sock.setblocking(False)
        hello = cmdproto.client_hello(os.getpid(), self.name,
                                      PROTOCOL_VERSION)
        try:
            done = self._sendall(cmdproto.encode(hello), self.timeout)
        except OSError as exc:
            raise ChannelError(
                f"the task of instance {instance} closed the connection "
                f"during the handshake ({exc.strerror or exc})") from None
        if not done:
            raise ChannelError(
                f"the task of instance {instance} did not take the "
                f"handshake within {self.timeout:g} s (is it stuck?)")
        answer = self._read_hello(instance)
        if answer.get("ok") is not True:
            error = answer.get("error") or "no reason given"
            raise ChannelError(
                f"the task of instance {instance} refused this client: "
                f"{error} (use the halsdk that runs the machine)")
        pid = answer.get("task_pid")
        self.task_pid = pid if isinstance(pid, int) else 0

    def _read_hello(self, instance: str) -> dict[str, Any]:
        deadline = time.monotonic() + self.timeout
        while True:
            try:
                for message in self._reader.frames():
                    if message.get("hello") != cmdproto.HELLO:
                        raise ChannelError(
                            f"the task of instance {instance} answered the "
                            "handshake with something else than a hello")
                    return message
            except FrameError as exc:
                raise ChannelError(
                    f"the task of instance {instance} answered the "
                    f"handshake with a bad frame: {exc}") from None
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise ChannelError(
                    f"the task of instance {instance} did not answer the "
                    f"handshake within {self.timeout:g} s (is it stuck?)")
            if not self._poll(select.POLLIN, remaining):
                continue
            try:
                data = self._sock.recv(_RECV_SIZE)
            except (BlockingIOError, InterruptedError):
                continue
            except OSError as exc:
                data = b""
                if exc.errno not in _GONE_ERRNOS:
                    raise ChannelError(
                        f"cannot read the answer of the task of instance "
                        f"{instance}: {exc.strerror or exc}") from None
            if not data:
                raise ChannelError(
                    f"the task of instance {instance} closed the connection "
                    "during the handshake")
            self._reader.feed(data)

    # -------------------------------------------------------------- API

    def send(self, name: str, **args: Any) -> int:
        """Send command ``name`` with ``args``; return its serial.

        The task checks the command and answers; this only writes it.

        :raises CommandError: the command cannot be framed (too large, a
            value JSON cannot carry).
        :raises ChannelGone: the task is gone.
        :raises ChannelError: the task did not take the frame in time.
        """
        self._check()
        with self._send_lock:
            self._check()
            serial = self.serial + 1
            message = {"serial": serial, "cmd": name, "args": args}
            try:
                frame = cmdproto.encode(message)
            except (TypeError, ValueError, FrameError) as exc:
                raise CommandError(f"command '{name}' cannot be sent: "
                                   f"{exc}") from None
            # read what is there first: a client that only sends must not
            # let its replies pile up (and a task gone shows here)
            self._read_turn(0.0)
            self._check()
            try:
                done = self._sendall(frame, self.timeout)
            except OSError as exc:
                self._lost(exc)
                self._check()
                raise           # not reached: _check() raised
            if not done:
                self._fail(ChannelError(
                    f"the task (pid {self.task_pid}) did not take command "
                    f"'{name}' within {self.timeout:g} s; the connection is "
                    "closed (is the task stuck?)"))
            self.serial = serial
            if serial - self._forgotten > 2 * KEEP:
                self._forget()
            return serial

    def wait(self, serial: int,
             timeout: Optional[float]) -> tuple[int, Optional[str]]:
        """Wait until command ``serial`` is done or refused.

        :param timeout: seconds; ``None`` waits without a limit (the
            task's death still ends the wait).
        :returns: ``(RCS_DONE, None)``, ``(RCS_ERROR, reason)`` or
            ``(-1, None)`` when the time ran out.
        :raises ChannelGone: the task is gone.
        """
        return self._wait(serial, timeout, _FINAL)

    def wait_received(self, serial: int,
                      timeout: Optional[float]) -> tuple[int, Optional[str]]:
        """Wait until the task took command ``serial`` (``RCS_EXEC``),
        finished it or refused it: ``(state, error text)``, ``(-1, None)``
        when the time ran out."""
        return self._wait(serial, timeout, _TAKEN)

    def state_of(self, serial: int) -> int:
        """The last known state of command ``serial`` after reading the
        replies that arrived: 0 (none yet), ``RCS_EXEC``, ``RCS_DONE`` or
        ``RCS_ERROR``."""
        self._known(serial)
        self._read_turn(0.0)
        self._check()
        return self._states.get(serial, 0)

    def close(self) -> None:
        """Close the connection (commands sent go on in the task)."""
        if not self._closed:
            self._closed = True
            self._sock.close()

    def __enter__(self) -> CommandClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return (f"<CommandClient {self.path} task pid {self.task_pid} "
                f"serial {self.serial}>")

    # --------------------------------------------------------- internals

    def _check(self) -> None:
        if self._failure is not None:
            raise type(self._failure)(str(self._failure))
        if self._closed:
            raise ChannelError("this command client is closed; open a new "
                               "one")

    def _known(self, serial: int) -> None:
        if not isinstance(serial, int) or not 0 < serial <= self.serial:
            raise InvalidError(f"serial {serial!r} was not sent by this "
                               f"client (last sent: {self.serial})")
        if serial <= self._forgotten:
            raise InvalidError(f"serial {serial} is too old: this client "
                               f"keeps the replies of the last {KEEP} "
                               "commands")

    def _wait(self, serial: int, timeout: Optional[float],
              states: tuple[int, ...]) -> tuple[int, Optional[str]]:
        self._known(serial)
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            state = self._states.get(serial, 0)
            if state in states:
                return state, self._errors.get(serial)
            self._check()
            if deadline is None:
                self._read_turn(None)
                continue
            remaining = max(0.0, deadline - time.monotonic())
            self._read_turn(remaining)
            if remaining == 0.0:
                state = self._states.get(serial, 0)
                if state in states:
                    return state, self._errors.get(serial)
                self._check()
                return -1, None

    def _read_turn(self, timeout: Optional[float]) -> Optional[bool]:
        """Read the replies, waiting up to ``timeout`` s for the first
        (0: only those there; ``None``: no limit), unless another thread
        is reading: then wait up to ``timeout`` for it to take some in.
        Whether this thread read anything; None if another thread read."""
        with self._cond:
            self._check()
            if self._reading:
                if timeout != 0.0:
                    self._cond.wait(timeout)
                return None
            self._reading = True
        try:
            got = self._receive(timeout)
            while got and self._receive(0.0):
                pass
            return got
        finally:
            with self._cond:
                self._reading = False
                self._cond.notify_all()

    def _receive(self, timeout: Optional[float]) -> bool:
        """Read once (waiting up to ``timeout``) and take in the replies;
        whether anything came. Only the reader calls it."""
        if self._failure is not None or self._closed:
            return False
        if timeout != 0.0 and not self._poll(select.POLLIN, timeout):
            return False
        try:
            data = self._sock.recv(_RECV_SIZE)
        except (BlockingIOError, InterruptedError):
            return False
        except OSError as exc:
            self._lost(exc)
            return False
        if not data:
            self._gone()
            return False
        self._reader.feed(data)
        try:
            for message in self._reader.frames():
                self._take(message)
        except (FrameError, ChannelError) as exc:
            self._mark(ChannelError(
                f"the task (pid {self.task_pid}) sent a bad frame: {exc}; "
                "the connection is closed"))
        return True

    def _take(self, message: dict[str, Any]) -> None:
        serial = message.get("serial")
        if serial is None:
            return              # not a reply: room for later notices
        state = message.get("state")
        if not cmdproto.is_serial(serial) or state not in _TAKEN:
            raise ChannelError(
                f"the task (pid {self.task_pid}) sent a reply this client "
                f"does not understand: {str(message)[:200]}")
        if serial <= self._forgotten:
            return
        self._states[serial] = state
        if state == RCS_ERROR:
            error = message.get("error")
            self._errors[serial] = (error if isinstance(error, str)
                                    else "the task gave no reason")

    def _poll(self, events: int, timeout: Optional[float]) -> bool:
        """Wait up to ``timeout`` s (``None``: no limit) until the socket
        is ready for ``events`` (or has failed); whether it is."""
        poller = select.poll()
        poller.register(self._sock, events)
        ms = None if timeout is None else max(0, int(timeout * 1000 + 0.999))
        return bool(poller.poll(ms))

    def _sendall(self, data: bytes, timeout: float) -> bool:
        """Send all of ``data`` within ``timeout`` s; False if the time
        ran out. Raises the OSError of a failed send."""
        deadline = time.monotonic() + timeout
        view = memoryview(data)
        try:
            while view:
                try:
                    sent = self._sock.send(view, socket.MSG_NOSIGNAL)
                except (BlockingIOError, InterruptedError):
                    remaining = deadline - time.monotonic()
                    if remaining <= 0 or not self._poll(select.POLLOUT,
                                                        remaining):
                        return False
                    continue
                view = view[sent:]
        except BaseException:
            if 0 < len(view) < len(data):   # e.g. KeyboardInterrupt
                self._mark(ChannelError(
                    "a send to the task was interrupted half-way; the "
                    "connection is closed (open a new client)"))
            raise
        return True

    def _forget(self) -> None:
        self._forgotten = self.serial - KEEP
        keep = self._forgotten
        self._states = {s: v for s, v in self._states.items() if s > keep}
        self._errors = {s: v for s, v in self._errors.items() if s > keep}

    def _lost(self, exc: OSError) -> None:
        if exc.errno in _GONE_ERRNOS or isinstance(exc, ConnectionError):
            self._gone()
        else:
            self._mark(ChannelError(
                f"the command channel to the task (pid {self.task_pid}) "
                f"failed: {exc.strerror or exc}; the connection is closed"))

    def _gone(self) -> None:
        self._mark(ChannelGone(
            f"the machine is gone: the task (pid {self.task_pid}) closed "
            "the command channel"))

    def _mark(self, error: ChannelError) -> None:
        """Remember ``error`` for every later call and close; the replies
        read before it still count."""
        if self._failure is None:
            self._failure = error
        if not self._closed:
            self._closed = True
            self._sock.close()

    def _fail(self, error: ChannelError) -> NoReturn:
        """:meth:`_mark` ``error`` and raise it."""
        self._mark(error)
        self._check()
        raise error             # not reached: _check() raised
