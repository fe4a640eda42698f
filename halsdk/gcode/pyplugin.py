"""The ``[PYTHON]`` plugin of an INI file: Python code the interpreter calls.

A machine's INI file may name a Python script, ``[PYTHON]TOPLEVEL``, with
folders for its imports (``PATH_PREPEND``/``PATH_APPEND``, repeatable,
relative to the INI file's folder).  The script is run once, when the
interpreter is set up; the modules it imports under the names ``oword``
and ``remap`` (``import oword``, ``import remap``) hold:

* ``oword.NAME(self, *args)``: called by ``o<NAME> call [a] [b]`` (before
  an NGC subroutine of the same name is looked for); it returns None, a
  number (``#<_value>``) or a string (an error message that ends the
  program);
* ``remap.NAME(self, **words)``: the ``python=``, ``prolog=`` and
  ``epilog=`` procedures of ``REMAP=`` lines (see :mod:`.remap`).

``self`` is an :class:`InterpreterView`: ``self.params[...]`` reads and sets
parameters, ``self.execute("G1 X1")`` runs G-code, and a few attributes of
the interpreter's state have the reference's names.

Only the script the INI file names is run, and what it imports.  The
modules it imports from its own folders are kept apart: they are in
``sys.modules`` only while plugin code runs, so two machines in one
process may each have their own ``remap`` module, and the folders are on
``sys.path`` only then too.  The names ``interpreter`` and ``emccanon``
import small stand-ins (return codes, ``MESSAGE``), so plugins written for
the reference's embedded Python load.
"""

from __future__ import annotations

import contextlib
import os
import sys
import traceback
import types
from collections.abc import Iterator
from typing import Any, Callable, Optional

from .errors import GCodeError

#: The return codes of the reference's interpreter (its ``interpreter``
#: module): a procedure returns INTERP_OK (or None); INTERP_MIN_ERROR and
#: above are errors.
INTERP_OK = 0
INTERP_EXIT = 1
INTERP_EXECUTE_FINISH = 2
INTERP_ENDFILE = 3
INTERP_FILE_NOT_OPEN = 4
INTERP_ERROR = 5
INTERP_MIN_ERROR = 3


class PluginError(GCodeError):
    """A ``[PYTHON]`` plugin that cannot be loaded (names the INI file and
    line) or Python code that failed (names the G-code line and the last
    frame of the Python traceback)."""


class InterpreterException(Exception):
    """Raised by ``self.execute()`` for a G-code error (the reference's
    name); ``line_number``, ``line_text`` and ``error_message`` say what."""

    def __init__(self, line_number: int, line_text: str,
                 error_message: str) -> None:
        super().__init__(f"{line_number}: {line_text!r}: {error_message}")
        self.line_number = line_number
        self.line_text = line_text
        self.error_message = error_message


def last_frame(exc: BaseException) -> str:
    """``file:line in function`` of the innermost frame of ``exc``."""
    frames = traceback.extract_tb(exc.__traceback__)
    if not frames:
        return "?"
    last = frames[-1]
    return f"{last.filename}:{last.lineno} in {last.name}"


def python_failure(exc: BaseException, what: str, file: str, line: int,
                   column: int = 0) -> PluginError:
    """The error of Python code that raised ``exc`` while running G-code
    line ``file:line``."""
    if isinstance(exc, SyntaxError):
        detail = f"{type(exc).__name__}: {exc.msg}"
        frame = f"{exc.filename}:{exc.lineno}"
    else:
        detail = "".join(traceback.format_exception_only(type(exc), exc)
                         ).strip()
        frame = last_frame(exc)
    return PluginError(f"{what} raised {detail} (at {frame})", file, line,
                       column)


# -- the stand-in modules ----------------------------------------------------

#: The interpreter whose plugin code runs now (for ``emccanon``).
_current: list[Any] = []


def _stand_ins() -> dict[str, types.ModuleType]:
    interpreter = types.ModuleType("interpreter")
    interpreter.__doc__ = "halsdk's stand-in for the reference's module"
    for name in ("INTERP_OK", "INTERP_EXIT", "INTERP_EXECUTE_FINISH",
                 "INTERP_ENDFILE", "INTERP_FILE_NOT_OPEN", "INTERP_ERROR",
                 "INTERP_MIN_ERROR"):
        setattr(interpreter, name, globals()[name])
    interpreter.InterpreterException = InterpreterException  # type: ignore
    interpreter.throw_exceptions = 1    # type: ignore[attr-defined]
    emccanon = types.ModuleType("emccanon")
    emccanon.__doc__ = "halsdk's stand-in for the reference's module"

    def message(text: str) -> None:
        if _current:
            _current[-1].message(str(text))
    emccanon.MESSAGE = message          # type: ignore[attr-defined]
    return {"interpreter": interpreter, "emccanon": emccanon}


