"""LinuxCNC's Python ``hal`` module, implemented on halsdk.

Userspace components written for LinuxCNC run unchanged when ``import hal``
finds this module (put :func:`halsdk.compat.pythonpath` on ``PYTHONPATH``)::

    import hal
    h = hal.component("scale")
    h.newpin("in", hal.HAL_FLOAT, hal.HAL_IN)
    h.newpin("out", hal.HAL_FLOAT, hal.HAL_OUT)
    h.newparam("gain", hal.HAL_FLOAT, hal.HAL_RW)
    h.ready()
    try:
        while True:
            h["out"] = h["in"] * h["gain"]
            time.sleep(0.01)
    except KeyboardInterrupt:
        raise SystemExit

The component attaches to the running instance (``$HALSDK_INSTANCE`` or the
user's default one) or, when none runs, creates one.  ``halcmd unload``
(SIGTERM) raises :class:`KeyboardInterrupt` in the main thread, as in
LinuxCNC.  Errors raise the same exception types as LinuxCNC's module;
:class:`error` is also a :class:`halsdk.HalError`.
"""

from __future__ import annotations

import ctypes
import errno
import operator
import os
import signal as _signal
import sys
import threading
from typing import Any, Optional, Union

import halsdk
from halsdk.errors import ExistsError, HalError, NotFoundError, Rule, StaleError
from halsdk.types import INT_RANGES, Direction, HalType

__all__ = [
    "HAL_BIT", "HAL_FLOAT", "HAL_S32", "HAL_U32", "HAL_S64", "HAL_U64",
    "HAL_IN", "HAL_OUT", "HAL_IO", "HAL_RO", "HAL_RW",
    "MSG_NONE", "MSG_ERR", "MSG_WARN", "MSG_INFO", "MSG_DBG", "MSG_ALL",
    "is_kernelspace", "is_rt", "is_sim", "is_userspace", "kernel_version",
    "error", "item", "Pin", "Param", "component", "stream", "shm",
    "streamer_base", "sampler_base",
    "component_exists", "component_is_ready", "connect", "disconnect",
    "new_sig", "set_p", "get_value", "pin_has_writer", "get_info_pins",
    "get_info_params", "get_info_signals", "get_msg_level", "set_msg_level",
]

HAL_BIT = 1
HAL_FLOAT = 2
HAL_S32 = 3
HAL_U32 = 4
HAL_S64 = 6
HAL_U64 = 7

HAL_IN = 16
HAL_OUT = 32
HAL_IO = 48
HAL_RO = 64
HAL_RW = 192

MSG_NONE = 0
MSG_ERR = 1
MSG_WARN = 2
MSG_INFO = 3
MSG_DBG = 4
MSG_ALL = 5

# what LinuxCNC's simulator (uspace, non-realtime) build reports
is_kernelspace = 0
is_rt = 0
is_sim = 1
is_userspace = 1
kernel_version = "Not Available"

# the reference's words are the enum names: BIT, S32, IN, IO, RO, ...
_TYPE_NAMES = {int(t): t.name for t in HalType}
_DIR_NAMES = {int(d): d.name for d in Direction}
_CLOSED = "Invalid operation on closed HAL component"
_NO_COMPONENT = "Cannot call before creating component"

Value = Union[bool, int, float]


class error(HalError):  # noqa: N801 - the reference's name
    """Raised where LinuxCNC's ``hal`` module raises ``hal.error``: a bad
    type or direction, a name HAL refuses, ready/unready twice, a
    duplicate component."""


# ---------------------------------------------------------------- helpers

def _need_str(value: Any, position: int) -> str:
    if not isinstance(value, str):
        raise TypeError(f"argument {position} must be str, not "
                        f"{type(value).__name__}")
    return value


def _need_instance() -> halsdk.Hal:
    """The instance this process uses (RuntimeError if none)."""
    hal = halsdk.Hal.current()
    if hal is None:
        raise RuntimeError(_NO_COMPONENT)
    return hal


