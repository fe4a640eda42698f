"""The task's end of the command channel.

:class:`CommandServer` lives in the task thread and never blocks it: the
sockets are non-blocking, the replies wait in a queue per client, and
:meth:`CommandServer.service` returns as soon as it has handled what
arrived, so that the task runs its cycle on time. Only the task thread
may call its methods.

Faults of a client (garbage, a frame cut short by its death, a client
that stops reading its replies, another protocol version) close that
client's connection and are said once through ``report``; the task and
the other clients go on. A command is submitted only once its frame is
whole: a client killed in the middle of a frame has sent nothing.

Order: the first reply of each command (``RCS_EXEC``, or ``RCS_ERROR`` when
the channel refuses it: unknown name, bad arguments) goes out in the order
the commands came, and the commands are submitted in that order; their
final replies come from the task (in its order: first come, first done). A
refusal does not wait for the commands before it to finish.
"""

from __future__ import annotations

import errno
import os
import selectors
import socket
import stat
import struct
import time
from typing import Callable, Optional

from halsdk.channels import cmdproto, sockfile
from halsdk.channels.cmdproto import (
    RCS_ERROR,
    RCS_EXEC,
    CommandError,
    FrameError,
    FrameReader,
)
from halsdk.channels.errors import ChannelError

__all__ = ["CommandServer", "MAX_QUEUED", "Peer"]

#: bytes of replies queued for one client before it counts as one that
#: stopped reading (then it is dropped)
MAX_QUEUED = 1 << 20
#: seconds a client has to send its hello after it connected
HANDSHAKE_TIMEOUT = 10.0
#: bytes read from one client per readiness
_RECV_SIZE = 1 << 16           # below the allocator's mmap threshold
#: connections accepted per service() call at most
_ACCEPTS = 32
#: longest error text sent back
_MAX_ERROR = 4000
_CREDS = struct.Struct("3i")

Submit = Callable[["Peer", int, str, dict], None]


class Peer:
    """One client connection: its process id and user id (from the kernel,
    not the client's word), the name it gave, whether it finished the
    handshake and whether it is closed (replies to it are then ignored)."""

    def __init__(self, sock: socket.socket, pid: int, uid: int) -> None:
        self.pid = pid
        self.uid = uid
        self.name = ""
        self.greeted = False
        self.closed = False
        self._sock = sock
        self._reader = FrameReader()
        self._out = bytearray()
        self._writing = False       # registered for EVENT_WRITE
        self._since = time.monotonic()

    @property
    def queued(self) -> int:
        """Bytes of replies waiting for the client to read them."""
        return len(self._out)

    def __repr__(self) -> str:
        state = "closed" if self.closed else "open"
        return f"<Peer pid={self.pid} name={self.name!r} {state}>"

    def words(self) -> str:
        """The client in words for a report: ``pid 12 ('ctl')``."""
        return f"pid {self.pid}" + (f" ({self.name!r})" if self.name else "")


