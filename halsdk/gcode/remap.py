"""``REMAP=``: G, M, T, S and F codes defined by NGC or Python procedures.

An INI file's ``[RS274NGC]`` section may hold lines such as::

    REMAP=M400 modalgroup=10 argspec=Pq ngc=m400
    REMAP=G88.6 modalgroup=1 argspec=XYZp python=g886
    REMAP=M6 modalgroup=6 prolog=change_prolog ngc=change epilog=change_epilog

When a block holds a remapped code, the interpreter runs it at the place of
its modal group in the order of execution (M codes: group 5, 6, 7, 8, 9 or
10, default 10; G codes: group 1, with the motion; T, S and F at their
own place): what comes before in the order runs first, then the
procedure, then the rest of the block.

* ``argspec``: upper-case letters are words the block must have, lower
  case ones words it may have; they are taken out of the block (F, S and
  T keep their usual effect too) and passed as local named parameters
  (``#<p>``), or as ``#1``, ``#2`` ... in the order given after ``@``;
  ``n`` passes the line number, ``^`` asks for a spindle speed above 0,
  ``>`` for a feed above 0.
* ``ngc=NAME``: ``NAME.ngc`` on the subroutine path, called as ``o<NAME>
  call``; inside it (and in what it calls) the remapped code itself runs
  the built-in code.  ``#<_remap_level>`` is the nesting (at most 9).
* ``python=NAME``: ``remap.NAME(self, **words)`` of the ``[PYTHON]``
  plugin (:mod:`.pyplugin`); ``prolog=``/``epilog=`` are called around
  the NGC procedure, with its locals in scope.  A string returned is an
  error message.

A bad ``REMAP`` line is a :class:`RemapError` naming the INI file and
line; its message, and the warning for a G or M code with no
``modalgroup=`` (passed to ``warn``), are the reference's words, which
quote the line as ``LINE:REMAP = VALUE``.
"""

from __future__ import annotations

import inspect
import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Optional

from .block import Block, code_key
from .errors import GCodeError
from .modal import _G_OF, _M_OF
from .params import LOCAL_NUMBERED
from .pyplugin import (
    INTERP_EXECUTE_FINISH,
    INTERP_MIN_ERROR,
    INTERP_OK,
    InterpreterView,
    Plugin,
    PluginError,
    python_failure,
)

#: Remapped codes nested deeper than this are an error (the reference's
#: limit: its 10 levels count the line that started them).
MAX_REMAP_LEVEL = 9

_ARGSPEC_LETTERS = set("abcdefhijklmnpqrstuvwxyz")
_OPTIONS = ("modalgroup", "argspec", "ngc", "python", "py", "prolog",
            "epilog")
_M_GROUPS = (5, 6, 7, 8, 9, 10)

# The order of execution, as steps: where each part of a block runs.
_STEP_F, _STEP_S, _STEP_T = 4, 5, 6
_M_STEP = {5: 7, 6: 8, 7: 9, 8: 11, 9: 12, 10: 13, 4: 25}
_G_STEP = {5: 3, 2: 15, 6: 16, 7: 17, 8: 18, 12: 19, 13: 20, 3: 21,
           4: 21, 15: 21, 10: 22, 1: 24}
_STEP_MOTION = 24


class RemapError(GCodeError):
    """A bad ``REMAP=`` line (file: the INI file) or a remapped code that
    cannot run (file: the G-code program)."""


#: ``warn(warning)``: a warning about the INI file (a :class:`GCodeError`
#: that names the file and line, not raised)
Warn = Callable[[GCodeError], None]


def _quoted(text: str, line: int) -> str:
    """A REMAP line as the reference quotes it in its messages."""
    return f"{line}:REMAP = {text.strip()}"