def _convert(htype: int, value: Any) -> Value:
    """A Python value for a pin or param of type ``htype``, converted the
    way LinuxCNC's module converts it (bits by truth value, integers by
    ``int()`` and a range check)."""
    if htype == HAL_BIT:
        return bool(value)
    if htype == HAL_FLOAT:
        try:
            return float(value)
        except (TypeError, ValueError):
            raise TypeError(f"Number expected, not "
                            f"{type(value).__name__}") from None
    number = int(value)
    lo, hi = INT_RANGES[HalType(htype)]
    if not -(1 << 63) <= number <= max(hi, (1 << 63) - 1):
        raise OverflowError("int too big to convert")
    if not lo <= number <= hi:
        raise OverflowError(f"Value {number} out of range")
    return number


def _report(exc: BaseException) -> bool:
    """Print a failed call as LinuxCNC prints HAL errors; True (failure)."""
    if get_msg_level() >= MSG_ERR:
        print(f"HAL: ERROR: {exc}", file=sys.stderr)
    return True


def _install_sigterm() -> None:
    """Let SIGTERM (``halcmd unload``) raise KeyboardInterrupt in the main
    thread, unless the program installed a handler of its own."""
    if threading.current_thread() is not threading.main_thread():
        return
    current = _signal.getsignal(_signal.SIGTERM)
    if current in (_signal.SIG_DFL, None) or getattr(
            current, "__module__", None) == "halsdk.core.instance":
        _signal.signal(_signal.SIGTERM, _signal.default_int_handler)


# ---------------------------------------------------------------- items

class _State:
    """Open/closed state shared by a component and its items (the items do
    not keep the component alive, so dropping it removes it)."""

    __slots__ = ("closed",)

    def __init__(self) -> None:
        self.closed = True

    def check(self) -> None:
        if self.closed:
            raise RuntimeError(_CLOSED)


class item:  # noqa: N801 - the reference's name
    """A pin or param of a :class:`component` of this process, as returned
    by :meth:`component.getitem`."""

    __slots__ = ("_state", "_name", "_handle", "_is_pin", "_type", "_dir")
    _state: _State
    _name: str
    _handle: Any
    _is_pin: bool
    _type: int
    _dir: int

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError("hal.item objects come from component.getitem()")

    @classmethod
    def _make(cls, state: _State, name: str, handle: Any, is_pin: bool,
              htype: int, hdir: int) -> item:
        self = object.__new__(cls)
        self._state = state
        self._name = name
        self._handle = handle
        self._is_pin = is_pin
        self._type = htype
        self._dir = hdir
        return self

    def get(self) -> Value:
        """The current value."""
        self._state.check()
        try:
            return self._handle.value
        except StaleError:
            raise RuntimeError(_CLOSED) from None

    def set(self, value: Any) -> None:
        """Write the value (the owner may write any direction)."""
        self._state.check()
        converted = _convert(self._type, value)
        try:
            self._handle.write(converted)
        except StaleError:
            raise RuntimeError(_CLOSED) from None

    def get_name(self) -> str:
        """The name given to newpin/newparam (without the prefix)."""
        return self._name

    def get_type(self) -> int:
        return self._type

    def get_dir(self) -> int:
        return self._dir

    def is_pin(self) -> bool:
        return self._is_pin

    def __repr__(self) -> str:
        kind = "pin" if self._is_pin else "param"
        return (f'<hal {kind} "{self._name}" {_TYPE_NAMES[self._type]}-'
                f"{_DIR_NAMES[self._dir]}>")


class _ItemWrap:
    """Base of :class:`Pin` and :class:`Param`: an :class:`item` with
    ``name``, ``type``, ``dir`` and ``value`` properties."""

    def __init__(self, wrapped: item) -> None:
        if not isinstance(wrapped, item):
            raise TypeError(f"Constructor argument must be hal.item: "
                            f"{type(wrapped)}")
        self._item = wrapped

    def get(self) -> Value:
        return self._item.get()

    def set(self, value: Any) -> None:
        self._item.set(value)

    def get_name(self) -> str:
        return self._item.get_name()

    def get_type(self) -> int:
        return self._item.get_type()

    def get_dir(self) -> int:
        return self._item.get_dir()

    def is_pin(self) -> bool:
        return self._item.is_pin()

    @property
    def name(self) -> str:
        return self._item.get_name()

    @property
    def type(self) -> int:
        return self._item.get_type()

    @property
    def dir(self) -> int:
        return self._item.get_dir()

    @property
    def value(self) -> Value:
        return self._item.get()

    @value.setter
    def value(self, value: Any) -> None:
        self._item.set(value)

    def __repr__(self) -> str:
        return repr(self._item)


