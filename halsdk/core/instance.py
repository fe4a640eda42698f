"""The process's connection to a HAL instance: create (host) or attach.

One process uses one instance at a time.  The first :class:`halsdk.Hal`
(or :func:`halsdk.component`) of a process connects; later ones share the
connection, which closes when the last user closes it or the process exits.
"""

from __future__ import annotations

import atexit
import os
import re
import signal
import threading
import time
from types import FrameType
from typing import TYPE_CHECKING, Any, Callable, NoReturn, Optional

from halsdk.core import _core
from halsdk.core.errors import ExistsError, HalError, InstanceError, InvalidError

if TYPE_CHECKING:
    from halsdk.core.channel import Server

_INSTANCE_NAME = re.compile(r"^[A-Za-z0-9_.-]{1,40}$")
SHM_DIR = "/dev/shm"


def shm_name(instance: Optional[str] = None) -> str:
    """POSIX shared-memory name of an instance of this user.

    ``None`` means ``$HALSDK_INSTANCE`` or, if unset, the user's default
    instance.
    """
    name = instance if instance is not None else os.environ.get(
        "HALSDK_INSTANCE", "")
    base = f"/halsdk-{os.getuid()}"
    if not name:
        return base
    if not _INSTANCE_NAME.match(name):
        raise InvalidError(
            f"instance name {name!r} is not 1..40 characters of "
            "letters, digits, '_', '.' or '-'")
    return f"{base}-{name}"


def instance_label(shm: str) -> str:
    """The instance name a shared-memory name stands for."""
    base = f"/halsdk-{os.getuid()}"
    return shm[len(base) + 1:] if shm != base else "default"


class Connection:
    """This process's mapping of an instance and what it owns there."""

    def __init__(self, shm: str, host: bool):
        self.shm = shm
        self.host = host
        self.users = 0
        self.closers: list[Callable[[], None]] = []
        self.server: Optional[Server] = None    # request channel, on the host
        self.handlers: dict[str, Callable[..., Any]] = {}  # requests it serves
        # the host's realtime modules: a halsdk.loader.Registry that the
        # first Hal of the host process makes (the core does not know the
        # loader, the layer above it)
        self.registry: Any = None
        self.lock = threading.RLock()

    @property
    def label(self) -> str:
        return instance_label(self.shm)


_conn: Optional[Connection] = None
_conn_lock = threading.RLock()


def current() -> Optional[Connection]:
    return _conn


def connect(instance: Optional[str] = None, create: Optional[bool] = None,
            size: Optional[int] = None) -> Connection:
    """Create or attach; ``create``: True must create, False must attach,
    None creates when there is no instance."""
    global _conn
    with _conn_lock:
        # no name given: the instance this process already uses
        shm = _conn.shm if instance is None and _conn is not None \
            else shm_name(instance)
        if _conn is not None:
            if _conn.shm != shm:
                raise InstanceError(
                    f"this process already uses HAL instance "
                    f"'{_conn.label}'; one instance per process")
            if create and not _conn.host:
                raise InstanceError(
                    f"HAL instance '{_conn.label}' exists; this process "
                    "is attached to it, not its host")
            _conn.users += 1
            return _conn
        conn = _attach_or_create(shm, create, size)
        conn.users = 1
        _conn = conn
        if conn.host:
            from halsdk.core import channel
            try:
                conn.server = channel.Server(conn)
            except Exception:
                _teardown(conn)
                raise
        return conn


def _probe_settled(shm: str) -> tuple[Any, ...]:
    """Probe, waiting up to a second for an instance being created."""
    deadline = time.monotonic() + 1.0
    while True:
        found: tuple[Any, ...] = _core.probe(shm)
        if found[0] != "creating" or time.monotonic() > deadline:
            return found
        time.sleep(0.01)


def _attach_or_create(shm: str, create: Optional[bool],
                      size: Optional[int]) -> Connection:
    label = instance_label(shm)
    for _attempt in range(3):
        state, pid, start, abi = _probe_settled(shm)
        if state == "junk":
            raise InstanceError(f"{SHM_DIR}{shm} is not a halsdk instance; "
                                "remove it by hand")
        if state == "abi":
            raise InstanceError(
                f"HAL instance '{label}' ({SHM_DIR}{shm}) has ABI version "
                f"{abi}; this halsdk speaks version {_core.ABI_VERSION}")
        if state == "creating":
            raise InstanceError(
                f"HAL instance '{label}' is still being created, or was left "
                "half-made; try again, or remove it with halsdk.cleanup()")
        if state == "ok":
            if not _core.pid_alive(pid, start):
                if create is False:
                    raise InstanceError(
                        f"no HAL instance '{label}' is running: its host "
                        f"(pid {pid}) is gone")
                if _take_over(shm, label, pid):
                    continue
                raise InstanceError(
                    f"HAL instance '{label}' was left by a host (pid {pid}) "
                    "that is gone, and it could not be removed; remove it "
                    "with 'halrun -U'")
            if create:
                raise InstanceError(f"HAL instance '{label}' already has a "
                                    f"host (pid {pid})")
            _core.attach(shm)
            return Connection(shm, host=False)
        if create is False:
            raise InstanceError(f"no HAL instance '{label}' is running "
                                "(start one with halrun or halsdk.Hal())")
        try:
            _core.create(shm, label, size or 0)
        except ExistsError:
            continue            # another process created it meanwhile
        _install_sigterm()
        return Connection(shm, host=True)
    raise InstanceError(f"HAL instance '{label}' appeared while it was "
                        "being created here; try again")