@dataclass(frozen=True)
class Remap:
    """One ``REMAP=`` line."""

    #: ``m400``, ``g88.6``, ``t``, ``s`` or ``f``
    code: str
    modal_group: int
    argspec: str = ""
    ngc: Optional[str] = None
    python: Optional[str] = None
    prolog: Optional[str] = None
    epilog: Optional[str] = None
    file: str = ""
    line: int = 0
    #: the value of the REMAP line, as written
    text: str = ""

    @property
    def name(self) -> str:
        """``M400``, ``G88.6``, ``T``."""
        return self.code.upper()

    @property
    def step(self) -> int:
        """Its place in the order of execution."""
        if self.code[0] == "g":
            return _STEP_MOTION
        if self.code[0] == "m":
            return _M_STEP[self.modal_group]
        return {"f": _STEP_F, "s": _STEP_S, "t": _STEP_T}[self.code]

    @property
    def required(self) -> str:
        return "".join(c.lower() for c in self.argspec if c.isupper())

    @property
    def words(self) -> str:
        """Every word letter of the argspec, lower case, in order."""
        return "".join(c.lower() for c in self.argspec
                       if c.isalpha() and c.lower() != "n")


def parse_remap(text: str, file: str = "", line: int = 0,
                warn: Optional[Warn] = None) -> Remap:
    """Read the value of one ``REMAP=`` line; ``warn`` receives the
    reference's warning for a G or M code with no ``modalgroup=``."""
    def fail(message: str) -> RemapError:
        return RemapError(f"REMAP={text.strip()}: {message}", file, line)

    parts = text.split()
    if not parts:
        raise fail("no code given")
    code = parts[0].lower()
    options: dict[str, str] = {}
    for part in parts[1:]:
        key, eq, option = part.partition("=")
        key = key.lower()
        if not eq or key not in _OPTIONS:
            # (the reference warns and goes on; we refuse a typo)
            raise RemapError(f"unrecognized option '{part}' in  "
                             f"{_quoted(text, line)}", file, line)
        if key == "py":
            key = "python"
        if key in options:
            raise fail(f"{key}= given twice")
        options[key] = option
    letter, digits = code[0], code[1:]
    group: int
    if code in ("t", "s", "f"):
        group = 0
    elif letter in "gm" and digits:
        try:
            value = float(digits)
        except ValueError:
            raise fail(f"{parts[0]} is not a G, M, T, S or F code") from None
        if value < 0 or round(value, 1) != value or \
                (letter == "m" and value != int(value)):
            raise fail(f"{parts[0]} is not a G, M, T, S or F code")
        code = code_key(letter, value)
        default = 1 if letter == "g" else 10
        if "modalgroup" not in options and warn is not None:
            warn(GCodeError(f"warning: code '{parts[0]}' : no "
                            "modalgroup=<int> given, using default group "
                            f"{default} : {_quoted(text, line)}", file,
                            line))
        try:
            group = int(options.get("modalgroup", default))
        except ValueError:
            raise fail(f"modalgroup={options['modalgroup']} is not a "
                       "number") from None
        allowed = (1,) if letter == "g" else _M_GROUPS
        if group not in allowed:
            raise fail(f"modalgroup={group}: a remapped {letter.upper()} "
                       f"code may have modal group "
                       f"{', '.join(map(str, allowed))}")
        builtin = (_G_OF if letter == "g" else _M_OF).get(
            int(round(value * 10)))
        remappable = {0, 10, 600, 60, 610}   # M0 M1 M60 M6 M61
        if builtin is not None and not (letter == "m" and
                                        int(round(value * 10)) in
                                        remappable):
            raise fail(f"{parts[0].upper()} is a built-in code that "
                       "cannot be remapped (M0, M1, M6, M60, M61, T, S "
                       "and F can)")
    else:
        raise fail(f"{parts[0]} is not a G, M, T, S or F code")
    argspec = options.get("argspec", "")
    bad = [c for c in argspec
           if c not in "@^>" and c.lower() not in _ARGSPEC_LETTERS]
    if bad:                             # (the reference's words)
        raise RemapError(f"argspec: illegal word '{bad[0]}' - "
                         f"{_quoted(text, line)}", file, line)
    if argspec.count("@") > 1:
        raise fail(f"argspec={argspec}: '@' given twice")
    ngc, python = options.get("ngc"), options.get("python")
    if ngc and python:
        raise fail("ngc= and python= exclude each other")
    if not ngc and not python:
        raise RemapError(f"code '{parts[0]}' - no remap function given, "
                         "use either 'python=<function>' or "
                         f"'ngc=<basename>' : {_quoted(text, line)}",
                         file, line)
    if python and (options.get("prolog") or options.get("epilog")):
        raise fail("prolog= and epilog= go with ngc=, not python=")
    return Remap(code, group, argspec, ngc or None, python or None,
                 options.get("prolog") or None, options.get("epilog") or None,
                 file, line, text.strip())