class Pin(_ItemWrap):
    """A pin of a component of this process."""

    def __init__(self, wrapped: item) -> None:
        super().__init__(wrapped)
        if not wrapped.is_pin():
            raise TypeError("Must be constructed from pin object")


class Param(_ItemWrap):
    """A parameter of a component of this process."""

    def __init__(self, wrapped: item) -> None:
        super().__init__(wrapped)
        if wrapped.is_pin():
            raise TypeError("Must be constructed from param object")


# ---------------------------------------------------------------- component

_INTERNAL = frozenset({"_c_comp", "_c_name", "_c_prefix", "_c_items",
                       "_c_state"})


class component:  # noqa: N801 - the reference's name
    """A userspace component owned by this process.

    ``component(name, prefix=name)``: pins and params are named
    ``<prefix>.<name>``.  Create them with :meth:`newpin` and
    :meth:`newparam`, call :meth:`ready`, then read and write them as
    ``comp["name"]`` or ``comp.name``.
    """

    # the attributes of the object itself (_INTERNAL; set with
    # object.__setattr__): every other attribute name is a pin or param
    _c_state: _State
    _c_comp: halsdk.Component
    _c_name: str
    _c_prefix: str
    _c_items: dict[str, item]

    def __init__(self, name: str, prefix: Optional[str] = None) -> None:
        object.__setattr__(self, "_c_state", _State())
        if not isinstance(name, str):
            raise TypeError(f"hal.component() argument 1 must be str, not "
                            f"{type(name).__name__}")
        if prefix is None:
            prefix = name
        elif not isinstance(prefix, str):
            raise TypeError(f"hal.component() argument 2 must be str, not "
                            f"{type(prefix).__name__}")
        try:
            comp = halsdk.component(name, prefix)
        except HalError as exc:
            raise error(str(exc)) from exc
        object.__setattr__(self, "_c_comp", comp)
        object.__setattr__(self, "_c_name", name)
        object.__setattr__(self, "_c_prefix", prefix)
        object.__setattr__(self, "_c_items", {})
        self._c_state.closed = False
        _install_sigterm()

    def _check_open(self) -> None:
        self._c_state.check()

    def _check_live(self) -> None:
        """Open, and not removed by the host (``unload``) meanwhile."""
        self._c_state.check()
        if not self._c_comp.exists:
            raise RuntimeError(_CLOSED)

    # ----------------------------------------------------------- creation

    def _new(self, name: str, htype: int, hdir: int, pin: bool) -> item:
        _need_str(name, 1)
        htype = operator.index(htype)
        hdir = operator.index(hdir)
        self._check_live()
        if name in self._c_items:
            what = "pin" if pin else "parameter"
            raise ValueError(f"Duplicate {what} name '{name}'")
        kind = "pin" if pin else "param"
        if htype not in _TYPE_NAMES:
            raise error(f"Invalid {kind} type {htype}")
        allowed = (HAL_IN, HAL_OUT, HAL_IO) if pin else (HAL_RO, HAL_RW)
        if hdir not in allowed:
            words = "HAL_IN, HAL_OUT or HAL_IO" if pin else "HAL_RO or HAL_RW"
            raise error(f"Invalid {kind} direction {hdir} for '{name}' "
                        f"(one of {words})")
        comp = self._c_comp
        comp.prefix = self._c_prefix
        try:
            if pin:
                handle = comp.newpin(name, htype, hdir)
            else:
                handle = comp.newparam(name, htype, hdir)
        except StaleError:
            raise RuntimeError(_CLOSED) from None
        except HalError as exc:
            raise error(str(exc)) from exc
        made = item._make(self._c_state, name, handle, pin, htype, hdir)
        self._c_items[name] = made
        return made

    def newpin(self, name: str, htype: int, hdir: int, /) -> Pin:
        """Create the pin ``<prefix>.<name>`` of a type (HAL_BIT, ...) and
        a direction (HAL_IN, HAL_OUT, HAL_IO); before :meth:`ready`."""
        return Pin(self._new(name, htype, hdir, True))

    def newparam(self, name: str, htype: int, hdir: int, /) -> Param:
        """Create the param ``<prefix>.<name>`` (HAL_RO or HAL_RW)."""
        return Param(self._new(name, htype, hdir, False))

    def getitem(self, name: str, /) -> item:
        """The :class:`item` of a pin or param made by this component."""
        _need_str(name, 1)
        self._check_open()
        found = self._c_items.get(name)
        if found is None:
            raise AttributeError(f"Pin '{name}' does not exist")
        return found

    def getpin(self, name: str, /) -> Pin:
        """The :class:`Pin` of a pin made by this component."""
        return Pin(self.getitem(name))

    def getparam(self, name: str, /) -> Param:
        """The :class:`Param` of a param made by this component."""
        return Param(self.getitem(name))

    def getpins(self) -> dict[str, Value]:
        """Every pin and param of the component: {name: value}."""
        self._check_open()
        return {n: self._c_items[n].get() for n in sorted(self._c_items)}

    def getprefix(self) -> str:
        """The prefix of pins and params created from now on."""
        self._check_open()
        return self._c_prefix

    def setprefix(self, prefix: str, /) -> None:
        """Change the prefix of pins and params created from now on."""
        _need_str(prefix, 1)
        self._check_open()
        object.__setattr__(self, "_c_prefix", prefix)

    # ----------------------------------------------------------- state

    def ready(self) -> None:
        """Mark the component ready (``loadusr -W`` waits for this)."""
        self._check_live()
        if self._c_comp.is_ready:
            raise error(f"Component '{self._c_name}' already ready")
        self._c_comp.ready()

    def unready(self) -> None:
        """Mark the component not ready: pins may be added again."""
        self._check_live()
        if not self._c_comp.is_ready:
            raise error(f"Component '{self._c_name}' already unready")
        self._c_comp.unready()

    def exit(self) -> None:
        """Remove the component and its pins; the object is closed."""
        self._check_open()
        self._c_state.closed = True
        self._c_comp.exit()

    def __del__(self) -> None:
        try:
            if not self._c_state.closed:
                self._c_state.closed = True
                self._c_comp.exit()
        except Exception:  # interpreter shutdown, instance gone
            pass

    # ----------------------------------------------------------- values

    def __getitem__(self, name: str) -> Value:
        if not isinstance(name, str):
            raise TypeError("bad argument type for built-in operation")
        return self.getitem(name).get()

    def __setitem__(self, name: str, value: Any) -> None:
        if not isinstance(name, str):
            raise TypeError("bad argument type for built-in operation")
        self.getitem(name).set(value)

    def __delitem__(self, name: str) -> None:
        raise TypeError("pins and params of a hal.component cannot be "
                        "deleted")

    def __getattr__(self, name: str) -> Value:
        # only called for names that are not attributes: pins and params
        if name in _INTERNAL or (name.startswith("__")
                                 and name.endswith("__")):
            raise AttributeError(name)
        return self[name]

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _INTERNAL:
            object.__setattr__(self, name, value)
        else:
            self[name] = value

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"'{name}': pins and params of a hal.component "
                             "cannot be deleted")

    def __len__(self) -> int:
        self._check_open()
        return len(self._c_items)

    def __repr__(self) -> str:
        if self._c_state.closed:
            return f"<hal component {self._c_name} (closed)>"
        return (f"<hal component {self._c_name}({self._c_comp.id}) with "
                f"{len(self._c_items)} pins and params>")