_STAND_INS = _stand_ins()


# -- the view of the interpreter given to Python -------------------------------

class ParamsView:
    """``self.params``: ``self.params[5220]``, ``self.params["name"]``
    (a local of the running procedure), ``self.params["_global"]``; an
    unknown name raises KeyError."""

    def __init__(self, params: Any) -> None:
        self._params = params

    def __getitem__(self, key: Any) -> float:
        try:
            return float(self._params.get(key))
        except GCodeError as exc:
            raise KeyError(exc.message) from None

    def __setitem__(self, key: Any, value: float) -> None:
        try:
            self._params.set(key, float(value))
        except GCodeError as exc:
            raise KeyError(exc.message) from None

    def __contains__(self, key: Any) -> bool:
        if isinstance(key, str):
            return bool(self._params.exists(key))
        try:
            self._params.get(key)
        except GCodeError:
            return False
        return True


class BlockView:
    """``self.blocks[level]``: the words of a block, as the reference's
    ``x_flag``/``x_number`` attributes, and its ``comment``."""

    def __init__(self, block: Any) -> None:
        self._block = block
        self.line_number = int(block.line)
        self.comment = " ".join(block.comments)
        self.text = block.text

    def __getattr__(self, name: str) -> Any:
        letter, _, kind = name.partition("_")
        if len(letter) == 1 and kind in ("flag", "number"):
            words = self._block.words
            if kind == "flag":
                return letter in words
            return float(words.get(letter, 0.0))
        raise AttributeError(f"block has no attribute {name!r}")


class InterpreterView:
    """What Python plugin code gets as ``self``: the interpreter, with the
    reference's names for what it offers."""

    #: 0: this interpreter is not the one of a task (the reference's
    #: ``self.task`` is 1 only in its milltask)
    task = 0
    debugmask = 0

    def __init__(self, interp: Any, runner: Callable[[str, str, int], None],
                 remapped: Callable[[], list[Any]] = list) -> None:
        self._interp = interp
        self._runner = runner
        self._remapped = remapped
        self.params = ParamsView(interp.params)

    # -- state -------------------------------------------------------------
    @property
    def blocks(self) -> list[BlockView]:
        """The block being executed (``blocks[0]``) and those of the
        remapped codes in progress (``blocks[self.remap_level]``: the
        one whose procedure runs now)."""
        line = self._interp.line_block
        found = [BlockView(line)] if line is not None else []
        return found + [BlockView(b) for b in self._remapped()]

    @property
    def remap_level(self) -> int:
        return len(self._remapped())

    @property
    def call_level(self) -> int:
        return int(self._interp.params.depth)

    @property
    def feed_rate(self) -> float:
        return float(self._interp.feed_value)

    @property
    def speed(self) -> list[float]:
        return [float(self._interp.speed)]

    @property
    def current_tool(self) -> int:
        return int(self._interp.current_tool)

    @property
    def selected_tool(self) -> int:
        return int(self._interp.selected_tool)

    @property
    def selected_pocket(self) -> int:
        return int(self._interp.selected_pocket)

    @property
    def return_value(self) -> float:
        return float(self._interp.params.get("_value")) \
            if self._interp.params.exists("_value") else 0.0

    @property
    def value_returned(self) -> int:
        return int(self._interp.params.get("_value_returned")) \
            if self._interp.params.exists("_value_returned") else 0

    @property
    def line(self) -> int:
        """The line of the G-code being executed."""
        return int(self._interp.line)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("current_") and len(name) == 9:
            axis = "xyzabcuvw".find(name[-1])
            if axis >= 0:
                # the program position in program units (#<_x> ...)
                return float(self._interp.params.get("_" + name[-1]))
        raise AttributeError(f"the interpreter seen from Python has no "
                             f"attribute {name!r} in halsdk")

    # -- actions -----------------------------------------------------------
    def execute(self, code: str, lineno: Optional[int] = None) -> int:
        """Run the G-code ``code`` (one or more lines) now; INTERP_OK, or
        an :class:`InterpreterException` for an error."""
        where = self._interp.line_block
        file = where.file if where is not None else "<python>"
        line = int(lineno) if lineno is not None else int(self._interp.line)
        try:
            self._runner(str(code), file, line)
        except PluginError:
            raise
        except GCodeError as exc:
            raise InterpreterException(exc.line, str(code), exc.message
                                       ) from None
        return INTERP_OK

    def message(self, text: str) -> None:
        """Show ``text`` as a (msg, ...) comment does."""
        self.execute(f"(MSG,{text.replace(')', '')})")