@dataclass
class _Active:
    """A remapped code running."""

    remap: Remap
    block: Block


@dataclass
class Remapper:
    """The remapped codes of an INI file and the plugin they call; set as
    ``Interpreter.remap`` (see :func:`configure`)."""

    remaps: dict[str, Remap] = field(default_factory=dict)
    plugin: Optional[Plugin] = None
    active: list[_Active] = field(default_factory=list)
    view: Optional[InterpreterView] = None
    #: where ``ngc=`` procedures are (besides the running program's path)
    search_path: tuple[str, ...] = ()

    @classmethod
    def from_ini(cls, ini: Any, warn: Optional[Warn] = None) -> Remapper:
        """Read ``[RS274NGC]REMAP`` lines and load ``[PYTHON]TOPLEVEL``;
        ``warn`` receives the warnings of the lines (see
        :func:`parse_remap`)."""
        remapper = cls(plugin=Plugin.from_ini(ini))
        for value, number in ini.every.get(("RS274NGC", "REMAP"), []):
            # (a code remapped twice is refused before its warnings)
            warnings: list[GCodeError] = []
            remap = parse_remap(value, ini.path, number, warnings.append)
            if remap.code in remapper.remaps:
                raise RemapError(f"code '{value.split()[0]}' already "
                                 f"remapped : {_quoted(value, number)}",
                                 ini.path, number)
            for warning in warnings:
                if warn is not None:
                    warn(warning)
            remapper.remaps[remap.code] = remap
        for remap in remapper.remaps.values():
            for name in (remap.python, remap.prolog, remap.epilog):
                if name is None:
                    continue
                if remapper.plugin is None:
                    raise RemapError(f"REMAP {remap.name}: {name} is a "
                                     "Python procedure, but there is no "
                                     "[PYTHON]TOPLEVEL plugin", remap.file,
                                     remap.line)
                if remapper.plugin.function("remap", name) is None:
                    raise RemapError(f"REMAP {remap.name}: the plugin has "
                                     f"no function remap.{name}", remap.file,
                                     remap.line)
        return remapper

    # -- predefined parameters from Python -----------------------------
    def named_param(self, interp: Any, name: str) -> Optional[float]:
        """``#<_name>`` from the plugin's ``namedparams._name(self)``
        (None: it has none); a string returned is an error message."""
        plugin = self.plugin
        if plugin is None or not name.startswith("_"):
            return None
        fn = plugin.function("namedparams", name)
        if fn is None:
            return None
        view = self._view(interp)
        what = f"#<{name}>: Python namedparams.{name}()"
        try:
            with plugin.running(view):
                result = fn(view)
        except GCodeError:
            raise
        except Exception as exc:
            failure = python_failure(exc, what, "", 0)
            raise GCodeError(failure.message) from None
        if isinstance(result, str):
            raise GCodeError(result)
        if isinstance(result, (int, float)) and not isinstance(result, bool):
            return float(result)
        raise GCodeError(f"{what} returned {type(result).__name__}: it "
                         "returns a number or an error message")

    # -- what runs --------------------------------------------------------
    @property
    def level(self) -> int:
        """``#<_remap_level>``: remapped codes in progress."""
        return len(self.active)

    def _running(self, code: str) -> bool:
        return any(a.remap.code == code for a in self.active)

    def first(self, block: Block) -> Optional[Remap]:
        """The remapped code of ``block`` that runs first (None: none, or
        only codes whose own procedure is running, which do the built-in
        thing)."""
        found: list[Remap] = []
        remaps = self.remaps
        for value in block.m:
            r = remaps.get(code_key("m", value))
            if r is not None and not self._running(r.code):
                found.append(r)
        for value in block.g:
            r = remaps.get(code_key("g", value))
            if r is not None and not self._running(r.code):
                found.append(r)
        for letter in "fst":
            if letter in block.words:
                r = remaps.get(letter)
                if r is not None and not self._running(r.code):
                    found.append(r)
        return min(found, key=lambda r: r.step) if found else None

    def execute(self, interp: Any, block: Block, remap: Remap) -> None:
        """Run ``block`` whose code ``remap`` is remapped: the part before
        it in the order of execution, the procedure, the rest."""
        before, after = _split(block, remap)
        try:
            words = self._words(interp, block, remap)
        except GCodeError as exc:
            raise _as_call(exc, block, remap) from None
        if before is not None:
            interp.execute(before)
        if len(self.active) >= MAX_REMAP_LEVEL:
            # (deeper than MAX_REMAP_LEVEL, the reference's words)
            raise block.error("maximum nesting of remapped blocks "
                              "exceeded", remap.code)
        interp.line = block.line
        interp.line_block = block
        self.active.append(_Active(remap, block))
        try:
            if remap.python is not None:
                # (a call level of its own, as an NGC procedure's)
                depth = interp.params.depth
                interp.params.push_scope()
                try:
                    self._call(interp, remap, remap.python, words, block)
                finally:
                    _close_scopes(interp.params, depth)
            else:
                self._ngc(interp, block, remap, words)
        except GCodeError as exc:
            raise _as_call(exc, block, remap) from None
        finally:
            self.active.pop()
        if after is not None:
            interp.execute(after)

    def _words(self, interp: Any, block: Block, remap: Remap
               ) -> dict[str, float]:
        """The argspec words of ``block``, checked."""
        spec = remap.argspec
        missing = [c for c in remap.required if c not in block.words]
        # the reference's words: the words missing, then F>0, (a feed
        # above 0 needed) and S>0, (a spindle speed above 0)
        problem = (f" missing: {','.join(c.upper() for c in missing)}"
                   if missing else "")
        if ">" in spec and not interp.feed_value > 0:
            problem += "F>0,"
        if "^" in spec and not interp.speed > 0:
            problem += "S>0,"
        if problem:
            raise block.error(f"user-defined {remap.name}:{problem}",
                              remap.code)
        words = {c: float(block.words[c]) for c in remap.words
                 if c in block.words}
        if "n" in spec:
            words["n"] = float(block.line)
        return words

    def _view(self, interp: Any) -> InterpreterView:
        if self.view is None or self.view._interp is not interp:
            self.view = InterpreterView(
                interp, lambda text, file, line: run_text(interp, text, file,
                                                          line),
                lambda: [a.block for a in self.active])
        return self.view

    def _call(self, interp: Any, remap: Remap, name: str,
              words: dict[str, float], block: Block) -> None:
        """Call ``remap.<name>(self, **words)`` and check what it returns."""
        assert self.plugin is not None
        fn = self.plugin.function("remap", name)
        if fn is None:          # (checked when the INI file was read)
            raise block.error(f"no Python function remap.{name}",
                              remap.code)
        view = self._view(interp)
        what = f"{remap.name} remap: {name}()"
        try:
            with self.plugin.running(view):
                result = fn(view, **words)
                if inspect.isgenerator(result):
                    # yield INTERP_EXECUTE_FINISH: nothing is queued ahead
                    # here, so the generator goes on at once
                    for step in result:
                        if step not in (None, INTERP_OK,
                                        INTERP_EXECUTE_FINISH):
                            result = step
                            break
                    else:
                        result = None
        except (GCodeError, RemapError):
            raise
        except Exception as exc:
            raise python_failure(exc, what, block.file, block.line,
                                 block.column_of(remap.code)
                                 ) from None
        _check_result(result, what, block, remap.code)

    def _ngc(self, interp: Any, block: Block, remap: Remap,
             words: dict[str, float]) -> None:
        """Call the NGC procedure with the words as its locals, between
        the prolog and the epilog."""
        spec = remap.argspec
        positional: list[float] = []
        named = dict(words)
        if "@" in spec:
            order = [c.lower() for c in spec[spec.index("@") + 1:]
                     if c.isalpha()]
            positional = [words.get(c, 0.0) for c in order]
            named = {k: v for k, v in words.items() if k not in order}

        def prolog() -> None:
            params = interp.params
            for key, value in named.items():
                params.set(key, value)
            if remap.prolog is not None:
                self._call(interp, remap, remap.prolog, words, block)
            # the positional words after the prolog: #1.. the prolog set
            # do not reach the procedure (as in the reference)
            for index in LOCAL_NUMBERED:
                params.set(index, positional[index - 1]
                           if index <= len(positional) else 0.0)

        def epilog() -> None:
            if remap.epilog is not None:
                self._call(interp, remap, remap.epilog, words, block)

        assert remap.ngc is not None
        call_procedure(interp, remap.ngc, block, remap.code,
                       prolog, epilog)