# ---------------------------------------------------------------- streams

#: key of the stream of ``loadrt streamer`` channel 0 (channel N: + N)
streamer_base = 0x48535430
#: key of the stream of ``loadrt sampler`` channel 0 (channel N: + N)
sampler_base = 0x48534130
# channels of streamer/sampler reached by key (base + N, N below this)
_CHANNELS = 256


def _stream_name(key: int) -> str:
    """The name of the stream of a key: ``streamer.N`` and ``sampler.N``
    for the keys of the reference's streamer and sampler channels (so
    halstreamer, halsampler and the components find them), else
    ``stream.KKKKKKKK`` (the key in hex)."""
    k = key & 0xFFFFFFFF
    for base, comp in ((streamer_base, "streamer"), (sampler_base, "sampler")):
        if 0 <= k - base < _CHANNELS:
            return f"{comp}.{k - base}"
    return f"stream.{k:08x}"


def _shm_name(key: int) -> str:
    """The name of the shared block of a key: ``shm.KKKKKKKK``."""
    return f"shm.{key & 0xFFFFFFFF:08x}"


def _int32(value: Any) -> int:
    """An int argument as the reference parses a C ``int``."""
    number = operator.index(value)
    if number > 0x7FFFFFFF:
        raise OverflowError("signed integer is greater than maximum")
    if number < -0x80000000:
        raise OverflowError("signed integer is less than minimum")
    return number