def _take_over(shm: str, label: str, pid: int) -> bool:
    """Remove the segment of an instance whose host is verifiably gone
    (its pid is not running, or runs another program since the host's
    start time), with a one-line note on stderr.  True when the caller
    may look again: the dead instance was removed here, or the name
    holds another instance now (another process took it over first);
    False when it cannot be removed (not a file this user may open).

    Two processes may take over at once: each locks the segment file it
    opened and removes the name only while the name still refers to that
    locked file and the file still holds a dead host, so nobody removes
    the instance that the other one created meanwhile."""
    import fcntl
    import sys

    from halsdk.core import channel

    path = SHM_DIR + shm
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
    except FileNotFoundError:
        return True             # gone already: create it
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        try:
            same = os.fstat(fd).st_ino == os.stat(
                path, follow_symlinks=False).st_ino
        except FileNotFoundError:
            return True         # removed by another process meanwhile
        if same:
            state, now_pid, start, _abi = _core.probe(shm)
            if state != "ok" or _core.pid_alive(now_pid, start):
                return True     # another process took it over: attach
            os.unlink(path)
            channel.remove_socket(shm)
            print(f"halsdk: HAL instance '{label}': its host (pid {pid}) "
                  "is gone; taking the instance over", file=sys.stderr)
        return True
    except OSError:
        return False
    finally:
        os.close(fd)


def release(conn: Connection) -> None:
    """One user is done; the last one closes the connection."""
    with _conn_lock:
        if conn is not _conn:
            return
        conn.users -= 1
        if conn.users <= 0:
            _teardown(conn)


def _teardown(conn: Connection) -> None:
    global _conn
    with _conn_lock:
        if _conn is not conn:
            return
        if conn.host:
            if conn.server is not None:
                conn.server.close()
            try:
                _core.stop()
            except Exception:
                pass
        # closers run newest first: loaded modules, then components
        while conn.closers:
            closer = conn.closers.pop()
            try:
                closer()
            except Exception as exc:  # keep tearing down
                import sys
                print(f"halsdk: while closing: {exc}", file=sys.stderr)
        try:
            comps = _core.items("component")
        except HalError:            # a damaged instance: just leave it
            comps = []
        for comp in comps:
            try:
                if comp.exists and comp.pid == os.getpid():
                    _core.comp_exit(comp.id)
            except Exception:
                pass
        _core.detach(conn.host, conn.shm if conn.host else None)
        _conn = None


@atexit.register
def _close_at_exit() -> None:
    if _conn is not None:
        _teardown(_conn)


def _install_sigterm() -> None:
    """Let SIGTERM end a host normally so that it removes its instance."""
    if threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        def on_term(signum: int, frame: Optional[FrameType]) -> NoReturn:
            raise SystemExit(128 + signum)
        signal.signal(signal.SIGTERM, on_term)


def _older_than(name: str, seconds: float) -> bool:
    try:
        st = os.stat(os.path.join(SHM_DIR, name))
    except FileNotFoundError:
        return False
    return time.time() - st.st_mtime > seconds


def cleanup(instance: Optional[str] = None) -> list[str]:
    """Remove instances of this user whose host process is gone.

    With ``instance`` only that one is considered.  Returns the names of
    the shared-memory segments removed.  Instances with a live host are
    left alone.
    """
    from halsdk.core import channel

    prefix = f"halsdk-{os.getuid()}"
    if instance is not None:
        names = [shm_name(instance)[1:]]
    else:
        try:
            names = [n for n in os.listdir(SHM_DIR)
                     if n == prefix or n.startswith(prefix + "-")]
        except FileNotFoundError:
            names = []
    removed = []
    for n in sorted(names):
        shm = "/" + n
        if _conn is not None and _conn.shm == shm:
            continue
        state, pid, start, _abi = _core.probe(shm)
        if state in ("absent", "abi"):
            continue            # another version's instance is not ours
        if state == "ok" and _core.pid_alive(pid, start):
            continue
        if state in ("creating", "junk") and not _older_than(n, 10.0):
            continue            # perhaps being created right now
        try:
            os.unlink(os.path.join(SHM_DIR, n))
            removed.append(n)
        except FileNotFoundError:
            pass
        channel.remove_socket(shm)
    return removed