def _as_call(exc: GCodeError, block: Block, remap: Remap) -> GCodeError:
    """An error of the remapped code of ``block`` itself (its words, its
    Python procedure) shows the line the reference shows for it, the
    call of the procedure (``O <m400> call ``); errors inside the
    procedure keep their own line."""
    if exc.file == block.file and exc.line == block.line and \
            exc.source is None:
        exc.source = f"O <{remap.ngc or remap.python}> call "
    return exc


def _check_result(result: Any, what: str, block: Block, key: str) -> None:
    if result is None or result in (INTERP_OK, INTERP_EXECUTE_FINISH):
        return
    if isinstance(result, str):
        raise block.error(result, key)
    if isinstance(result, (int, float)) and not isinstance(result, bool):
        if result >= INTERP_MIN_ERROR:
            raise block.error(f"{what} returned error {result:g}", key)
        return
    raise block.error(f"{what} returned {type(result).__name__}: it "
                      "returns INTERP_OK (or nothing) or an error message",
                      key)


def _step_of_g(value: float) -> int:
    tenths = int(round(value * 10))
    group = _G_OF.get(tenths)
    if group == 0:
        return 14 if tenths == 40 else (24 if tenths == 530 else 23)
    return _G_STEP.get(group, _STEP_MOTION) if group is not None \
        else _STEP_MOTION