def _os_error(code: int) -> OSError:
    return OSError(code, os.strerror(code))


def _tname(value: Any) -> str:
    """The type of a value as the reference's argument errors name it."""
    return "None" if value is None else type(value).__name__


def _need_component(value: Any, who: str) -> component:
    if not isinstance(value, component):
        raise TypeError(f"{who}argument 1 must be hal.component, not "
                        f"{_tname(value)}")
    return value


_LETTERS = {"f": HAL_FLOAT, "b": HAL_BIT, "s": HAL_S32, "u": HAL_U32,
            "l": HAL_S64, "k": HAL_U64}


class stream:  # noqa: N801 - the reference's name
    """A FIFO of records shared with a realtime component or another
    process, found by a key (an int).

    ``stream(comp, key, depth, cfg)`` creates it (the creator) with one
    value per letter of ``cfg`` (f float, b bit, s s32, u u32, and l s64,
    k u64); a stream of ``depth`` holds ``depth - 1`` records.
    ``stream(comp, key[, cfg])`` attaches to an existing one (``cfg``, if
    given, must match its types).  ``streamer_base + N`` is the stream of
    ``loadrt streamer`` channel N (write it), ``sampler_base + N`` that of
    ``loadrt sampler`` channel N (read it).  One process writes, one reads.
    """

    __slots__ = ("_s", "_key", "_creator", "_sampleno", "_types")
    _s: Any
    _key: int
    _creator: bool
    _sampleno: int
    _types: list

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        for kw in kwargs:
            if kw not in ("depth", "cfg"):
                raise TypeError(f"hal.stream() got an unexpected keyword "
                                f"argument '{kw}'")
        if len(args) < 2:
            raise TypeError(f"hal.stream() takes at least 2 arguments "
                            f"({len(args)} given)")
        if len(args) > 4:
            raise TypeError(f"hal.stream() takes at most 4 arguments "
                            f"({len(args)} given)")
        comp, key, *rest = args
        depth: Any = rest[0] if len(rest) == 2 else None
        cfg: Any = rest[-1] if rest else None
        for kw, given in (("depth", len(rest) == 2), ("cfg", bool(rest))):
            if kw in kwargs:
                if given:
                    raise TypeError(f"argument for hal.stream() given by "
                                    f"name ('{kw}') and position")
                if kw == "depth":
                    depth = kwargs[kw]
                else:
                    cfg = kwargs[kw]
        _need_component(comp, "hal.stream() ")
        key = _int32(key)
        creating = depth is not None
        if creating:
            depth = _int32(depth)
        if cfg is not None and not isinstance(cfg, str):
            raise TypeError(f"hal.stream() argument {4 if creating else 3} "
                            f"must be str, not {_tname(cfg)}")
        name = _stream_name(key)
        if creating:
            if cfg is None:
                raise TypeError("hal.stream() needs cfg to create a stream")
            found = self._create(comp, name, depth, cfg)
        else:
            found = self._attach(name, cfg)
        setattr_ = object.__setattr__
        setattr_(self, "_s", found)
        setattr_(self, "_key", key & 0xFFFFFFFF)
        setattr_(self, "_creator", creating)
        setattr_(self, "_sampleno", 0)
        setattr_(self, "_types", list(found.types))

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(getattr(type(self), name, None), property):
            raise AttributeError("readonly attribute")
        raise AttributeError(f"'hal.stream' object has no attribute "
                             f"'{name}'")

    @staticmethod
    def _create(comp: component, name: str, depth: int, cfg: str) -> Any:
        comp._check_live()
        if depth < 1:
            raise _os_error(errno.EINVAL)
        try:
            return _need_instance().new_stream(name, depth, cfg,
                                               comp._c_comp)
        except ExistsError:
            print(f"stream: ERROR: a stream with key {name} exists",
                  file=sys.stderr)
            raise _os_error(errno.EEXIST) from None
        except HalError as exc:
            print(f"stream: ERROR: {exc}", file=sys.stderr)
            raise _os_error(errno.EINVAL) from None

    @staticmethod
    def _attach(name: str, cfg: Optional[str]) -> Any:
        hal = halsdk.Hal.current()
        if hal is None:
            raise RuntimeError(_NO_COMPONENT)
        try:
            found = hal.stream(name)
        except NotFoundError:
            raise _os_error(errno.EINVAL) from None
        if cfg is None:
            return found
        types = found.types
        if not cfg:
            print("stream: ERROR: empty cfg", file=sys.stderr)
            raise _os_error(errno.EINVAL)
        # as the reference: the letters given must match the first types
        for i, letter in enumerate(cfg):
            want = _LETTERS.get(letter.lower())
            if want is None:
                print(f"stream: ERROR: unknown type '{letter}', must be F, "
                      "B, S, U, L or K", file=sys.stderr)
                raise _os_error(errno.EINVAL)
            if i >= len(types) or types[i] != want:
                have = (_TYPE_NAMES[types[i]].lower() if i < len(types)
                        else "nothing")
                print(f"stream: ERROR: type mismatch: value {i} is {have}, "
                      f"cfg says {_TYPE_NAMES[want].lower()}",
                      file=sys.stderr)
                raise _os_error(errno.EINVAL)
        return found

    def _live(self) -> Any:
        """The core stream, or RuntimeError when its owner is gone."""
        if halsdk.Hal.current() is None or not self._s.exists:
            raise RuntimeError("the stream no longer exists (its "
                               "component was removed)")
        return self._s

    def write(self, *args: Any, **kwargs: Any) -> None:
        """Append one record, a tuple of one value per type (converted as
        pin values are); OSError ENOSPC (and one more overrun) when
        full."""
        if kwargs:
            raise TypeError("stream.write() takes no keyword arguments")
        if len(args) != 1:
            raise TypeError(f"hal.stream.write() takes exactly 1 argument "
                            f"({len(args)} given)")
        values = args[0]
        if not isinstance(values, tuple):
            raise TypeError(f"hal.stream.write() argument 1 must be tuple, "
                            f"not {_tname(values)}")
        types = self._types
        if len(values) < len(types):
            raise ValueError("Too few elements to unpack")
        if len(values) > len(types):
            raise ValueError("Too many elements to unpack")
        record = [_convert(t, v) for t, v in zip(types, values)]
        if not self._live().write(record):
            raise _os_error(errno.ENOSPC)

    def read(self, *args: Any, **kwargs: Any) -> Optional[tuple]:
        """The oldest record as a tuple, or None (and one more underrun)
        when the stream is empty."""
        if kwargs:
            raise TypeError("stream.read() takes no keyword arguments")
        if args:
            raise TypeError(f"stream.read() takes no arguments "
                            f"({len(args)} given)")
        got = self._live().read()
        if got is None:
            return None
        sampleno, values = got
        object.__setattr__(self, "_sampleno", sampleno + 1)
        return values

    @property
    def depth(self) -> int:
        """Records waiting to be read."""
        return self._live().depth

    @property
    def maxdepth(self) -> int:
        """The depth the stream was created with."""
        return self._live().maxdepth

    @property
    def element_types(self) -> bytes:
        """The cfg letters of the values, lowercase (``b'fbsu'``)."""
        return self._live().typestring.encode()

    @property
    def num_overruns(self) -> int:
        """Writes that found the stream full."""
        return self._live().overruns

    @property
    def num_underruns(self) -> int:
        """Reads that found the stream empty."""
        return self._live().underruns

    @property
    def readable(self) -> bool:
        """True if a record is waiting."""
        return self._live().depth > 0

    @property
    def writable(self) -> bool:
        """True if a record can be written."""
        return self._live().room > 0

    @property
    def sampleno(self) -> int:
        """The number of the last record this object read (records are
        numbered from 1 by the writer; 0 before the first read)."""
        return self._sampleno

    def __repr__(self) -> str:
        return (f"<stream 0x{self._key:x}"
                f"{' creator' if self._creator else ''}>")


