"""The Python API of a HAL instance: :class:`Hal`."""

from __future__ import annotations

import os
import time
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any, Callable, Optional, Union

from halsdk.component import Component
from halsdk.core import _core, instance
from halsdk.errors import (
    ConflictError,
    InvalidError,
    NotFoundError,
    NotPermittedError,
    Rule,
)
from halsdk.types import Direction, HalType, parse_type, type_word

if TYPE_CHECKING:
    import subprocess

    from halsdk.core.records import Record

# fnmatch, signal, subprocess, halsdk.core.channel, halsdk.core.records
# and halsdk.loader are imported where they are used: a halcmd or halrun
# that does not need them starts faster
# (tests/halcmd/test_startup_imports.py)

Value = Union[bool, int, float, str]

# requests an attached process forwards to the host
_HOST_OPS = ("loadrt", "unloadrt", "unload", "newinst", "delinst",
             "newthread", "delthread", "addf", "delf", "start", "stop",
             "step", "loadrt_args", "recorder", "recorder_delete")


def ends_with_this_process(chained: Optional[Callable[[], None]] = None
                           ) -> Callable[[], None]:
    """A ``preexec_fn`` for ``subprocess.Popen``: the child gets SIGTERM
    from the kernel when the thread that starts it ends (with its
    process, however it ends: ``PR_SET_PDEATHSIG``), and at once if that
    already happened; then ``chained`` runs.  Start from the main thread
    so that the thread lives as long as the process."""
    import signal
    parent = os.getpid()
    sigterm = int(signal.SIGTERM)

    def preexec() -> None:
        _core.set_parent_death_signal(sigterm)
        if os.getppid() != parent:      # the parent ended already
            os.kill(os.getpid(), sigterm)
        if chained is not None:
            chained()
    return preexec


def _capture_items(what: str, names: Iterable[str]) -> list:
    """The pins, signals or params ``names`` (NotFoundError naming the
    first that is none of them)."""
    items = []
    for name in names:
        obj = (_core.find("pin", name) or _core.find("signal", name)
               or _core.find("param", name))
        if obj is None:
            raise NotFoundError(f"{what}: no pin, signal or param named "
                                f"'{name}'")
        items.append(obj)
    return items


def _capture_comp(comp: str, items: list, depth: int, thread: str,
                  position: int) -> tuple[int, Any]:
    """A realtime component ``comp`` whose function (added to ``thread``
    at ``position``) copies ``items`` into its stream of ``depth``
    records each cycle; ``(component id, stream)``.  Nothing is left
    when it fails."""
    _core.set_loading_rt(True)
    try:
        cid = _core.comp_new(comp, _core.COMP_RT)
    finally:
        _core.set_loading_rt(False)
    try:
        uses_fp = any(o.type == _core.FLOAT for o in items)
        stream = _core.capture_new(cid, comp, comp, items, depth, uses_fp)
        _core.comp_ready(cid, True)
        _core.addf(comp, thread, position)
    except BaseException:
        _core.comp_exit(cid)
        raise
    return cid, stream


def is_halcmd_comp(name: str, pid: int) -> bool:
    """Whether a component is the ``halcmd<pid>`` of a halcmd session
    (``unload all`` and ``unloadusr all`` leave those alone)."""
    return name == f"halcmd{pid}"