def _step_of_m(value: float) -> int:
    group = _M_OF.get(int(round(value * 10)))
    return _M_STEP.get(group, 13) if group is not None else 13


def _split(block: Block, remap: Remap
           ) -> tuple[Optional[Block], Optional[Block]]:
    """The parts of ``block`` that run before and after the remapped code
    (None: nothing); the remapped code and its argspec words are out."""
    step = remap.step
    own = remap.code
    consumed = set(remap.words) - set("fst")
    if own in ("f", "s", "t"):
        consumed.add(own)
    before_g = [g for g in block.g
                if code_key("g", g) != own and _step_of_g(g) < step]
    after_g = [g for g in block.g
               if code_key("g", g) != own and _step_of_g(g) > step]
    before_m = [m for m in block.m
                if code_key("m", m) != own and _step_of_m(m) < step]
    after_m = [m for m in block.m
               if code_key("m", m) != own and _step_of_m(m) > step]
    word_step = {"f": _STEP_F, "s": _STEP_S, "t": _STEP_T}
    before_w: dict[str, float] = {}
    after_w: dict[str, float] = {}
    # the other words go with the codes after, if any, else with those
    # before; with no other code, with the (modal) motion
    others_after = bool(after_g or after_m) or (
        not (before_g or before_m) and step < _STEP_MOTION)
    for letter, value in block.words.items():
        if letter in consumed:
            continue
        at = word_step.get(letter)
        if at is None:
            (after_w if others_after else before_w)[letter] = value
        elif at < step:
            before_w[letter] = value
        else:
            after_w[letter] = value
    first = replace(block, g=before_g, m=before_m, words=before_w,
                    columns=dict(block.columns), comments=list(block.comments))
    second = replace(block, text="", g=after_g, m=after_m, words=after_w,
                     columns=dict(block.columns), comments=[], message=None)
    first_used = bool(before_g or before_m or before_w or block.comments
                      or block.message is not None
                      or _has_comment(block.text))
    return (first if first_used else None,
            second if (after_g or after_m or after_w) else None)