class shm:  # noqa: N801 - the reference's name
    """A block of shared memory found by a key (an int).

    ``shm(comp, key, size)`` attaches to the block of that key, or creates
    it (``size`` zeroed bytes, owned by ``comp``).  :meth:`getbuffer`
    gives a writable memoryview of it (``struct.pack_into``,
    ``numpy.frombuffer``, ``view.cast("I")``, ...).
    """

    __slots__ = ("_key", "_addr", "_block", "_size", "_comp", "_id")
    _ids = 0

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        if kwargs or len(args) != 3:
            raise TypeError(f"function takes exactly 3 arguments "
                            f"({len(args)} given)")
        comp = _need_component(args[0], "")
        key = _int32(args[1])
        size = operator.index(args[2])
        hal = halsdk.Hal.current()
        if hal is None:
            raise RuntimeError(_NO_COMPONENT)
        name = _shm_name(key)
        try:
            addr, block = hal.shared_block(name)
        except NotFoundError:
            comp._check_live()
            if size < 1:
                raise error("Invalid argument") from None
            try:
                addr, block = hal.new_shared_block(name, size, comp._c_comp)
            except HalError as exc:
                print(f"shm: ERROR: {exc}", file=sys.stderr)
                raise error("Invalid argument") from None
        if not 0 < size <= block:
            raise error("Invalid argument")
        shm._ids += 1
        self._id = shm._ids
        self._key = key & 0xFFFFFFFF
        self._addr = addr
        self._block = block
        self._size = size
        self._comp = comp           # the block lives with its component

    def getbuffer(self) -> memoryview:
        """A writable memoryview of ``size`` bytes (format ``B``) of the
        block; it keeps this object (and so its component) alive."""
        raw = (ctypes.c_ubyte * self._size).from_address(self._addr)
        raw._shm = self             # type: ignore[attr-defined]
        return memoryview(raw).cast("B")

    def setsize(self, *args: Any) -> None:
        """Set the size of the views :meth:`getbuffer` gives (0 to the
        size of the block)."""
        if len(args) != 1:
            raise TypeError(f"function takes exactly 1 argument "
                            f"({len(args)} given)")
        size = args[0]
        if not isinstance(size, int):
            raise TypeError(f"argument 1 must be int, not {_tname(size)}")
        if not 0 <= size <= self._block:
            raise ValueError(f"size {size} is outside the block (0 to "
                             f"{self._block} bytes)")
        self._size = size

    def __repr__(self) -> str:
        return (f"<shared memory buffer key={self._key:08x} id={self._id} "
                f"size={self._size}>")


