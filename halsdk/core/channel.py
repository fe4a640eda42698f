"""The request channel from attached processes to the host.

Changes that concern realtime modules (load, unload, addf, delf, start,
stop, newinst, delinst, threads) are executed by the host, which owns the
realtime threads and the loaded modules.  An attached process sends the
request over a Unix-domain socket in a directory only the user can enter
(mode 0700) and gets the result or the error back.  Nothing listens on a
network port.

Protocol: one JSON object per line each way.  Request
``{"op": name, "args": [...], "kwargs": {...}}``; reply
``{"ok": true, "result": ...}`` or
``{"ok": false, "error": message, "class": exception class name}``.
"""

from __future__ import annotations

import os
import socket
import struct
import threading
from typing import TYPE_CHECKING, Any, Callable, Optional

from halsdk.core import errors, trust

if TYPE_CHECKING:
    from halsdk.core.instance import Connection

_MAX_REQUEST = 1 << 20


def socket_dir() -> str:
    """The private directory of this user's request sockets (mode 0700,
    see :func:`halsdk.core.trust.runtime_dir`); TrustError when another
    user made it, or it is a link or open to others."""
    return trust.runtime_dir()


def socket_path(shm: str) -> str:
    return os.path.join(socket_dir(), shm.lstrip("/") + ".sock")


#: the sockets of an instance besides the request socket:
#: ``<instance>.<purpose>.sock`` (``Hal.private_socket_path``)
SOCKET_PURPOSES = ("task",)


def remove_socket(shm: str,
                  report: Optional[Callable[[str], None]] = None) -> None:
    """Remove the request socket of instance ``shm`` and its other
    sockets (:data:`SOCKET_PURPOSES`), as the host does at exit and
    ``halrun -U`` after a crash.  A file there that is not a socket of
    this user (or a runtime folder that is not ours) is left in place and
    passed to ``report`` in words."""
    try:
        path = socket_path(shm)
    except errors.InstanceError as exc:
        if report is not None:
            report(str(exc))
        return
    base = path[:-len(".sock")]
    for name in (path, *(f"{base}.{p}.sock" for p in SOCKET_PURPOSES)):
        try:
            trust.check_socket(name)
            os.unlink(name)
        except FileNotFoundError:
            pass
        except errors.InstanceError as exc:
            if report is not None:
                report(str(exc))
        except OSError as exc:
            if report is not None:
                report(f"cannot remove {name}: {exc.strerror or exc}")


class Server:
    """Serves requests on the host: a daemon thread accepts connections and
    each connection is served by a thread of its own."""

    def __init__(self, conn: Connection) -> None:
        self.conn = conn
        self.path = socket_path(conn.shm)
        trust.check_socket(self.path)   # a stale one of ours is replaced
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        old = os.umask(0o077)
        try:
            self.sock.bind(self.path)
            self.sock.listen(16)
        except OSError as exc:
            self.sock.close()
            raise errors.InstanceError(
                f"cannot make the request socket {self.path}: "
                f"{exc.strerror or exc} (a shorter runtime folder: set "
                "HALSDK_RUNTIME_DIR or XDG_RUNTIME_DIR)") from None
        finally:
            os.umask(old)
        self.sock.settimeout(0.2)
        self.stopping = False
        self.thread = threading.Thread(target=self._serve,
                                       name="halsdk-requests", daemon=True)
        self.thread.start()

    def close(self) -> None:
        if self.stopping:
            return
        self.stopping = True
        try:                    # wake accept() now rather than at its timeout
            with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as poke:
                poke.settimeout(1)
                poke.connect(self.path)
        except OSError:
            pass
        if threading.current_thread() is not self.thread:
            self.thread.join(timeout=5)
        self.sock.close()
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass

    def _serve(self) -> None:
        while not self.stopping:
            try:
                client, _ = self.sock.accept()
            except (socket.timeout, OSError):
                continue
            if self.stopping:
                client.close()
                break
            # one thread per connection: a slow or idle client does not
            # hold up the others (host operations serialize themselves)
            threading.Thread(target=self._client, args=(client,),
                             name="halsdk-request", daemon=True).start()

    def _client(self, client: socket.socket) -> None:
        with client:
            client.settimeout(30)
            try:
                self._handle(client)
            except (OSError, ValueError):
                pass

    def _handle(self, client: socket.socket) -> None:
        # json is imported on the first request, not by every halrun
        import json
        creds = client.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED,
                                  struct.calcsize("3i"))
        pid, uid, _gid = struct.unpack("3i", creds)
        if uid != os.geteuid():
            # only the host's own user may use its instance: say so to the
            # client (the socket's folder keeps others out; root passes)
            why = (f"the host of this HAL instance runs as "
                   f"{trust.me_words()}; pid {pid} of "
                   f"{trust.owner_words(uid)} may not use it")
            client.sendall(json.dumps(
                {"ok": False, "class": "TrustError",
                 "error": why}).encode() + b"\n")
            return
        reader = client.makefile("rb")
        while True:
            line = reader.readline(_MAX_REQUEST)
            if not line:
                return
            reply = self._dispatch(line)
            client.sendall(json.dumps(reply).encode() + b"\n")

    def _dispatch(self, line: bytes) -> dict[str, Any]:
        import json
        try:
            req = json.loads(line)
            op = req["op"]
            args = req.get("args", [])
            kwargs = req.get("kwargs", {})
            if not isinstance(args, list) or not isinstance(kwargs, dict):
                raise ValueError("args must be a list, kwargs an object")
        except (ValueError, KeyError, TypeError) as exc:
            return {"ok": False, "error": f"bad request: {exc}",
                    "class": "InvalidError"}
        handler = self.conn.handlers.get(op)
        if handler is None:
            return {"ok": False, "class": "InvalidError",
                    "error": f"the host does not serve request '{op}'"}
        try:
            return {"ok": True, "result": handler(*args, **kwargs)}
        except Exception as exc:
            reply = {"ok": False, "error": str(exc),
                     "class": type(exc).__name__}
            if isinstance(exc, errors.HalError):
                reply.update(rule=exc.rule.value, kind=exc.kind,
                             names=list(exc.names))
            return reply