def _has_comment(text: str) -> bool:
    return "(" in text or ";" in text


# -- running G-code from inside a remap ------------------------------------------

def _child(interp: Any, text: str, file: str) -> Any:
    """A program of ``text`` run inside the one ``interp`` runs now."""
    from .program import Program
    parent = interp.program
    search = [*getattr(parent, "search_path", ())]
    remapper = getattr(interp, "remap", None)
    if remapper is not None:
        search += [d for d in remapper.search_path if d not in search]
    child = Program(text, file, interp.params, search,
                    max_iterations=getattr(parent, "max_iterations",
                                           1_000_000),
                    max_idle_time=getattr(parent, "max_idle_time", 5.0))
    if parent is not None:
        child.share_files(parent)
    return child


def _close_scopes(params: Any, depth: int) -> None:
    """Close the parameter scopes above ``depth`` (those of calls an
    error left), with the method of the class (not a remap's hook)."""
    while params.depth > depth:
        type(params).pop_scope(params)


def _drive(interp: Any, child: Any) -> None:
    """Execute the blocks of ``child`` with ``interp`` (as the program it
    runs, for the call level), then give it back its own."""
    parent = interp.program
    depth = interp.params.depth
    interp.program = child
    try:
        for sub_block in child.subroutine_blocks():
            interp.execute(sub_block)
            if interp.ended:
                break
    except BaseException:
        _close_scopes(interp.params, depth)
        raise
    finally:
        interp.program = parent


def run_text(interp: Any, text: str, file: str, line: int) -> None:
    """``self.execute(text)`` of Python code: run the G-code ``text``."""
    label = f"<python execute at {file}:{line}>"
    _drive(interp, _child(interp, text, label))


def call_procedure(interp: Any, name: str, block: Block, key: str,
                   prolog: Callable[[], None], epilog: Callable[[], None]
                   ) -> None:
    """``o<name> call`` from ``block``, with ``prolog()`` run once its
    scope is open and ``epilog()`` once it has returned, before the scope
    closes."""
    label = f"<{block.file}:{block.line} remap>"
    child = _child(interp, f"o<{name}> call", label)
    params = interp.params
    depth = params.depth
    # the methods of the class (an outer remap's hooks are put back after)
    plain_push = type(params).push_scope.__get__(params)
    plain_pop = type(params).pop_scope.__get__(params)
    saved = {k: params.__dict__.get(k) for k in ("push_scope", "pop_scope")}
    held = [False]

    def push(args: Optional[list[float]] = None) -> None:
        plain_push(args)
        if params.depth == depth + 1 and not held[0]:
            if saved["push_scope"] is None:
                del params.push_scope   # back to the method
            else:
                params.push_scope = saved["push_scope"]
            prolog()

    def pop() -> None:
        if params.depth == depth + 1 and not held[0]:
            held[0] = True              # closed after the epilog
            return
        plain_pop()

    params.push_scope = push
    params.pop_scope = pop
    try:
        _drive(interp, child)
        if held[0]:
            epilog()
    except GCodeError as exc:
        if exc.file == label:   # the call itself: unknown procedure ...
            raise block.error(f"{key.upper()}: {exc.message}",
                              key) from None
        raise
    finally:
        for k, hook in saved.items():
            if hook is None:
                params.__dict__.pop(k, None)
            else:
                params.__dict__[k] = hook
        _close_scopes(params, depth)


