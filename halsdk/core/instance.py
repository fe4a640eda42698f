"""The process's connection to a HAL instance: create (host) or attach.

One process uses one instance at a time.  The first :class:`halsdk.Hal`
(or :func:`halsdk.component`) of a process connects; later ones share the
connection, which closes when the last user closes it or the process exits.
"""

from __future__ import annotations

import atexit
import os
import re
import threading
import time
from types import FrameType
from typing import TYPE_CHECKING, Any, Callable, NoReturn, Optional

from halsdk.core import _core
from halsdk.core.errors import (
    ExistsError,
    HalError,
    InstanceError,
    InvalidError,
)

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
        self.reaper: Optional[Reaper] = None    # on the host

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
    _lock_timeout_from_env()
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
                conn.reaper = Reaper()
            except Exception:
                _teardown(conn)
                raise
        return conn


def _lock_timeout_from_env() -> None:
    """``$HALSDK_LOCK_TIMEOUT``: seconds a wait for the instance lock
    lasts (the core reads it too; here a bad value is an error, not
    silently the default)."""
    text = os.environ.get("HALSDK_LOCK_TIMEOUT", "").strip()
    if not text:
        return
    try:
        seconds = float(text)
    except ValueError:
        seconds = float("nan")
    if not 0 < seconds <= 86400:
        raise InvalidError(f"HALSDK_LOCK_TIMEOUT={text!r} is not a number "
                           "of seconds in (0, 86400]")
    _core.set_lock_timeout(seconds)
def watch_host(conn: Connection, end_process: bool,
               who: Optional[str] = None) -> None:
    """In an attached process: watch the host (a thread of the core
    waits on a pidfd of the host's pid).  With ``end_process`` the process
    gets SIGTERM, after a line on stderr naming the instance and the host,
    the moment the host ends, however it ends.  Nothing on the host."""
    if conn.host:
        return
    if who is None:
        import sys
        who = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] \
            else "python"
        if who in ("-c", "-m", "__main__.py", ""):
            who = "python"
    _core.watch_host(end_process, who)


def host_gone() -> int:
    """The pid of this process's host once the watch saw it end, else 0
    (always 0 without :func:`watch_host`)."""
    return _core.host_gone() if _conn is not None else 0