# -- the plugin ----------------------------------------------------------------

class Plugin:
    """The loaded ``[PYTHON]TOPLEVEL`` script of an INI file."""

    def __init__(self, toplevel: str, folders: list[str], where: str,
                 line: int) -> None:
        self.toplevel = toplevel
        self.folders = [os.path.abspath(f) for f in folders]
        self._where = (where, line)
        self._modules: dict[str, types.ModuleType] = {}
        self.namespace: dict[str, Any] = {"__name__": "toplevel",
                                          "__file__": toplevel}
        try:
            with open(toplevel, encoding="utf-8") as f:
                source = f.read()
        except (OSError, UnicodeDecodeError) as exc:
            raise PluginError(f"[PYTHON]TOPLEVEL: cannot read {toplevel}: "
                              f"{getattr(exc, 'strerror', None) or exc}",
                              where, line) from None
        try:
            code = compile(source, toplevel, "exec")
            with self.running():
                exec(code, self.namespace)
        except Exception as exc:
            raise python_failure(exc, f"[PYTHON]TOPLEVEL {toplevel}",
                                 where, line) from None

    @classmethod
    def from_ini(cls, ini: Any) -> Optional[Plugin]:
        """The plugin of an :class:`~halsdk.ini.IniFile`, or None when it
        has no ``[PYTHON]TOPLEVEL``."""
        name = ini.get("PYTHON", "TOPLEVEL")
        if not name:
            return None
        base = os.path.dirname(os.path.abspath(ini.path))
        folders = [os.path.join(base, p) for p in
                   ini.all("PYTHON", "PATH_PREPEND")]
        folders.append(base)
        folders += [os.path.join(base, p) for p in
                    ini.all("PYTHON", "PATH_APPEND")]
        return cls(os.path.join(base, name), folders, ini.path,
                   ini.line("PYTHON", "TOPLEVEL"))

    def _ours(self, module: Any) -> bool:
        path = getattr(module, "__file__", None)
        if not path:
            return False
        path = os.path.abspath(path)
        return any(path.startswith(folder + os.sep)
                   for folder in self.folders)

    @contextlib.contextmanager
    def running(self, interp: Any = None) -> Iterator[None]:
        """Plugin code runs in here: its folders on ``sys.path``, its
        modules and the stand-ins in ``sys.modules``; all taken away
        afterwards."""
        saved_path = list(sys.path)
        replaced: dict[str, Optional[types.ModuleType]] = {}
        for name, module in [*_STAND_INS.items(), *self._modules.items()]:
            replaced.setdefault(name, sys.modules.get(name))
            sys.modules[name] = module
        before = set(sys.modules)
        sys.path[:0] = [f for f in self.folders if f not in sys.path]
        if interp is not None:
            _current.append(interp)
        try:
            yield
        finally:
            if interp is not None:
                _current.pop()
            for name in set(sys.modules) - before:
                module = sys.modules[name]
                if self._ours(module):
                    self._modules[name] = module
                    del sys.modules[name]
            for name, old in replaced.items():
                if old is None:
                    sys.modules.pop(name, None)
                else:
                    sys.modules[name] = old
            sys.path[:] = saved_path

    def function(self, module: str, name: str) -> Optional[Callable[..., Any]]:
        """``module.name`` (``oword``, ``remap`` or ``namedparams``) if it
        is callable; never a ``__dunder__`` attribute of the module (such
        as ``__class__``)."""
        if name.startswith("__") and name.endswith("__"):
            return None
        mod = self.namespace.get(module)
        if not isinstance(mod, types.ModuleType):
            mod = self._modules.get(module)
        fn = getattr(mod, name, None) if mod is not None else None
        return fn if callable(fn) else None

    def init(self, view: InterpreterView) -> None:
        """Call the TOPLEVEL's ``__init__(self)`` if it has one."""
        fn = self.namespace.get("__init__")
        if callable(fn):
            file, line = self._where
            try:
                with self.running(view):
                    fn(view)
            except Exception as exc:
                raise python_failure(exc, "[PYTHON]TOPLEVEL __init__",
                                     file, line) from None