def configure(interp: Any, ini: Any, search_path: Sequence[str] = (),
              warn: Optional[Warn] = None) -> Optional[Remapper]:
    """Give ``interp`` the remapped codes and the Python plugin of the
    :class:`~halsdk.ini.IniFile` ``ini`` (None when it has neither); the
    ``ngc=`` procedures must be files on ``search_path``.  ``warn``
    receives the warnings about the REMAP lines (the reference prints
    them; default: none)."""
    remapper = Remapper.from_ini(ini, warn)
    remapper.search_path = tuple(search_path)
    for remap in remapper.remaps.values():
        if remap.ngc is not None and not any(
                os.path.isfile(os.path.join(d, remap.ngc + ".ngc"))
                for d in search_path):
            # (the reference's two lines; the path searched was
            # search_path)
            raise RemapError(f"INTERP_REMAP: NGC file not found: "
                             f"ngc={remap.ngc}\nREMAP INI Line:"
                             f"{remap.line} = {remap.text}",
                             remap.file, remap.line)
    if not remapper.remaps and remapper.plugin is None:
        interp.remap = None
        return None
    interp.remap = remapper
    if remapper.plugin is not None:
        remapper.plugin.init(remapper._view(interp))
    return remapper


def python_sub(interp: Any, name: str
               ) -> Optional[Callable[[list[float], str, int, int],
                                      Optional[float]]]:
    """The ``oword.<name>`` of ``interp``'s plugin as a subroutine of
    ``o<name> call``, or None."""
    remapper = getattr(interp, "remap", None)
    if remapper is None or remapper.plugin is None:
        return None
    plugin = remapper.plugin
    fn = plugin.function("oword", name)
    if fn is None:
        return None

    def call(args: list[float], file: str, line: int, column: int
             ) -> Optional[float]:
        view = remapper._view(interp)
        what = f"o<{name}> call: Python oword.{name}()"
        try:
            with plugin.running(view):
                result = fn(view, *args)
        except GCodeError:
            raise
        except Exception as exc:
            raise python_failure(exc, what, file, line, column) from None
        if result is None:
            return None
        if isinstance(result, str):     # (the reference's words)
            raise GCodeError(f"pycall(oword.{name}) failed", file, line,
                             column)
        if isinstance(result, (int, float)) and not isinstance(result, bool):
            return float(result)
        raise GCodeError(f"{what} returned {type(result).__name__}: it "
                         "returns nothing, a number or an error message",
                         file, line, column)
    return call


def py_comment(interp: Any, code: str, block: Block) -> None:
    """Run the Python statement(s) ``code`` of a ``;py,`` line or a
    ``(py,...)`` comment in the namespace of ``interp``'s ``[PYTHON]
    TOPLEVEL`` script (its globals: what it defines is seen, what the
    statement assigns stays), as the reference does.  Without a plugin
    it is an error (the reference runs it in a namespace of its own)."""
    remapper = getattr(interp, "remap", None)
    if remapper is None or remapper.plugin is None:
        raise block.error("a ;py, or (py,...) comment needs the [PYTHON] "
                          "plugin of an INI file (TOPLEVEL=)")
    plugin = remapper.plugin
    what = f"py comment {code.strip()!r}"
    try:
        compiled = compile(code, "<py comment>", "exec")
        with plugin.running(remapper._view(interp)):
            exec(compiled, plugin.namespace)
    except GCodeError:
        raise
    except Exception as exc:
        raise python_failure(exc, what, block.file, block.line, 1) from None


__all__ = ["MAX_REMAP_LEVEL", "Remap", "RemapError", "Remapper",
           "configure", "parse_remap", "py_comment", "python_sub",
           "PluginError"]
