"""Userspace components written in Python: :func:`halsdk.component`."""

from __future__ import annotations

from typing import Any, Optional, Union

from halsdk.core import _core, instance
from halsdk.errors import ExistsError, NotFoundError, NotPermittedError
from halsdk.types import parse_direction, parse_type


class Component:
    """A userspace component owned by this process.

    Create pins and params, call :meth:`ready`, then read inputs and write
    outputs with ``comp["name"]`` (names are relative to the component's
    prefix).  The component and its pins disappear with :meth:`exit`, when
    the process exits, or when the host unloads it.

    A process with a userspace component ends with the instance's host:
    the moment the host ends (however: exit, crash, SIGKILL) the process
    gets SIGTERM after a line on stderr naming the instance and the host's
    pid (``docs/halcmd.rst``, "When a process dies").  If this process
    itself dies without removing the component, the host marks it
    ``dead`` and sets its out pins to zero.

    ``realtime=True`` makes a realtime component instead: what a module
    loaded with ``loadrt`` in the host makes (e.g. ``threads``).
    """

    def __init__(self, name: str, prefix: Optional[str] = None,
                 instance_name: Optional[str] = None, *,
                 realtime: bool = False, keep_open: bool = True):
        # keep_open=False: made by Hal.new_component, on the instance
        # this process uses, without keeping it open
        self._conn = instance.connect(instance_name) if keep_open else None
        try:
            self.id = _core.comp_new(
                name, _core.COMP_RT if realtime else _core.COMP_USER)
        except Exception:
            if self._conn is not None:
                instance.release(self._conn)
            raise
        self.name = name
        self.prefix = prefix if prefix is not None else name
        self._items: dict[str, Any] = {}
        self._exited = False
        if self._conn is not None and not realtime:
            # a userspace component's process ends with the host
            # (SIGTERM and a line on stderr the moment the host ends)
            instance.watch_host(self._conn, end_process=True)

    def _full(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def newpin(self, name: str, type: Union[str, int],
               direction: Union[str, int]) -> _core.Pin:
        """Create a pin ``<prefix>.<name>``; before :meth:`ready` only."""
        if name in self._items:
            raise ExistsError(f"duplicate pin or param name "
                              f"'{self._full(name)}'")
        pin = _core.pin_new(self._full(name), parse_type(type),
                            parse_direction(direction), self.id)
        self._items[name] = pin
        return pin

    def newparam(self, name: str, type: Union[str, int],
                 direction: Union[str, int]) -> _core.Param:
        """Create a param ``<prefix>.<name>``; before :meth:`ready` only."""
        if name in self._items:
            raise ExistsError(f"duplicate pin or param name "
                              f"'{self._full(name)}'")
        param = _core.param_new(self._full(name), parse_type(type),
                                parse_direction(direction, param=True),
                                self.id)
        self._items[name] = param
        return param

    def ready(self) -> None:
        _core.comp_ready(self.id, True)

    def unready(self) -> None:
        _core.comp_ready(self.id, False)

    @property
    def is_ready(self) -> bool:
        """False once removed, or before :meth:`ready`."""
        return self.exists and _core.comp_by_id(self.id).ready

    def item(self, name: str):
        try:
            return self._items[name]
        except KeyError:
            raise NotFoundError(f"component '{self.name}' has no pin or "
                                f"param '{name}'") from None

    def __getitem__(self, name: str):
        return self.item(name).value

    def __setitem__(self, name: str, value: Any) -> None:
        # the owner writes its own pins and params in any direction
        self.item(name).write(value)

    def __contains__(self, name: str) -> bool:
        return name in self._items

    def __iter__(self):
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    @property
    def exists(self) -> bool:
        """False once the component was removed (by exit or unload)."""
        if self._exited or not _core.attached():
            return False
        comp = _core.comp_by_id(self.id)
        return comp is not None and comp.name == self.name

    @property
    def host_gone(self) -> int:
        """The pid of the instance's host once it has ended (this
        process then gets SIGTERM), else 0."""
        return instance.host_gone()

    def exit(self) -> None:
        """Remove the component and its pins."""
        if self._exited:
            return
        self._exited = True
        try:
            if _core.attached() and _core.comp_by_id(self.id) is not None:
                _core.comp_exit(self.id)
        finally:
            if self._conn is not None:
                instance.release(self._conn)

    def __enter__(self) -> Component:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.exit()

    def __repr__(self) -> str:
        return f"<halsdk.Component {self.name!r}>"


def component(name: str, prefix: Optional[str] = None,
              instance: Optional[str] = None) -> Component:
    """Create a userspace component in the running instance (or in a new
    one, hosted by this process, if none runs)."""
    if not name:
        raise NotPermittedError("a component needs a name")
    return Component(name, prefix, instance)