# ---------------------------------------------------------------- functions

def component_exists(name: str, /) -> bool:
    """True if a component of that name exists."""
    _need_str(name, 1)
    return _need_instance().find("component", name) is not None


def component_is_ready(name: str, /) -> bool:
    """True if a component of that name exists and is ready."""
    _need_str(name, 1)
    comp = _need_instance().find("component", name)
    return bool(comp is not None and comp.ready)


def connect(pin_name: str, signal_name: str, /) -> bool:
    """Link a pin to an existing signal.  As in LinuxCNC, returns False on
    success and True on failure (the error is printed to stderr)."""
    _need_str(pin_name, 1)
    _need_str(signal_name, 2)
    hal = _need_instance()
    try:
        hal.linkps(pin_name, signal_name)
    except HalError as exc:
        return _report(exc)
    return False


def disconnect(pin_name: str, /) -> bool:
    """Unlink a pin from its signal (no-op if unlinked).  False on
    success, True on failure."""
    _need_str(pin_name, 1)
    hal = _need_instance()
    try:
        hal.unlinkp(pin_name)
    except HalError as exc:
        return _report(exc)
    return False


def new_sig(signal_name: str, htype: int, /) -> bool:
    """Create a signal of a type (HAL_BIT, ...).  False on success, True
    on failure (e.g. a duplicate name)."""
    _need_str(signal_name, 1)
    htype = operator.index(htype)
    hal = _need_instance()
    if htype not in _TYPE_NAMES:
        raise RuntimeError("not a valid HAL signal type")
    try:
        hal.newsig(signal_name, htype)
    except HalError as exc:
        return _report(exc)
    return False


def set_p(name: str, value: str, /) -> bool:
    """Set a pin or param from a string, as ``halcmd setp``.  False on
    success, True if the string is not a valid value; raises
    RuntimeError for an unknown, output, linked or read-only item."""
    _need_str(name, 1)
    _need_str(value, 2)
    hal = _need_instance()
    try:
        hal.setp(name, value)
    except HalError as exc:
        if exc.rule == Rule.BAD_VALUE:
            return True
        raise RuntimeError(_SET_P_WORDS.get(exc.rule, str(exc))) from exc
    return False


# the reference module's words for a refused set_p
_SET_P_WORDS = {Rule.NOT_FOUND: "pin not found",
                Rule.WRITE_OUTPUT: "pin not writable",
                Rule.PIN_CONNECTED: "pin connected to signal",
                Rule.RO_PARAM: "param not writable"}


def get_value(name: str, /) -> Value:
    """The value of a pin, param or signal."""
    _need_str(name, 1)
    hal = _need_instance()
    for kind in ("pin", "param", "signal"):
        found = hal.find(kind, name)
        if found is not None:
            return found.value
    raise RuntimeError(f"Can't set value: pin / param {name} not found")


def pin_has_writer(name: str, /) -> bool:
    """True if the pin is linked to a signal that has an output pin."""
    _need_str(name, 1)
    pin = _need_instance().find("pin", name)
    if pin is None:
        raise NameError(f"Pin `{name}' does not exist")
    sig = pin.signal
    return bool(sig is not None and sig.writers > 0)


def _sorted(kind: str) -> list:
    """Records of every object of a kind, by name: a snapshot taken in
    one pass, which never fails while other processes load or unload
    components."""
    return _need_instance().snapshot(kind)


def get_info_pins() -> list[dict[str, Any]]:
    """Every pin: [{NAME, VALUE, DIRECTION, TYPE}], sorted by name."""
    _need_instance()
    return [{"NAME": p.name, "VALUE": p.value, "DIRECTION": p.direction,
             "TYPE": p.type} for p in _sorted("pin")]


def get_info_params() -> list[dict[str, Any]]:
    """Every param: [{NAME, DIRECTION, VALUE}], sorted by name."""
    _need_instance()
    return [{"NAME": p.name, "DIRECTION": p.direction, "VALUE": p.value}
            for p in _sorted("param")]


def get_info_signals() -> list[dict[str, Any]]:
    """Every signal: [{NAME, VALUE, DRIVER, TYPE}], sorted by name;
    DRIVER is the name of its output pin or None."""
    _need_instance()
    out = []
    for sig in _sorted("signal"):
        driver = None
        if sig.writers:
            driver = next((p.name for p in sig.pins
                           if p.direction == HAL_OUT), None)
        out.append({"NAME": sig.name, "VALUE": sig.value, "DRIVER": driver,
                    "TYPE": sig.type})
    return out


_msg_level = MSG_ERR        # used while no instance is attached


def get_msg_level() -> int:
    """The message level (MSG_NONE .. MSG_ALL) of the instance."""
    hal = halsdk.Hal.current()
    if hal is not None:
        return hal.msg_level
    return _msg_level


def set_msg_level(level: int, /) -> None:
    """Set the message level; values outside MSG_NONE .. MSG_ALL are
    clamped to that range."""
    global _msg_level
    level = min(max(operator.index(level), MSG_NONE), MSG_ALL)
    _msg_level = level
    hal = halsdk.Hal.current()
    if hal is not None:
        hal.msg_level = level