def _label(shm: str) -> str:
    from halsdk.core.instance import instance_label
    return instance_label(shm)


def _gone(shm: str, what: str, exc: BaseException | None = None
          ) -> errors.HostGoneError:
    """The error of a channel failure: the instance named, one line."""
    why = ""
    if exc is not None:
        text = getattr(exc, "strerror", None) or str(exc) or \
            type(exc).__name__
        why = f" ({text})"
    return errors.HostGoneError(f"HAL instance '{_label(shm)}': {what}"
                                f"{why}")


def request(shm: str, op: str, *args: Any, timeout: float = 60.0,
            **kwargs: Any) -> Any:
    """Ask the host of an instance to do ``op``; raise its error.

    A failure of the channel itself (no host listening, the host dying
    or closing the connection before the whole reply, no answer within
    ``timeout`` seconds, a garbled reply) raises
    :class:`~halsdk.errors.HostGoneError` naming the instance, never a
    bare ``OSError``."""
    import json
    try:
        path = socket_path(shm)
    except OSError as exc:
        raise _gone(shm, "cannot use the request channel folder",
                    exc) from None
    trust.check_socket(path)
    try:
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    except OSError as exc:
        raise _gone(shm, "cannot open a request channel", exc) from None
    sock.settimeout(timeout)
    try:
        try:
            sock.connect(path)
        except OSError as exc:
            raise _gone(shm, f"cannot reach its host ({path})",
                        exc) from None
        msg = {"op": op, "args": list(args), "kwargs": kwargs}
        data = b""
        try:
            sock.sendall(json.dumps(msg).encode() + b"\n")
            while not data.endswith(b"\n"):
                chunk = sock.recv(65536)
                if not chunk:
                    raise _gone(shm, "the host closed the channel during "
                                f"request '{op}' (did it exit?)")
                data += chunk
        except socket.timeout:
            raise _gone(shm, f"the host did not answer request '{op}' "
                        f"within {timeout:g} s") from None
        except errors.HostGoneError:
            raise
        except OSError as exc:
            raise _gone(shm, f"the host went away during request '{op}'",
                        exc) from None
    finally:
        sock.close()
    try:
        reply = json.loads(data)
        if not isinstance(reply, dict):
            raise ValueError("not an object")
    except ValueError as exc:
        raise _gone(shm, f"garbled reply to request '{op}'", exc) from None
    if reply.get("ok"):
        return reply.get("result")
    cls = getattr(errors, reply.get("class", ""), None)
    if not (isinstance(cls, type) and issubclass(cls, errors.HalError)):
        cls = errors.HalError
    try:
        rule = errors.Rule(reply.get("rule", "NONE"))
    except ValueError:
        rule = errors.Rule.NONE
    raise cls(reply.get("error", "request failed"), rule=rule,
              kind=reply.get("kind"), names=tuple(reply.get("names", ())))