class Reaper:
    """The host's watch over the processes of userspace components.

    A daemon thread waits on a pidfd of each process that owns a userspace
    component (the kernel wakes it when one ends) and, every 0.1 s, looks
    at the instance's change counter for components added or removed.  A
    component whose process ended without removing it is marked dead
    (``show comp`` says ``dead``) and its out pins are set to zero by the
    core; the ``halcmd<pid>`` component of a dead halcmd is removed.
    Nothing of this runs in the realtime threads.
    """

    PERIOD = 0.1

    def __init__(self) -> None:
        self._stop = threading.Event()
        self._wake_r, self._wake_w = os.pipe2(os.O_CLOEXEC)
        self._fds: dict[int, int] = {}          # component id -> pidfd
        self._polled: set[int] = set()          # ids without a pidfd
        self._thread = threading.Thread(target=self._run,
                                        name="halsdk-reaper", daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop the thread (before the instance is unmapped)."""
        self._stop.set()
        try:
            os.write(self._wake_w, b"x")
        except OSError:
            pass
        if threading.current_thread() is not self._thread:
            self._thread.join(timeout=10)
        for fd in (*self._fds.values(), self._wake_r, self._wake_w):
            try:
                os.close(fd)
            except OSError:
                pass
        self._fds.clear()

    def _run(self) -> None:
        import select
        serial = None
        while not self._stop.is_set():
            try:
                now = _core.serial()
                if now != serial:
                    serial = now
                    self._rescan()
                poller = select.poll()
                poller.register(self._wake_r, select.POLLIN)
                by_fd = {}
                for cid, fd in self._fds.items():
                    poller.register(fd, select.POLLIN)
                    by_fd[fd] = cid
                ended = [by_fd[fd] for fd, _ev in
                         poller.poll(self.PERIOD * 1000) if fd in by_fd]
                for cid in list(self._polled):
                    comp = _core.comp_by_id(cid)
                    if comp is None or not comp.alive:
                        ended.append(cid)
                for cid in ended:
                    if not self._stop.is_set():
                        self._ended(cid)
            except Exception as exc:    # never let the watch die silently
                if self._stop.is_set():
                    return
                import sys
                print(f"halsdk: watching userspace components: {exc}",
                      file=sys.stderr)
                self._stop.wait(self.PERIOD)

    def _rescan(self) -> None:
        me = os.getpid()
        present = set()
        for comp in _core.items("component"):
            if comp.realtime or comp.pid == me or comp.dead:
                continue
            cid = comp.id
            present.add(cid)
            if cid in self._fds or cid in self._polled:
                continue
            try:
                fd = os.pidfd_open(comp.pid)
            except ProcessLookupError:
                self._ended(cid)
                continue
            except OSError:             # no pidfds: look every PERIOD
                self._polled.add(cid)
                continue
            self._fds[cid] = fd
            if not comp.alive:          # the pid was reused meanwhile
                self._ended(cid)
        for cid in set(self._fds) - present:
            os.close(self._fds.pop(cid))
        self._polled &= present

    def _ended(self, cid: int) -> None:
        fd = self._fds.pop(cid, None)
        if fd is not None:
            os.close(fd)
        self._polled.discard(cid)
        comp = _core.comp_by_id(cid)
        if comp is None or comp.alive:
            return
        try:
            if comp.name == f"halcmd{comp.pid}":
                _core.comp_exit(cid)    # a halcmd session's bookkeeping
            else:
                _core.comp_mark_dead(cid)
        except HalError:
            pass                        # removed meanwhile (unload)


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
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK
                     | os.O_CLOEXEC)
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
            channel.remove_socket(shm)      # first, as in cleanup()
            os.unlink(path)
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
            if conn.reaper is not None:
                conn.reaper.close()
                conn.reaper = None
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
        # the safety net for components left open; a process stopped
        # while holding the lock (LockTimeoutError) must not turn the
        # exit into a traceback
        try:
            comps = _core.items("component")
        except HalError:
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
        # the process is ending: another Ctrl-C or SIGTERM (halrun's
        # unloadusr, an impatient user; both raise KeyboardInterrupt
        # here) must not cut the teardown short, which would print a
        # traceback and leave the component half removed. Once ignored,
        # a signal that came just before is not raised either.
        import signal
        import threading
        if threading.current_thread() is threading.main_thread():
            for _ in range(3):
                try:
                    signal.signal(signal.SIGINT, signal.SIG_IGN)
                    signal.signal(signal.SIGTERM, signal.SIG_IGN)
                    break
                except KeyboardInterrupt:
                    continue
        _teardown(_conn)


def _install_sigterm() -> None:
    """Let SIGTERM end a host normally so that it removes its instance."""
    # imported here: an attached halcmd starts faster without it
    import signal
    if threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        def on_term(signum: int, frame: Optional[FrameType]) -> NoReturn:
            raise SystemExit(128 + signum)
        signal.signal(signal.SIGTERM, on_term)


def _older_than(name: str, seconds: float) -> bool:
    try:
        st = os.lstat(os.path.join(SHM_DIR, name))
    except FileNotFoundError:
        return False
    return time.time() - st.st_mtime > seconds


def cleanup(instance: Optional[str] = None,
            report: Optional[Callable[[str], None]] = None) -> list[str]:
    """Remove instances of this user whose host process is gone.

    With ``instance`` only that one is considered.  Returns the names of
    the shared-memory segments removed.  Instances with a live host are
    left alone.  A segment or socket that fails the trust checks (another
    user's file, a link, the wrong mode: see :class:`TrustError`), a
    runtime folder that is not this user's, and a file that cannot be
    removed are left in place and passed to ``report`` (when given), one
    message each, naming the file and its owner.
    """
    from halsdk.core import channel

    def say(message: str) -> None:
        if report is not None:
            report(message)

    try:
        channel.socket_dir()
        sockets: Optional[Callable[[str], None]] = say
    except InstanceError as exc:
        say(str(exc))           # the folder is not ours: leave it be
        sockets = None

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
        try:
            state, pid, start, _abi = _core.probe(shm)
        except InstanceError as exc:
            say(str(exc))       # not ours to judge, or to remove
            continue
        if state in ("absent", "abi"):
            continue            # another version's instance is not ours
        if state == "ok" and _core.pid_alive(pid, start):
            continue
        if state in ("creating", "junk") and not _older_than(n, 10.0):
            continue            # perhaps being created right now
        # the sockets first, the segment last: whoever finds the segment
        # gone (another halrun -U at the same time) finds its sockets
        # gone too
        if sockets is not None:
            channel.remove_socket(shm, sockets)
        try:
            os.unlink(os.path.join(SHM_DIR, n))
            removed.append(n)
        except FileNotFoundError:
            pass
        except OSError as exc:
            say(f"cannot remove {SHM_DIR}/{n}: {exc.strerror or exc}")
    return removed