class Hal:
    """A HAL instance: create it (become its host) or attach to it.

    ``Hal()`` attaches to the user's instance when one runs, otherwise it
    creates it and this process becomes the host: it runs the realtime
    threads and loads realtime modules.  An attached process sends those
    operations to the host; everything else (values, links, signals,
    listing) it does directly in shared memory.

    Use it as a context manager or call :meth:`close`; the host removes
    the instance when it closes or the process exits.

    :param instance: instance name (default ``$HALSDK_INSTANCE`` or the
        user's default instance).
    :param create: True: must create; False: must attach; None: either.
    :param size: size of a new instance in bytes (default 160 MiB, enough
        for well over 100,000 pins; pages are used only when touched).
    """

    def __init__(self, instance: Optional[str] = None, *,
                 create: Optional[bool] = None, size: Optional[int] = None):
        from halsdk.core import instance as inst_mod
        self._conn = inst_mod.connect(instance, create=create, size=size)
        self._closed = False
        conn = self._conn
        with conn.lock:
            if conn.host and conn.registry is None:
                from halsdk.loader import Registry
                conn.registry = Registry()
                conn.closers.append(conn.registry.unload_all)
                for op in _HOST_OPS:
                    conn.handlers[op] = getattr(self, "_host_" + op)
                conn.handlers["ping"] = lambda: os.getpid()

    @classmethod
    def current(cls) -> Optional[Hal]:
        """The instance this process already uses, or None.

        The result is a view that does not count as one more user of the
        instance: closing it does nothing, and it does not keep the
        instance open (for modules such as the compat ``hal`` that act on
        whatever instance their caller opened).
        """
        conn = instance.current()
        if conn is None or not _core.attached():
            return None
        view = cls.__new__(cls)
        view._conn = conn
        view._closed = True
        return view

    # ------------------------------------------------------------ lifetime

    def close(self) -> None:
        """Stop using the instance (the host also removes it).

        Stop this process's other threads' use of the instance first: a
        call still running in another thread when the last user closes
        it is not guarded against the segment going away.
        """
        if not self._closed:
            self._closed = True
            instance.release(self._conn)

    def __enter__(self) -> Hal:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    @property
    def is_host(self) -> bool:
        """True in the process that created the instance."""
        return self._conn.host

    @property
    def instance(self) -> str:
        return self._conn.label

    def info(self) -> dict:
        """Size, usage, counts, host pid and clock state of the instance."""
        return _core.info()

    def end_with_host(self, who: Optional[str] = None) -> None:
        """End this attached process when the host ends: the moment it
        ends (exit, crash, SIGKILL), a line naming the instance and the
        host's pid goes to stderr (as ``who``, default the program's name)
        and this process gets SIGTERM.  A userspace component does this
        by itself (:class:`halsdk.Component`); nothing on the host."""
        instance.watch_host(self._conn, True, who)

    @property
    def host_gone(self) -> int:
        """The pid of the host once it was seen to end (after
        :meth:`end_with_host` or with a userspace component), else 0."""
        return instance.host_gone()

    def spawn(self, argv: Sequence[str], **popen: Any
              ) -> subprocess.Popen:
        """Start a program (``subprocess.Popen`` arguments) that ends
        when the host ends, however it ends (exit, crash, SIGKILL): it
        gets SIGTERM, as a host's normal exit sends its ``loadusr``
        programs.  On the host's main thread the kernel does it
        (``PR_SET_PDEATHSIG``, which it ties to the starting thread);
        elsewhere (an attached ``halcmd``, another thread of the host) a
        small ``halsdk-guard`` process waits on pidfds of the host and the
        program and ends with whichever ends first."""
        import subprocess
        import threading
        on_main = self._conn.host and \
            threading.current_thread() is threading.main_thread()
        if on_main:
            popen["preexec_fn"] = ends_with_this_process(
                popen.pop("preexec_fn", None))
        child = subprocess.Popen(list(argv), **popen)
        if not on_main:
            try:
                _core.guard_child(child.pid)
            except BaseException:
                child.terminate()
                child.wait()
                raise
        return child

    def _call_host(self, op: str, *args: Any, **kwargs: Any) -> Any:
        if self._conn.host:
            return getattr(self, "_host_" + op)(*args, **kwargs)
        from halsdk.core import channel
        return channel.request(self._conn.shm, op, *args, **kwargs)

    # ------------------------------------------------------------ modules

    def loadrt(self, name: str, *args: str, **modparams: Any) -> list[str]:
        """Load a realtime component module; returns the components made.

        Parameters come as ``"count=2"`` words, keywords, or both:
        ``hal.loadrt("and2", count=2)``.
        """
        if " " in name.strip():
            first, _, rest = name.strip().partition(" ")
            name, args = first, (rest,) + args
        return self._call_host("loadrt", name, *args, **modparams)

    def _host_loadrt(self, name: str, *args: str, **kw: Any) -> list[str]:
        with self._conn.lock:
            return self._conn.registry.load(name, *args, **kw)

    def module(self, name: str):
        """The Python module of a loaded realtime module (host only)."""
        if not self._conn.host:
            raise NotPermittedError(f"module '{name}': modules live in the "
                                    "host process")
        loaded = self._conn.registry.modules.get(name)
        if loaded is None:
            raise NotFoundError(f"module '{name}' is not loaded")
        return loaded.module

    def loadrt_args(self) -> dict[str, str]:
        """Component name -> the load-line parameters it was loaded with
        (what ``save comp`` writes)."""
        return self._call_host("loadrt_args")

    def _host_loadrt_args(self) -> dict[str, str]:
        with self._conn.lock:
            return self._conn.registry.load_args()

    def unloadrt(self, name: str) -> None:
        """Unload a realtime module (``"all"``: every module)."""
        self._call_host("unloadrt", name)

    def _host_unloadrt(self, name: str) -> None:
        with self._conn.lock:
            if name == "all":
                self._conn.registry.unload_all()
            else:
                self._conn.registry.unload(name)

    def unload(self, name: str, timeout: float = 5.0) -> None:
        """Remove a component of any kind (``"all"``: every component).

        A realtime module is unloaded; a userspace component of a live
        process is asked to exit (SIGTERM) and awaited; one whose process
        is gone is removed directly.

        ``"all"`` never signals the calling process: its own components
        are removed directly (halcmd makes its ``halcmd<pid>`` again), and
        the ``halcmd<pid>`` components of other halcmd sessions are left
        alone, as in the reference.
        """
        self._call_host("unload", name, timeout, caller=os.getpid())

    def _host_unload(self, name: str, timeout: float = 5.0,
                     caller: Optional[int] = None) -> None:
        registry = self._conn.registry
        caller = os.getpid() if caller is None else caller
        with self._conn.lock:
            if name == "all":
                registry.unload_all()
                own, users = [], []
                for c in _core.items("component"):
                    if not c.exists or c.name.startswith("__"):
                        continue
                    if c.pid == caller:
                        own.append(c)       # never signal the caller
                    elif not is_halcmd_comp(c.name, c.pid):
                        users.append(c.name)
            else:
                loaded = registry.module_of_comp(name)
                if loaded is not None or name in registry.modules:
                    registry.unload(loaded.name if loaded else name)
                    return
                own, users = [], [name]
        for c in own:
            if c.exists:
                _core.comp_exit(c.id)
        # waiting for a process to exit must not block other requests
        for comp in users:
            self._remove_user_comp(comp, timeout)

    def _remove_user_comp(self, name: str, timeout: float) -> None:
        comp = _core.find("component", name)
        if comp is None:
            raise NotFoundError(f"component '{name}' not found")
        if comp.name.startswith("__"):
            raise NotPermittedError(f"component '{name}' belongs to a "
                                    "thread; delete the thread instead")
        if comp.pid == os.getpid() or not comp.alive:
            _core.comp_exit(comp.id)
            return
        import signal
        os.kill(comp.pid, signal.SIGTERM)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if not comp.exists:
                return
            if not comp.alive:
                _core.comp_exit(comp.id)
                return
            time.sleep(0.01)
        raise ConflictError(f"component '{name}' (pid {comp.pid}) did not "
                            f"exit within {timeout:g} s of SIGTERM")

    def newinst(self, comp: str, name: str, *args: str, **kw: Any) -> None:
        """Add an instance to a loaded component that supports it."""
        self._call_host("newinst", comp, name, *args, **kw)

    def _host_newinst(self, comp: str, name: str, *args: str,
                      **kw: Any) -> None:
        from halsdk.loader import parse_modparams
        with self._conn.lock:
            loaded = self._conn.registry.module_of_comp(comp)
            if loaded is None:
                raise NotFoundError(f"component '{comp}' is not a loaded "
                                    "realtime component")
            hook = getattr(loaded.module, "new_instance", None)
            if not callable(hook):
                raise NotPermittedError(f"component '{comp}' does not "
                                        "support instances (newinst)")
            params = parse_modparams(comp, _InstParams(loaded.module),
                                     args, kw)
            _core.set_loading_rt(True)
            try:
                hook(name, **params)
            finally:
                _core.set_loading_rt(False)

    def delinst(self, name: str) -> None:
        """Remove an instance made by :meth:`newinst`."""
        self._call_host("delinst", name)

    def _host_delinst(self, name: str) -> None:
        with self._conn.lock:
            inst = _core.find("instance", name)
            if inst is None:
                raise NotFoundError(f"instance '{name}' not found")
            loaded = self._conn.registry.module_of_comp(inst.owner)
            _core.inst_delete(name)
            hook = getattr(loaded.module, "delete_instance", None) \
                if loaded else None
            if callable(hook):
                hook(name)

    # ------------------------------------------------------------ threads

    def newthread(self, name: str, period: int, fp: bool = True,
                  timing_every: int = 16) -> None:
        """Create a thread running every ``period`` ns.

        Per-function ``.time``/``.tmax`` are measured every
        ``timing_every``-th cycle (1: every cycle, as the reference does);
        the thread's own time and tmax are measured every cycle.
        """
        self._call_host("newthread", name, period, fp, timing_every)

    def _host_newthread(self, name: str, period: int, fp: bool = True,
                        timing_every: int = 16) -> None:
        if not isinstance(period, int) or isinstance(period, bool):
            raise InvalidError(f"thread '{name}': period must be an "
                               f"integer of ns, not {period!r}")
        if not 1 <= timing_every <= 1_000_000:
            raise InvalidError(f"thread '{name}': timing_every must be "
                               "1..1000000")
        _core.thread_new(name, period, fp, timing_every)

    def delthread(self, name: str) -> None:
        self._call_host("delthread", name)

    def _host_delthread(self, name: str) -> None:
        _core.thread_delete(name)

    def addf(self, funct: str, thread: str, position: int = -1) -> None:
        """Add a function to a thread; position 1 is first, -1 last."""
        self._call_host("addf", funct, thread, position)

    def _host_addf(self, funct: str, thread: str, position: int = -1):
        _core.addf(funct, thread, position)

    def delf(self, funct: str, thread: str) -> None:
        self._call_host("delf", funct, thread)

    def _host_delf(self, funct: str, thread: str) -> None:
        _core.delf(funct, thread)

    def start(self, realtime: bool = True) -> Optional[str]:
        """Start every thread in real time.

        SCHED_FIFO and locked memory are used when the process may;
        otherwise threads run with normal scheduling and a note is printed
        to stderr and returned.
        """
        return self._call_host("start", realtime)

    def _host_start(self, realtime: bool = True) -> Optional[str]:
        note = _core.start(realtime)
        if note:
            import sys
            print(note, file=sys.stderr)
        return note

    def stop(self) -> None:
        """Stop every thread."""
        self._call_host("stop")

    def _host_stop(self) -> None:
        _core.stop()

    def step(self, n: int = 1, thread: Optional[str] = None) -> None:
        """Run threads synchronously with exact simulated time.

        Without ``thread``: advance the simulated clock by ``n`` periods
        of the fastest thread, running every thread whose cycle falls due
        (faster first at equal times).  With ``thread``: run that thread
        ``n`` cycles.  Functions get the exact nominal period;
        ``rtapi_get_time()`` returns the simulated time.
        """
        self._call_host("step", n, thread)

    def _host_step(self, n: int = 1, thread: Optional[str] = None) -> None:
        _core.step(n, thread)

    def run_for(self, seconds: float) -> None:
        """Step the threads for ``seconds`` of simulated time."""
        threads = _core.items("thread")
        if not threads:
            raise NotFoundError("there are no threads to step")
        base = min(t.period for t in threads)
        self.step(max(1, round(seconds * 1e9 / base)))

    @property
    def time(self) -> int:
        """rtapi_get_time() in ns: simulated time after stepping."""
        return _core.get_time()

    def add_python_function(self, name: str, fn: Callable[[int], None],
                            thread: Optional[str] = None, fp: bool = True,
                            position: int = -1) -> None:
        """Export ``fn(period_ns)`` as a HAL function (not realtime: it
        takes the GIL) and optionally add it to a thread."""
        if not self._conn.host:
            raise NotPermittedError(f"function '{name}': Python functions "
                                    "run in the host process")
        comp = _core.find("component", "__python")
        if comp is None:
            _core.set_loading_rt(True)
            try:
                cid = _core.comp_new("__python", _core.COMP_RT)
            finally:
                _core.set_loading_rt(False)
        else:
            cid = comp.id
            _core.comp_ready(cid, False)
        try:
            _core.export_python(name, fn, cid, fp)
        finally:
            _core.comp_ready(cid, True)
        if thread is not None:
            self.addf(name, thread, position)

    # ------------------------------------------------------------ signals

    def newsig(self, name: str, type: Union[str, int]) -> _core.Signal:
        """Create a signal of a type ("bit", "float", "s32", ...)."""
        return _core.signal_new(name, parse_type(type))

    def delsig(self, name: str) -> None:
        """Delete a signal, unlinking its pins (``"all"``: every one)."""
        if name == "all":
            for sig in _core.items("signal"):
                _core.signal_delete(sig.name)
        else:
            _core.signal_delete(name)

    def net(self, signal: str, *pins: str) -> _core.Signal:
        """Link pins to a signal, creating it with the first pin's type.

        Arrow words (``=>``, ``<=``, ``<=>``) are accepted and ignored.
        The core checks every pin before anything changes.
        """
        pins = tuple(p for p in pins if p not in ("=>", "<=", "<=>"))
        _core.net(signal, pins)
        return self._need("signal", signal)

    def linkps(self, pin: str, signal: str) -> None:
        _core.link(pin, signal)

    def linksp(self, signal: str, pin: str) -> None:
        _core.link(pin, signal)

    def unlinkp(self, pin: str) -> None:
        _core.unlink(pin)

    def sets(self, name: str, value: Value, *, ignore_lock: bool = False,
             wrap: bool = False) -> None:
        """Set a signal that has no writer.

        A string is read as halcmd reads it (:mod:`halsdk.values`).
        ``ignore_lock``: set it even when the instance is locked against
        setting values (halcmd's ``sets`` does, as the reference's).
        ``wrap``: an integer word out of range wraps as in C (halcmd).
        """
        self._need("signal", name).sets(value, ignore_lock=ignore_lock,
                                        wrap=wrap)

    def gets(self, name: str) -> Value:
        return self._need("signal", name).value

    def stype(self, name: str) -> str:
        return type_word(self._need("signal", name).type)

    # ------------------------------------------------------------ values

    def _item(self, name: str):
        item = _core.find("param", name) or _core.find("pin", name)
        if item is None:
            raise NotFoundError(f"pin or param '{name}' not found",
                                rule=Rule.NOT_FOUND, kind="pin",
                                names=(name,))
        return item

    def setp(self, name: str, value: Value, *, ignore_lock: bool = False,
             wrap: bool = False) -> None:
        """Set a param, or an unlinked in/io pin, as ``halcmd setp``.

        A string is read as halcmd reads it (:mod:`halsdk.values`).
        ``ignore_lock``: set it even when the instance is locked against
        setting values (halcmd's ``setp`` does, as the reference's).
        ``wrap``: an integer word out of range wraps as in C (halcmd).
        """
        self._item(name).setp(value, ignore_lock=ignore_lock, wrap=wrap)

    def getp(self, name: str) -> Value:
        return self._item(name).value

    def ptype(self, name: str) -> str:
        return type_word(self._item(name).type)

    def alias(self, kind: str, name: str, alias: str) -> None:
        """Give a pin or param (kind ``"pin"``/``"param"``) a new name."""
        if kind not in ("pin", "param"):
            raise InvalidError(f"alias: kind must be 'pin' or 'param', "
                               f"not {kind!r}")
        _core.alias(kind, name, alias)

    def unalias(self, kind: str, alias: str) -> None:
        if kind not in ("pin", "param"):
            raise InvalidError(f"unalias: kind must be 'pin' or 'param', "
                               f"not {kind!r}")
        _core.unalias(kind, alias)

    def lock(self, level: int = 255) -> None:
        """Lock the instance (bits: 1 load, 2 config, 4 params, 8 run)."""
        _core.set_lock(level)

    def unlock(self) -> None:
        _core.set_lock(0)

    #: lock bits, as the reference numbers them
    LOCK_LOAD, LOCK_CONFIG, LOCK_PARAMS, LOCK_RUN, LOCK_ALL = 1, 2, 4, 8, 255

    @property
    def lock_level(self) -> int:
        """The lock bits in force (see :meth:`lock`); settable."""
        return _core.get_lock()

    @lock_level.setter
    def lock_level(self, level: int) -> None:
        _core.set_lock(level)

    @property
    def msg_level(self) -> int:
        """The message level (0 none .. 5 all, as ``halcmd debug``);
        settable."""
        return _core.info()["msg_level"]

    @msg_level.setter
    def msg_level(self, level: int) -> None:
        _core.set_msg_level(level)

    def counts(self) -> dict[str, int]:
        """Number of objects of each kind ("pin": 12, ...)."""
        return dict(_core.info()["counts"])

    # ------------------------------------------------------------ lookup

    def _need(self, kind: str, name: str):
        item = _core.find(kind, name)
        if item is None:
            raise NotFoundError(f"{kind} '{name}' not found",
                                rule=Rule.NOT_FOUND, kind=kind,
                                names=(name,))
        return item

    KINDS = ("component", "instance", "pin", "param", "signal", "function",
             "thread", "stream")

    def find(self, kind: str, name: str) -> Optional[Any]:
        """The handle of the object of a kind ("pin", "signal", ...) of
        that name (pins and params also by their name before an alias),
        or None."""
        self._check_kind(kind)
        return _core.find(kind, name)

    def items(self, kind: str) -> list:
        """Handles of every object of a kind, in creation order."""
        self._check_kind(kind)
        return _core.items(kind)

    def _check_kind(self, kind: str) -> None:
        if kind not in self.KINDS:
            raise InvalidError(f"unknown kind {kind!r} (one of "
                               f"{', '.join(self.KINDS)})")

    def new_component(self, name: str, prefix: Optional[str] = None, *,
                      realtime: bool = False) -> Component:
        """A component of this process on this instance (pins and params
        as with :func:`halsdk.component`), which does not keep the
        instance open: halcmd's ``halcmd<pid>``, or with ``realtime`` the
        component of a module that makes no pins (``threads``)."""
        if realtime and not self._conn.host:
            raise NotPermittedError(f"component '{name}': realtime "
                                    "components live in the host process")
        return Component(name, prefix, realtime=realtime, keep_open=False)

    def component_by_id(self, comp_id: int) -> Optional[_core.Component]:
        """The component (or None) with that id."""
        return _core.comp_by_id(comp_id)

    def shared_block(self, name: str) -> tuple[int, int]:
        """``(address, size)`` in this process of a named shared block
        that a realtime module made (NotFoundError if there is none)."""
        return _core.shmem_attach(name)

    def new_shared_block(self, name: str, size: int,
                         owner: Component) -> tuple[int, int]:
        """Create a named shared block of ``size`` zeroed bytes owned by
        ``owner``, a component of this process (the block is deleted with
        it); returns ``(address, size)``.  ConflictError when the name is
        taken."""
        return _core.shmem_new(name, owner.id, size)

    def private_socket_path(self, purpose: str) -> str:
        """The path of a Unix socket of this instance for ``purpose``
        (``"task"``: the machine's command channel), in the user's private
        runtime folder (mode 0700), beside the host's request socket.
        TrustError when that folder is another user's, a link, or open to
        others (docs/concepts.rst, "the trust checks")."""
        from halsdk.core import channel
        if purpose not in channel.SOCKET_PURPOSES:
            raise InvalidError(f"socket purpose {purpose!r}: one of "
                               f"{', '.join(channel.SOCKET_PURPOSES)}")
        return os.path.join(channel.socket_dir(),
                            self._conn.shm.lstrip("/") + f".{purpose}.sock")

    def pin(self, name: str) -> _core.Pin:
        return self._need("pin", name)

    def param(self, name: str) -> _core.Param:
        return self._need("param", name)

    def signal(self, name: str) -> _core.Signal:
        return self._need("signal", name)

    def component(self, name: str) -> _core.Component:
        return self._need("component", name)

    def function(self, name: str) -> _core.Function:
        return self._need("function", name)

    def thread(self, name: str) -> _core.Thread:
        return self._need("thread", name)

    @staticmethod
    def _list(kind: str, pattern: Union[str, Iterable[str]]) -> list:
        # the names come with the handles, taken under the lock: an
        # object deleted meanwhile by another process cannot make the
        # listing fail (its handle is then stale, as any handle can be)
        import fnmatch
        pats = [pattern] if isinstance(pattern, str) else list(pattern)
        found = [(name, it) for name, it in _core.named_items(kind)
                 if any(fnmatch.fnmatchcase(name, p) for p in pats)]
        found.sort(key=lambda pair: pair[0])
        return [it for _, it in found]

    def snapshot(self, kind: str, pattern: Union[str, Iterable[str]] = "*",
                 *, sort: bool = True) -> list[Record]:
        """Records of the objects of a kind whose names match a glob
        pattern, sorted by name (``sort=False``: in creation order):
        copies of their metadata and values
        taken by the core in one pass under the instance lock
        (:mod:`halsdk.core.records`: ``PinInfo``, ``SignalInfo``, ...).

        Unlike the handles of :meth:`pins` and the like, records never go
        stale: a snapshot is a consistent picture of the instance at one
        moment and never fails because another process loads or unloads
        components meanwhile.  halcmd's ``show``, ``list`` and ``save``
        print snapshots."""
        import fnmatch
        self._check_kind(kind)
        pats = [pattern] if isinstance(pattern, str) else list(pattern)
        found = [r for r in _core.snapshot(kind)
                 if pats == ["*"]
                 or any(fnmatch.fnmatchcase(r.name, p) for p in pats)]
        if sort:
            found.sort(key=lambda r: r.name)
        return found

    def pins(self, pattern: Union[str, Iterable[str]] = "*") -> list:
        """Pins whose names match a glob pattern, sorted by name."""
        return self._list("pin", pattern)

    def params(self, pattern: Union[str, Iterable[str]] = "*") -> list:
        return self._list("param", pattern)

    def signals(self, pattern: Union[str, Iterable[str]] = "*") -> list:
        return self._list("signal", pattern)

    def components(self, pattern: Union[str, Iterable[str]] = "*") -> list:
        return self._list("component", pattern)

    def functions(self, pattern: Union[str, Iterable[str]] = "*") -> list:
        return self._list("function", pattern)

    def threads(self, pattern: Union[str, Iterable[str]] = "*") -> list:
        return self._list("thread", pattern)

    def instances(self, pattern: Union[str, Iterable[str]] = "*") -> list:
        return self._list("instance", pattern)

    # ------------------------------------------------------------ capture

    def stream(self, name: str) -> _core.Stream:
        """The stream ``name`` (e.g. ``"sampler.0"``): a realtime FIFO that
        can be read in bulk into NumPy arrays (``read_many``)."""
        return _core.stream_attach(name)

    def new_stream(self, name: str, depth: int, typestring: str,
                   owner: Component) -> _core.Stream:
        """Create the stream ``name`` of ``depth`` (it holds ``depth - 1``
        records, as the reference's streams) with one value per letter of
        ``typestring`` (f float, b bit, s s32, u u32, l s64, k u64), owned
        by ``owner``, a component of this process (the stream is deleted
        with it).  ConflictError when the name is taken, InvalidError for
        a bad depth or type string."""
        return _core.stream_create(name, owner.id, depth, typestring)

    def capture(self, names: Union[str, Iterable[str]], cycles: int,
                thread: Optional[str] = None, position: int = -1,
                timeout: Optional[float] = None) -> dict:
        """Record pins, signals or params once per cycle of a thread.

        A realtime function (added to ``thread`` at ``position``, default:
        last, after every other function) copies the values into a stream
        on each cycle; the result maps each name to a NumPy array of
        ``cycles`` values.  When the threads are not running, the threads
        are stepped (simulated time) until ``cycles`` cycles of ``thread``
        ran, so exactly one record per cycle is taken; when they run, this
        waits (at most ``timeout`` seconds) for ``cycles`` cycles.  The
        default thread is the fastest one.  Host process only.
        """
        if not self._conn.host:
            raise NotPermittedError("capture runs a realtime function and "
                                    "works in the host process only")
        if isinstance(names, str):
            names = [names]
        names = list(names)
        if len(set(names)) != len(names):
            raise InvalidError(f"capture: names repeat: {names}")
        if not isinstance(cycles, int) or cycles < 1:
            raise InvalidError(f"capture: cycles={cycles!r} is not a "
                               "positive integer")
        items = _capture_items("capture", names)
        threads = _core.items("thread")
        if thread is None:
            if not threads:
                raise NotFoundError("capture: there are no threads")
            th = min(threads, key=lambda t: t.period)
        else:
            th = self.thread(thread)
        Hal._captures += 1
        comp = f"__capture{os.getpid()}.{Hal._captures}"
        cid, stream = _capture_comp(comp, items, cycles, th.name, position)
        try:
            if _core.info()["threads_running"]:
                limit = timeout if timeout is not None else \
                    5.0 + 2.0 * cycles * th.period * 1e-9
                deadline = time.monotonic() + limit
                while stream.depth < cycles:
                    if time.monotonic() > deadline:
                        raise TimeoutError(
                            f"capture: {stream.depth} of {cycles} cycles of "
                            f"thread '{th.name}' in {limit:.1f} s")
                    time.sleep(min(0.01, th.period * 1e-9 * 10))
            else:
                base = min(t.period for t in threads)
                if th.period == base:
                    _core.step(cycles)
                else:
                    _core.step(-(-cycles * th.period // base))
                while stream.depth < cycles:
                    _core.step(1)
            arr = stream.read_many(cycles, names)
            return {n: arr[n].copy() for n in names}
        finally:
            _core.comp_exit(cid)

    _captures = 0

    # ------------------------------------------------------------ recorders

    #: the prefix of a recorder's component, function and stream
    RECORDER_PREFIX = "__recorder"
    #: most records a recorder's stream holds
    RECORDER_MAX_DEPTH = 1 << 20

    def recorder(self, names: Union[str, Iterable[str]], thread: str,
                 depth: int) -> str:
        """Start recording pins, signals or params once per cycle of
        ``thread`` into a stream, until :meth:`recorder_delete`.

        The continuous form of :meth:`capture`, for an attached process
        too (the host runs it): a realtime function, added last to
        ``thread``, copies the current value of each name (a pin's value
        is looked up on every cycle, so linking it later is seen) into a
        stream of ``depth`` records that the caller drains with
        ``Hal.stream(name).read_many()``; records that find it full are
        dropped and counted (``overruns``, a gap in ``sampleno``).
        Returns the recorder's name (of its component, function and
        stream).  The recorder belongs to the calling process: the host
        removes the recorders of processes that have ended whenever a
        recorder is made or deleted.
        """
        if isinstance(names, str):
            names = [names]
        return self._call_host("recorder", list(names), thread, depth,
                               os.getpid())

    def _host_recorder(self, names: list, thread: str, depth: int,
                       pid: int) -> str:
        if not isinstance(names, list) or not all(
                isinstance(n, str) for n in names):
            raise InvalidError("recorder: names must be a list of strings")
        if not 1 <= len(names) <= 256:
            raise InvalidError(f"recorder of {len(names)} values: 1 to 256 "
                               "allowed")
        if isinstance(depth, bool) or not isinstance(depth, int) or \
                not 2 <= depth <= Hal.RECORDER_MAX_DEPTH:
            raise InvalidError(f"recorder: depth={depth!r}: 2 to "
                               f"{Hal.RECORDER_MAX_DEPTH} records allowed")
        if isinstance(pid, bool) or not isinstance(pid, int) or pid <= 0:
            raise InvalidError(f"recorder: bad pid {pid!r}")
        with self._conn.lock:
            self._sweep_recorders()
            items = _capture_items("recorder", names)
            th = self.thread(thread)
            Hal._captures += 1
            comp = f"{Hal.RECORDER_PREFIX}{pid}.{Hal._captures}"
            _capture_comp(comp, items, depth - 1, th.name, -1)
            return comp

    def recorder_delete(self, name: str) -> None:
        """Remove a recorder made by :meth:`recorder` (its function leaves
        the thread, its stream goes)."""
        self._call_host("recorder_delete", name)

    def _host_recorder_delete(self, name: str) -> None:
        if not isinstance(name, str) or \
                not name.startswith(Hal.RECORDER_PREFIX):
            raise InvalidError(f"'{name}' is not a recorder")
        with self._conn.lock:
            comp = _core.find("component", name)
            if comp is None:
                raise NotFoundError(f"recorder '{name}' not found")
            _core.comp_exit(comp.id)
            self._sweep_recorders()

    def _sweep_recorders(self) -> None:
        """Remove the recorders whose process has ended."""
        for comp in _core.items("component"):
            if not comp.name.startswith(Hal.RECORDER_PREFIX):
                continue
            pid = comp.name[len(Hal.RECORDER_PREFIX):].split(".")[0]
            if pid.isdigit() and not _core.pid_alive(int(pid)):
                _core.comp_exit(comp.id)

    # ------------------------------------------------------------ halcmd

    def source(self, path: str, *, keep_going: bool = False,
               ini: Optional[str] = None) -> str:
        """Run a HAL file, as ``halcmd -f`` does; returns what it printed.

        A failing command raises :class:`~halsdk.errors.HalError` with the
        ``file:line: message`` lines (with ``keep_going``, after running
        the rest of the file).
        """
        from halsdk import halcmd
        out: list[str] = []
        err: list[str] = []
        failures = halcmd.source(self, path, keep_going=keep_going, ini=ini,
                                 out=out.append, err=err.append)
        if failures:
            from halsdk.errors import HalError
            raise HalError("".join(err).rstrip("\n"))
        return "".join(out)

    def command(self, line: str) -> str:
        """Run one line of the HAL language (``"show pin"``, ``"net x a
        b"``); returns what it printed, raises
        :class:`~halsdk.errors.HalError` with its message on failure."""
        from halsdk import halcmd
        out: list[str] = []
        err: list[str] = []
        if not halcmd.command(self, line, out=out.append, err=err.append):
            from halsdk.errors import HalError
            raise HalError("".join(err).rstrip("\n") or f"'{line}' failed")
        return "".join(out)

    def check(self) -> None:
        """Verify the instance's invariants; raise if any is broken.

        The lists, counts, name index, signal link counts, pin owners and
        links, and function users are checked in O(n log n) under the
        instance lock (well under a second at 125,000 pins)."""
        bad, report = _core.check_consistency()
        if bad:
            from halsdk.errors import InstanceError
            raise InstanceError(f"HAL instance '{self.instance}' is "
                                f"inconsistent ({bad} problems): {report}")

    @property
    def lock_timeout(self) -> float:
        """Seconds this process waits for the instance lock before the
        operation fails with :class:`~halsdk.errors.LockTimeoutError`
        naming the holder's pid (default 5 s, or ``$HALSDK_LOCK_TIMEOUT``
        when the process starts); settable, for the whole process."""
        return _core.lock_timeout()

    @lock_timeout.setter
    def lock_timeout(self, seconds: float) -> None:
        _core.set_lock_timeout(seconds)


def check_name(name: str, what: str = "object") -> None:
    """Raise :class:`~halsdk.InvalidError` (rule ``BAD_NAME``) if the core
    would refuse ``name`` for a new ``what`` ("pin", "instance", ...)."""
    _core.check_name(name, what)


class _InstParams:
    """The ``instance_params`` of a module, seen as ``modparams``."""

    def __init__(self, module):
        self.modparams = getattr(module, "instance_params", None) or {}


__all__ = ["Hal", "HalType", "Direction"]