class CommandServer:
    """Serves the command channel at ``path``.

    :param path: the socket's path (``Hal.private_socket_path("task")``).
        A stale socket file there is replaced; a live one (another task
        listening) is refused.
    :param submit: called as ``submit(peer, serial, name, args)`` for each
        valid command, in the order they arrived, after the ``RCS_EXEC``
        reply is queued. ``name`` is the canonical name
        (:func:`cmdproto.canonical`), ``args`` the checked arguments with
        the defaults filled in. The task answers later with :meth:`reply`.
    :param report: called with one line of text for each client fault.
    :param task_pid: the pid the handshake announces.
    :raises ChannelError: the socket cannot be created (path too long,
        another task serves it, permissions).
    """

    def __init__(self, path: str, submit: Submit,
                 report: Callable[[str], None], *, task_pid: int) -> None:
        self.path = path
        self.task_pid = task_pid
        self.peers: list[Peer] = []
        self.max_queued = MAX_QUEUED
        self.handshake_timeout = HANDSHAKE_TIMEOUT
        self._submit = submit
        self._report = report
        self._uid = os.getuid()
        self._closed = False
        self._paused = False        # listener unregistered (out of fds)
        self._listener = self._bind(path)
        try:
            self._ino = os.stat(path).st_ino
        except OSError:
            self._ino = -1
        self._sel = selectors.DefaultSelector()
        self._sel.register(self._listener, selectors.EVENT_READ, None)

    # ------------------------------------------------------------ setup

    @staticmethod
    def _bind(path: str) -> socket.socket:
        if len(os.fsencode(path)) > 107:
            raise ChannelError(
                f"cannot create the task's command channel at {path}: the "
                "path is longer than a Unix socket allows (107 bytes); use a "
                "shorter runtime folder (XDG_RUNTIME_DIR)")
        _clear_stale(path)
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        old = os.umask(0o077)
        try:
            sock.bind(path)
            os.chmod(path, 0o600)
            sock.listen(64)
        except OSError as exc:
            sock.close()
            raise ChannelError(
                f"cannot create the task's command channel at {path}: "
                f"{exc.strerror or exc}") from None
        finally:
            os.umask(old)
        sock.setblocking(False)
        return sock

    # ---------------------------------------------------------- service

    def service(self, timeout: float) -> None:
        """Wait at most ``timeout`` seconds for the clients, handle what
        came (connections, handshakes, commands, replies to send) and
        return; returns at once when something was ready."""
        if self._closed:
            return
        events = self._sel.select(max(0.0, timeout))
        for key, mask in events:
            peer = key.data
            if peer is None:
                self._accept()
                continue
            if peer.closed:
                continue
            if mask & selectors.EVENT_WRITE:
                self._flush(peer)
            if mask & selectors.EVENT_READ and not peer.closed:
                self._read(peer)
        self._expire_handshakes()

    def reply(self, peer: Peer, serial: int, state: int,
              error: Optional[str] = None) -> None:
        """Queue the reply ``state`` (an ``RCS_*``) for command ``serial``
        of ``peer`` and send what the socket takes now. Never blocks; a
        peer that is gone is ignored."""
        if peer.closed or self._closed:
            return
        message: dict[str, object] = {"serial": serial, "state": state}
        if error is not None:
            message["error"] = str(error)[:_MAX_ERROR]
        self._queue(peer, cmdproto.encode(message))

    def close(self) -> None:
        """Close every connection and the socket, and remove its file."""
        if self._closed:
            return
        self._closed = True
        for peer in list(self.peers):
            self._drop(peer, None)
        self._sel.close()
        self._listener.close()
        try:
            if os.stat(self.path).st_ino == self._ino:
                os.unlink(self.path)
        except OSError:
            pass

    def __enter__(self) -> CommandServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------ connections

    def _accept(self) -> None:
        for _ in range(_ACCEPTS):
            try:
                sock, _addr = self._listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                if exc.errno in (errno.EMFILE, errno.ENFILE, errno.ENOBUFS,
                                 errno.ENOMEM):
                    # the listener stays readable: stop listening until a
                    # client leaves, or service() would spin
                    self._sel.unregister(self._listener)
                    self._paused = True
                    self._say(f"cannot accept a new client: {exc.strerror}; "
                              "new clients wait until one leaves")
                return
            try:
                creds = sock.getsockopt(socket.SOL_SOCKET,
                                        socket.SO_PEERCRED, _CREDS.size)
                pid, uid, _gid = _CREDS.unpack(creds)
            except OSError:
                sock.close()
                continue
            if uid != self._uid:
                sock.close()
                self._say(f"refused a client (pid {pid}): it runs as uid "
                          f"{uid}, the task as uid {self._uid}; only the "
                          "machine's own user may command it")
                continue
            sock.setblocking(False)
            peer = Peer(sock, pid, uid)
            self.peers.append(peer)
            self._sel.register(sock, selectors.EVENT_READ, peer)

    def _expire_handshakes(self) -> None:
        late = time.monotonic() - self.handshake_timeout
        for peer in self.peers:
            if not peer.greeted and not peer.closed and peer._since < late:
                self._drop(peer, f"sent no hello within "
                                 f"{self.handshake_timeout:g} s")
                return          # the list changed; the rest next time

    def _drop(self, peer: Peer, reason: Optional[str]) -> None:
        """Close ``peer``; say ``reason`` first when it is a fault."""
        if peer.closed:
            return
        if reason is not None:
            self._say(f"closed the connection of {peer.words()}: {reason}")
        peer.closed = True
        peer._out.clear()
        try:
            self._sel.unregister(peer._sock)
        except (KeyError, ValueError):
            pass
        peer._sock.close()
        self.peers.remove(peer)
        if self._paused and not self._closed:
            self._paused = False
            self._sel.register(self._listener, selectors.EVENT_READ, None)

    def _say(self, text: str) -> None:
        try:
            self._report(f"command channel: {text}")
        except Exception:       # a broken report must not stop the task
            pass

    # ---------------------------------------------------------- reading

    def _read(self, peer: Peer) -> None:
        try:
            data = peer._sock.recv(_RECV_SIZE)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:         # ECONNRESET and the like: it is gone
            data = b""
        if not data:
            self._eof(peer)
            return
        peer._reader.feed(data)
        try:
            for message in peer._reader.frames():
                self._message(peer, message)
                if peer.closed:
                    return
        except FrameError as exc:
            self._drop(peer, f"it sent a bad frame: {exc}")

    def _eof(self, peer: Peer) -> None:
        reader = peer._reader
        if reader.pending:
            expected = reader.expected
            of = f" of {expected}" if expected is not None else ""
            self._drop(peer, f"it left in the middle of a frame "
                             f"({reader.pending}{of} bytes); that frame "
                             "was dropped, not applied")
        else:
            self._drop(peer, None)      # an orderly goodbye

    def _message(self, peer: Peer, message: dict) -> None:
        if not peer.greeted:
            self._handshake(peer, message)
            return
        serial = message.get("serial")
        if not cmdproto.is_serial(serial):
            self._drop(peer, "it sent a frame without a valid serial number "
                             "(a command frame is {\"serial\": n, \"cmd\": "
                             "name, \"args\": {...}})")
            return
        assert isinstance(serial, int)
        name = message.get("cmd")
        try:
            args = cmdproto.validate(name, message.get("args"))
        except CommandError as exc:
            self.reply(peer, serial, RCS_ERROR, str(exc))
            return
        assert isinstance(name, str)      # validate() checked it
        name = cmdproto.canonical(name)
        self.reply(peer, serial, RCS_EXEC)
        if peer.closed:
            return
        try:
            self._submit(peer, serial, name, args)
        except Exception as exc:
            text = f"the task could not take command '{name}': {exc}"
            self._say(f"{peer.words()}, serial {serial}: {text}")
            self.reply(peer, serial, RCS_ERROR, text)

    def _handshake(self, peer: Peer, message: dict) -> None:
        try:
            hello = cmdproto.parse_client_hello(message)
        except FrameError as exc:
            self._refuse(peer, str(exc))
            return
        peer.name = hello.name
        if hello.version != cmdproto.PROTOCOL_VERSION:
            self._refuse(peer, f"client speaks version {hello.version}, this "
                               f"task version {cmdproto.PROTOCOL_VERSION}")
            return
        peer.greeted = True
        self._queue(peer, cmdproto.encode(cmdproto.task_hello(self.task_pid)))

    def _refuse(self, peer: Peer, error: str) -> None:
        """Tell the client why, then close (a fresh socket takes the small
        frame at once)."""
        try:
            peer._sock.send(cmdproto.encode(cmdproto.task_refusal(error)),
                           socket.MSG_NOSIGNAL)
        except OSError:
            pass
        self._drop(peer, f"refused it: {error}")

    # ---------------------------------------------------------- writing

    def _queue(self, peer: Peer, frame: bytes) -> None:
        idle = not peer._out
        peer._out += frame
        if len(peer._out) > self.max_queued:
            self._drop(peer, f"it stopped reading its replies "
                             f"({len(peer._out)} bytes queued); the commands "
                             "it sent go on")
            return
        if idle:
            self._flush(peer)

    def _flush(self, peer: Peer) -> None:
        while peer._out:
            try:
                sent = peer._sock.send(peer._out, socket.MSG_NOSIGNAL)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:     # EPIPE, ECONNRESET: it left
                self._drop(peer, None)
                return
            del peer._out[:sent]
        want = bool(peer._out)
        if want != peer._writing:
            peer._writing = want
            events = selectors.EVENT_READ
            if want:
                events |= selectors.EVENT_WRITE
            self._sel.modify(peer._sock, events, peer)


def _clear_stale(path: str) -> None:
    """Remove a socket file nobody listens on; refuse a live one."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    if not stat.S_ISSOCK(st.st_mode):
        raise ChannelError(
            f"cannot create the task's command channel at {path}: a file "
            "that is not a socket is in the way; remove it if it is not "
            "needed")
    refused = sockfile.refusal(path)
    if refused is not None:
        raise ChannelError(
            f"cannot create the task's command channel: {refused}")
    probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    probe.settimeout(1.0)
    try:
        probe.connect(path)
    except OSError as exc:
        if exc.errno not in (errno.ECONNREFUSED, errno.ENOENT):
            raise ChannelError(
                f"cannot create the task's command channel at {path}: "
                f"{exc.strerror or exc}") from None
    else:
        raise ChannelError(
            f"another task already serves this instance's command channel "
            f"({path}); one machine per instance: stop it first")
    finally:
        probe.close()
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass
