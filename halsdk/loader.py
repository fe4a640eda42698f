"""Finding and loading component modules (``loadrt``).

A component module is a Python module (normally a compiled extension) that
defines:

``modparams``
    optional; a mapping of parameter name to ``(type, default, doc)``;
    ``type`` is ``int``, ``float``, ``str``, ``[int]`` or ``[str]`` (a
    comma-separated list on a load line), or one of the RTAPI kind letters
    ``i l s I L S``.
``setup(**params)``
    creates the component(s): calls ``hal_init``, makes pins, params and
    functions, calls ``hal_ready``.  Raises (or, for C modules, returns
    non-zero from ``rtapi_app_main``) on failure.
``cleanup()``
    optional; releases what ``setup`` took.  Components it leaves behind
    are removed by the loader.
``new_instance(name, **params)`` / ``delete_instance(name)``
    optional; support for ``newinst``/``delinst``.

Search order for ``loadrt NAME``: the folders of ``$HALSDK_PATH``, the
user folder that ``halcompile --install`` writes to
(:func:`user_component_dir`), the shipped ``halsdk.components`` and
``halsdk.drivers`` packages, then the ``halsdk.components`` entry-point
group of installed distributions.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import os
import re
import sys
from types import ModuleType
from typing import Any, Optional

from halsdk.core import _core
from halsdk.errors import (
    ConflictError,
    ExistsError,
    HalError,
    InvalidError,
    LoadError,
    NotFoundError,
)

_MODULE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_KINDS = {int: "i", float: "f", str: "s"}


def user_component_dir() -> str:
    """Folder of components installed by ``halcompile --install``."""
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(
        os.path.expanduser("~"), ".local", "share")
    return os.path.join(base, "halsdk", "components")


def search_path() -> list[str]:
    dirs = [d for d in os.environ.get("HALSDK_PATH", "").split(os.pathsep)
            if d]
    dirs.append(user_component_dir())
    return dirs


def _find_file(folder: str, name: str) -> Optional[str]:
    for suffix in importlib.machinery.EXTENSION_SUFFIXES + [".py"]:
        path = os.path.join(folder, name + suffix)
        if os.path.isfile(path):
            return path
    return None


_imported: dict[str, int] = {}     # file -> times imported in this process


def _import_file(name: str, path: str,
                 package: Optional[str] = None) -> ModuleType:
    """Import a component module from a file.

    A compiled module is mapped once per file by the dynamic loader, so a
    second load would share the C static variables of the first.  As the
    reference loads a module afresh each time, every load after the first
    maps a private copy of the file: its statics start from their initial
    values.  ``package``: the package the module belongs to (a shipped
    one), whose siblings it imports relatively.
    """
    # imported here, not at start-up: halcmd and halrun start faster
    import importlib.util
    import shutil
    import tempfile
    n = _imported.get(path, 0)
    _imported[path] = n + 1
    qual = f"halsdk._loaded.{name}"
    source, tmpdir = path, None
    if n and not path.endswith(".py"):
        tmpdir = tempfile.mkdtemp(prefix="halsdk-load-")
        source = os.path.join(tmpdir, os.path.basename(path))
        shutil.copy2(path, source)
        qual = f"halsdk._loaded_{n}.{name}"
    try:
        spec = importlib.util.spec_from_file_location(qual, source)
        if spec is None or spec.loader is None:
            raise LoadError(f"cannot load component '{name}' from {path}")
        try:
            # a compiled module is mapped here: a symbol it calls that
            # nothing provides (an API halsdk lacks) fails now, by name
            module = importlib.util.module_from_spec(spec)
            if package is not None:
                module.__package__ = package
            spec.loader.exec_module(module)
        except Exception as exc:
            raise LoadError(f"component '{name}' ({path}) failed to "
                            f"import: {exc}") from exc
    finally:
        if tmpdir:                  # mapped now: the file can go
            shutil.rmtree(tmpdir, ignore_errors=True)
    sys.modules[qual] = module
    return module


#: the module parameter that carries the command line of a userspace
#: program built by halcompile (its launcher sets it; loadrt refuses it)
USER_ARGV_PARAM = "halsdk_argv"


def import_component(name: str) -> ModuleType:
    """Import the module of component ``name`` by the search order."""
    import importlib.util
    if not _MODULE_NAME.match(name):
        raise InvalidError(f"'{name}' is not a component module name")
    for folder in search_path():
        path = _find_file(folder, name)
        if path:
            return _import_file(name, path)
    for package in ("halsdk.components", "halsdk.drivers"):
        qual = f"{package}.{name}"
        try:
            spec = importlib.util.find_spec(qual)
        except ModuleNotFoundError:
            continue
        if spec is None:
            continue
        origin = spec.origin or ""
        if origin.endswith(tuple(importlib.machinery.EXTENSION_SUFFIXES)):
            # compiled: each load gets fresh statics, as from a folder
            return _import_file(name, origin, package)
        try:
            return importlib.import_module(qual)
        except Exception as exc:
            raise LoadError(f"component '{name}' failed to import: "
                            f"{exc}") from exc
    from importlib.metadata import entry_points
    for ep in entry_points(group="halsdk.components"):
        if ep.name == name:
            try:
                return ep.load()
            except Exception as exc:
                raise LoadError(f"component '{name}' (entry point "
                                f"{ep.value}) failed to import: "
                                f"{exc}") from exc
    raise NotFoundError(
        f"component module '{name}' not found (searched HALSDK_PATH, "
        f"{user_component_dir()}, halsdk.components, halsdk.drivers and "
        "the 'halsdk.components' entry points)")


# ---------------------------------------------------------------- params

def _spec_kind(spec_type: Any) -> str:
    if isinstance(spec_type, str) and spec_type in "ilsfILSF":
        return spec_type
    if isinstance(spec_type, type) and spec_type in _KINDS:
        return _KINDS[spec_type]
    if isinstance(spec_type, list) and len(spec_type) == 1 and \
            spec_type[0] in _KINDS:
        return _KINDS[spec_type[0]].upper()
    raise LoadError(f"bad modparam type {spec_type!r}")


def _convert(comp: str, pname: str, kind: str, raw: Any) -> Any:
    if kind.isupper():
        if isinstance(raw, str):
            parts = raw.split(",")
            if kind in "IL":        # as the reference reads 'cfg=3,,5'
                parts = [p if p.strip() else "0" for p in parts]
        elif isinstance(raw, (list, tuple)):
            parts = list(raw)
        else:
            parts = [raw]
        return [_convert(comp, pname, kind.lower(), p) for p in parts]
    if kind == "s":
        if isinstance(raw, (list, tuple)):     # names=["a", "b"]
            return ",".join(map(str, raw))
        return str(raw)
    try:
        if kind == "f":
            return float(raw)
        if isinstance(raw, str):
            return _core.c_integer(raw)
        if isinstance(raw, bool) or not isinstance(raw, int):
            raise ValueError
        return raw
    except ValueError:
        what = "a number" if kind == "f" else "an integer"
        raise InvalidError(f"{comp}: parameter {pname}={raw!r} is not "
                           f"{what}") from None


def split_modparams(name: str, text: str) -> list[str]:
    """The ``name=value`` items of one load-line word, as LinuxCNC's
    insmod reads them: blanks separate items except inside double quotes,
    and every double quote is removed (``config="b2b,f2f"`` is
    ``config=b2b,f2f``, ``names="x y,z"`` names ``x y`` and ``z``).
    Single quotes are ordinary characters, as in the reference."""
    items: list[str] = []
    cur: list[str] = []
    started = quoted = False
    for ch in text:
        if ch == '"':
            quoted = not quoted
            started = True
        elif ch.isspace() and not quoted:
            if started:
                items.append("".join(cur))
            cur, started = [], False
        else:
            cur.append(ch)
            started = True
    if quoted:
        raise InvalidError(f"{name}: unterminated quoted string in "
                           f"'{text}'")
    if started:
        items.append("".join(cur))
    return items


def _quote_item(item: str) -> str:
    """An item as a load line writes it (``key="a b"`` when it has a
    blank), so that :func:`split_modparams` reads it back."""
    key, sep, value = item.partition("=")
    if any(ch.isspace() for ch in item):
        return f'{key}{sep}"{value}"' if sep else f'"{item}"'
    return item


def parse_modparams(name: str, module: object, args: tuple,
                    kwargs: dict) -> dict:
    """Merge ``key=value`` words and keyword arguments, typed by the
    ``modparams`` of ``module`` (a component module, or any object with
    that attribute).  Words are read by :func:`split_modparams`."""
    spec = getattr(module, "modparams", None) or {}
    given: dict[str, Any] = {}
    for word in args:
        for item in split_modparams(name, str(word)):
            key, sep, value = item.partition("=")
            if not sep or not key:
                raise InvalidError(f"{name}: '{item}' is not name=value")
            given[key] = value
    given.update(kwargs)
    out = {}
    for key, raw in given.items():
        if key not in spec:
            known = ", ".join(sorted(spec)) or "none"
            raise InvalidError(f"{name}: Unknown parameter `{key}={raw}' "
                               f"(its parameters: {known})")
        out[key] = _convert(name, key, _spec_kind(spec[key][0]), raw)
    return out


# ---------------------------------------------------------------- registry

class Loaded:
    """A module this host loaded: its components and its load line's
    parameters (as saved).  A plain class, not a dataclass: importing
    dataclasses would slow the start of every halrun."""

    __hash__ = None     # type: ignore[assignment]  # mutable, as before

    def __init__(self, name: str, module: ModuleType,
                 comp_ids: Optional[list[int]] = None,
                 args: str = "") -> None:
        self.name = name
        self.module = module
        self.comp_ids: list[int] = [] if comp_ids is None else comp_ids
        self.args = args

    def _key(self) -> tuple:
        return (self.name, self.module, self.comp_ids, self.args)

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        assert isinstance(other, Loaded)
        return self._key() == other._key()

    def __repr__(self) -> str:
        return (f"Loaded(name={self.name!r}, module={self.module!r}, "
                f"comp_ids={self.comp_ids!r}, args={self.args!r})")


class Registry:
    """The modules this host loaded, and which components each made."""

    def __init__(self) -> None:
        self.modules: dict[str, Loaded] = {}

    def _own_comp_ids(self) -> set[int]:
        """Components of this process, except those of threads (a module
        that creates threads does not own them)."""
        pid = os.getpid()
        threads = {"__" + t.name for t in _core.items("thread")}
        return {c.id for c in _core.items("component")
                if c.pid == pid and c.name not in threads}

    def load(self, name: str, *args: Any, **kwargs: Any) -> list[str]:
        if name in self.modules:
            raise ExistsError(f"module '{name}' is already loaded")
        if _core.get_lock() & 1:
            raise HalError(f"cannot load '{name}': HAL is locked against "
                           "loading")
        module = import_component(name)
        if not callable(getattr(module, "setup", None)):
            raise LoadError(f"module '{name}' has no setup(): it is not a "
                            "halsdk component module")
        if USER_ARGV_PARAM in getattr(module, "modparams", {}):
            raise LoadError(f"{name}: this is a userspace component: start "
                            f"it with 'loadusr {name}'")
        params = parse_modparams(name, module, args, kwargs)
        before = self._own_comp_ids()
        _core.set_loading_rt(True)
        try:
            module.setup(**params)
            error = None
        except Exception as exc:
            error = exc
        finally:
            _core.set_loading_rt(False)
        new = sorted(self._own_comp_ids() - before)
        if error is None:
            unready = [_core.comp_by_id(i).name for i in new
                       if not _core.comp_by_id(i).ready]
            if unready:
                error = LoadError(f"{name}: component(s) "
                                  f"{', '.join(unready)} did not call "
                                  "hal_ready()")
        if error is not None:
            self._undo(module, new)
            if isinstance(error, HalError):
                text = str(error)
                if not text.startswith(f"{name}:"):
                    text = f"{name}: {text}"
                again = type(error)(text)
                if hasattr(error, "status"):
                    again.status = error.status     # type: ignore[attr-defined]
                raise again from error
            if isinstance(error, ValueError):      # a bad parameter value
                raise InvalidError(f"{name}: {error}") from error
            raise LoadError(f"{name}: setup failed: {error}") from error
        # saved as written (quotes kept), as the reference's save does
        words = [str(a) for a in args]
        words += [_quote_item(f"{k}={v}") for k, v in kwargs.items()]
        self.modules[name] = Loaded(name, module, new,
                                    "".join(w + " " for w in words))
        return [_core.comp_by_id(i).name for i in new]

    def _undo(self, module: ModuleType, comp_ids: list[int]) -> None:
        cleanup = getattr(module, "cleanup", None)
        if callable(cleanup):
            try:
                cleanup()
            except Exception:
                pass
        for cid in comp_ids:
            if _core.comp_by_id(cid) is not None:
                _core.comp_exit(cid)

    def unload(self, name: str) -> None:
        loaded = self.modules.get(name)
        if loaded is None:
            raise NotFoundError(f"module '{name}' is not loaded")
        user = _core.symbol_user(name)
        if user is not None and user in self.modules:
            raise ConflictError(f"{name}: module '{user}' uses it; unload "
                                f"'{user}' first")
        del self.modules[name]
        self._undo(loaded.module, loaded.comp_ids)

    def unload_all(self) -> None:
        for name in reversed(list(self.modules)):
            self.unload(name)

    def load_args(self) -> dict[str, str]:
        """Component name -> the parameters of the load that made it."""
        out = {}
        for loaded in self.modules.values():
            for cid in loaded.comp_ids:
                comp = _core.comp_by_id(cid)
                if comp is not None:
                    out[comp.name] = loaded.args
        return out

    def module_of_comp(self, comp_name: str) -> Optional[Loaded]:
        comp = _core.find("component", comp_name)
        if comp is None:
            return None
        for loaded in self.modules.values():
            if comp.id in loaded.comp_ids:
                return loaded
        return None
