"""The HAL command executor shared by halrun, halcmd and Python.

:class:`Executor` runs one command (a list of words) or a whole file and
prints what the reference halcmd prints: results to ``out``, errors to
``err`` as ``file:line: message`` (no prefix on the command line).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from collections.abc import Iterable
from typing import Callable, Optional

from halsdk.core import _core
from halsdk.errors import HalError
from halsdk.halcmd.helptext import HELP
from halsdk.halcmd.lexer import (
    IniFile,
    SubstitutionError,
    logical_lines,
    strip_comment,
    tokenize,
)
from halsdk.halcmd.save import Saver, status
from halsdk.halcmd.show import Shower, type_name, value_text

Out = Callable[[str], None]

# lock bits of the core (same values as the reference)
LOCK_LOAD, LOCK_CONFIG, LOCK_PARAMS, LOCK_RUN = 1, 2, 4, 8
LOCK_WORDS = {"all": 255, "tune": LOCK_LOAD | LOCK_CONFIG, "none": 0}
ARROWS = ("=>", "<=", "<=>")
SIG_TYPES = {"bit": _core.BIT, "float": _core.FLOAT, "s32": _core.S32,
             "u32": _core.U32, "s64": _core.S64, "u64": _core.U64}
_TYPE_WORD = {_core.BIT: "bit", _core.FLOAT: "float", _core.S32: "S32",
              _core.U32: "U32", _core.S64: "S64", _core.U64: "U64"}
_FLOAT = re.compile(r"\s*[-+]?(\d+\.?\d*([eE][-+]?\d+)?|\.\d+([eE][-+]?\d+)?"
                    r"|inf|infinity|nan)\s*$", re.IGNORECASE)
_HEX_FLOAT = re.compile(r"\s*[-+]?0[xX][0-9a-fA-F]*\.?[0-9a-fA-F]*"
                        r"([pP][-+]?\d+)?\s*$")
_INT = re.compile(r"\s*([-+]?)(0[xX][0-9a-fA-F]+|0[0-7]*|[1-9]\d*)$")

# name: (least, most) argument counts (most None: any number)
ARG_COUNTS: dict[str, tuple[int, Optional[int]]] = {
    "addf": (2, None), "alias": (3, 3), "delf": (0, 2), "delsig": (1, 1),
    "echo": (0, 0), "unecho": (0, 0), "getp": (1, 1), "gets": (1, 1),
    "linkpp": (2, 2), "linkps": (2, 2), "linksp": (2, 2), "list": (1, None),
    "loadrt": (1, None), "lock": (0, 1), "unlock": (0, 1), "net": (1, None),
    "newsig": (2, 2), "ptype": (1, 1), "stype": (1, 1), "setp": (2, 2),
    "sets": (2, 2), "show": (0, None), "source": (1, 1), "start": (0, 0),
    "stop": (0, 0), "unalias": (2, 2), "unlinkp": (1, 1),
    "unloadrt": (1, 1), "unload": (1, 1), "newinst": (2, None),
    "delinst": (1, 1), "quit": (0, None), "exit": (0, None),
    "loadusr": (0, None), "waitusr": (1, 1), "unloadusr": (1, 1),
    "save": (0, 2), "status": (0, 1), "help": (0, 1), "debug": (1, 1),
    "print": (0, 1), "setexact_for_test_suite_only": (0, 0),
}
# longest name the reference HAL accepts (its HAL_NAME_LEN)
REFERENCE_NAME_LEN = 47
# kinds of objects whose new names are reported to Executor.created()
_CREATED_KINDS = ("component", "instance", "pin", "param", "function",
                  "thread")
# commands whose arrows are dropped before counting arguments
_DROP_ARROWS = ("linkps", "linksp", "linkpp")


class CommandError(Exception):
    """A failed command: ``lines`` are printed as they are, then each of
    ``messages`` with the ``file:line:`` prefix (either may be empty)."""

    def __init__(self, *messages: str, lines: Iterable[str] = ()):
        super().__init__(*messages)
        self.messages = [m for m in messages if m]
        self.lines = list(lines)


def hal_error(text: str, *messages: str) -> CommandError:
    """An error the reference reports from its HAL library first."""
    return CommandError(*messages, lines=[f"HAL: ERROR: {text}"])


def find(kind: str, name: str):
    """A pin, param or signal by name (pins and params also by the name
    they had before an alias: the core looks those up too)."""
    return _core.find(kind, name)


def _program_path(prog: str) -> str:
    """A program for loadusr: on PATH, else a launcher that halcompile
    put in a HALSDK_PATH folder or the user component folder."""
    if os.sep in prog or shutil.which(prog) is not None:
        return prog
    from halsdk.loader import search_path
    for folder in search_path():
        path = os.path.join(folder, prog)
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    return prog


class Quit(Exception):
    """``quit``/``exit``: stop reading commands."""


def parse_value(t: int, text: str):
    """Convert a word as the reference does (C strtol/strtod rules)."""
    if t == _core.BIT:
        if text == "1" or text.lower() == "true":
            return True
        if text == "0" or text.lower() == "false":
            return False
        raise ValueError
    if t == _core.FLOAT:
        if _FLOAT.match(text):
            return float(text)
        if not _HEX_FLOAT.match(text):
            raise ValueError
        return float.fromhex(text)
    m = _INT.match(text)
    if m is None:
        raise ValueError
    v = int(m.group(2), 0) if not re.fullmatch(r"0[0-7]+", m.group(2)) \
        else int(m.group(2), 8)
    if m.group(1) == "-":
        v = -v
    if t in (_core.S32, _core.S64):
        v = max(-2**63, min(2**63 - 1, v))      # strtol saturates
        bits = 32 if t == _core.S32 else 64
        v &= (1 << bits) - 1                     # then C truncates
        return v - (1 << bits) if v >> (bits - 1) else v
    if abs(v) >= 2**64:
        v = 2**64 - 1                            # strtoul saturates
    return v & (0xFFFFFFFF if t == _core.U32 else 2**64 - 1)


class Executor:
    """Runs HAL commands against an instance.

    :param hal: a :class:`halsdk.Hal` (host or attached).
    :param out: writes normal output (default: stdout, flushed).
    :param err: writes error lines (default: stderr).
    :param keep_going: ``-k``: continue after a failed command.
    :param script: ``-s``: script-friendly ``show`` formats.
    :param verbose: 0 quiet (``-Q``: nothing at all is -1), 1 ``-v``.
    :param ini: INI file for ``[SECTION]KEY`` substitution.
    :param echo: start with echo on (``-e``).
    :param warn_long_names: print a warning when a command creates a name
        longer than the reference's 47 characters (never with ``-Q``).
    :param workdir: the folder in which relative paths of ``source`` and
        ``loadusr`` programs are taken (default: the current folder); a
        machine's launcher gives the INI file's folder, as LinuxCNC does.
    """

    def __init__(self, hal, out: Optional[Out] = None,
                 err: Optional[Out] = None, *, keep_going: bool = False,
                 script: bool = False, verbose: int = 0,
                 ini: Optional[str] = None, echo: bool = False,
                 register: bool = True, warn_long_names: bool = True,
                 workdir: Optional[str] = None):
        self.hal = hal
        self.workdir = workdir
        if verbose < 0:
            out = _discard
        self.out = out or _writer(sys.stdout)
        self.err = err or _writer(sys.stderr)
        self.keep_going = keep_going
        self.verbose = verbose
        self.ini = IniFile(ini) if ini else None
        self.echo = echo
        self.warn_long_names = warn_long_names
        self.shower = Shower(self.out, script)
        self.filename: Optional[str] = None
        self.lineno = 0
        self.errors = 0
        self.comp_id: Optional[int] = None
        self._linkpp_warned = False     # linkpp warns once per process
        self.children: list[subprocess.Popen] = []
        if register:
            self.register()

    # ------------------------------------------------------------ identity

    def register(self) -> None:
        """(Re)create the ``halcmd<pid>`` component, as the newest one."""
        self.unregister()
        cid = _core.comp_new(f"halcmd{os.getpid()}", _core.COMP_USER)
        _core.comp_ready(cid, True)
        self.comp_id = cid

    def unregister(self) -> None:
        if self.comp_id is not None:
            comp = _core.comp_by_id(self.comp_id)
            if comp is not None:
                _core.comp_exit(self.comp_id)
            self.comp_id = None

    # ------------------------------------------------------------ running

    def info(self, message: str) -> None:
        """A ``-v`` progress line (prefixed like errors)."""
        if self.verbose > 0:
            prefix = (f"{self.filename}:{self.lineno}: "
                      if self.filename else "")
            self.out(prefix + message + "\n")

    def error(self, message: str) -> None:
        prefix = f"{self.filename}:{self.lineno}: " if self.filename else ""
        self.err(prefix + message + "\n")

    def _in_workdir(self, path: str) -> str:
        if self.workdir is None or os.path.isabs(path):
            return path
        return os.path.join(self.workdir, path)

    def end_children(self, timeout: float = 5.0) -> None:
        """Programs started by ``loadusr`` and still running get SIGTERM,
        then SIGKILL if they have not ended after ``timeout`` seconds."""
        for child in self.children:
            if child.poll() is None:
                child.terminate()
                try:
                    child.wait(timeout=timeout)
                except subprocess.TimeoutExpired:
                    child.kill()
                    child.wait()

    def run_file(self, path: str, keep_going: Optional[bool] = None) -> int:
        """Run a file ("-" is stdin); returns the number of failures."""
        if path == "-":
            return self.run_lines(sys.stdin, "<stdin>", keep_going)
        try:
            f = open(self._in_workdir(path), encoding="utf-8",
                     errors="replace")
        except OSError as exc:
            self.err(f"Could not open hal file '{path}': "
                     f"{exc.strerror}\n")
            self.errors += 1
            return 1
        with f:
            return self.run_lines(f, path, keep_going)

    def run_lines(self, lines: Iterable[str], filename: str,
                  keep_going: Optional[bool] = None) -> int:
        """Run lines read from ``filename``; returns the failures.

        ``keep_going`` defaults to the ``-k`` option; sourced files always
        stop at their first failure, as in the reference.
        """
        if keep_going is None:
            keep_going = self.keep_going
        saved = self.filename, self.lineno
        self.filename = filename
        failures = 0
        try:
            for self.lineno, text in logical_lines(lines):
                if not self.run_line(text):
                    failures += 1
                    if not keep_going:
                        break
        finally:
            self.filename, self.lineno = saved
        return failures

    def run_line(self, text: str) -> bool:
        """Run one logical line; False when it failed (Quit propagates)."""
        try:
            words = tokenize(text, self.ini)
        except SubstitutionError as exc:
            self.errors += 1
            self.error(str(exc))
            return False
        if self.echo:
            self.out(f"({self.lineno})<echo>: {strip_comment(text)}\n")
        if not words:
            return True
        return self.run_words(words)

    def run_words(self, words: list[str]) -> bool:
        try:
            try:
                self.dispatch(words)
            except HalError as exc:     # a case without its own message
                raise hal_error(str(exc), f"{words[0]} failed") from None
        except CommandError as exc:
            self.errors += 1
            if self.verbose >= 0:
                for line in exc.lines:
                    self.err(line + "\n")
            for message in exc.messages:
                self.error(message)
            return False
        return True

    def dispatch(self, words: list[str]) -> None:
        cmd, args = words[0], words[1:]
        if len(words) == 3 and words[1] == "=":
            return self.cmd_setp([words[0], words[2]], "setp")
        handler = getattr(self, "cmd_" + cmd, None)
        if handler is None or cmd not in ARG_COUNTS:
            raise CommandError(f"Unknown command '{cmd}'")
        if cmd in _DROP_ARROWS:
            args = [a for a in args if a not in ARROWS]
        least, most = ARG_COUNTS[cmd]
        if most == least and len(args) != least:
            raise CommandError(f"{cmd} requires {least} arguments, "
                               f"{len(args)} given")
        if len(args) < least:
            raise CommandError(f"{cmd} requires at least {least} arguments,"
                               f" {len(args)} given")
        if most is not None and len(args) > most:
            raise CommandError(f"{cmd} requires at most {most} arguments, "
                               f"{len(args)} given")
        handler(args)

    # ------------------------------------------------------------ helpers

    def created(self, kind: str, names: list[str]) -> None:
        """Hook called with the names of the objects a command created.

        Warns (on the error stream, as ``file:line: Warning: ...``) about
        names the reference could not hold; subclasses (the netlist
        checker) record more.
        """
        if self.verbose < 0 or not self.warn_long_names:
            return
        for name in names:
            if len(name) > REFERENCE_NAME_LEN:
                self.error(f"Warning: {kind} name '{name}' is {len(name)} "
                           f"characters long; the reference HAL accepts at "
                           f"most {REFERENCE_NAME_LEN}")

    @staticmethod
    def _counts() -> dict[str, int]:
        return dict(_core.info()["counts"])

    def _report_new(self, before: dict[str, int]) -> None:
        """Report the objects created since the ``before`` counts (the
        core lists objects in creation order)."""
        after = _core.info()["counts"]
        for kind in _CREATED_KINDS:
            added = after[kind] - before[kind]
            if added > 0:
                self.created(kind, [it.name for it
                                    in _core.items(kind)[-added:]])

    def _locked(self, bit: int) -> bool:
        return bool(_core.get_lock() & bit)

    def _item(self, name: str, order: str = "pin or parameter"):
        item = find("param", name) or find("pin", name)
        if item is None:
            raise CommandError(f"{order} '{name}' not found")
        return item

    def _signal(self, name: str):
        sig = _core.find("signal", name)
        if sig is None:
            raise CommandError(f"signal '{name}' not found")
        return sig

    # ------------------------------------------------------------ modules

    def cmd_loadrt(self, args: list[str]) -> None:
        if self._locked(LOCK_LOAD):
            raise CommandError("HAL is locked, loading of programs is not "
                               "permitted",
                               f"insmod for {args[0]} failed, returned -1")
        if self.comp_id is not None:
            self.register()
        before = self._counts()
        try:
            self.hal.loadrt(args[0], *args[1:])
        except HalError as exc:
            text = str(exc)         # it names the module, or we do
            if not text.startswith(f"{args[0]}:"):
                text = f"{args[0]}: {text}"
            raise CommandError(f"insmod for {args[0]} failed, returned -1",
                               lines=[text]) from None
        self._report_new(before)
        self.info(f"Component '{args[0]}' ready")
        self.info(f"Realtime module '{args[0]}' loaded")

    def cmd_unloadrt(self, args: list[str]) -> None:
        name = args[0]
        if name != "all" and name not in self._rt_modules():
            raise CommandError(f"component '{name}' is not loaded")
        try:
            self.hal.unloadrt(name)
        except HalError as exc:
            raise CommandError(f"unloadrt failed: {exc}") from None

    def cmd_unload(self, args: list[str]) -> None:
        registered = self.comp_id is not None
        if args[0] != "all" and _core.find("component", args[0]) is None:
            raise CommandError(f"component '{args[0]}' is not loaded")
        try:
            self.hal.unload(args[0])
        except HalError as exc:
            raise CommandError(f"unload failed: {exc}") from None
        finally:
            # halcmd's own component survives "unload all", as in the
            # reference
            if registered and args[0] == "all" and (
                    self.comp_id is None
                    or _core.comp_by_id(self.comp_id) is None):
                self.comp_id = None
                self.register()

    def _rt_modules(self) -> set[str]:
        return {c.name for c in _core.items("component")
                if c.realtime and not c.name.startswith("__")}

    def cmd_newinst(self, args: list[str]) -> None:
        before = self._counts()
        try:
            self.hal.newinst(args[0], args[1], *args[2:])
        except HalError as exc:
            raise CommandError(f"newinst failed: {exc}") from None
        self._report_new(before)

    def cmd_delinst(self, args: list[str]) -> None:
        try:
            self.hal.delinst(args[0])
        except HalError as exc:
            raise CommandError(f"delinst failed: {exc}") from None

    # ------------------------------------------------------------ programs

    def cmd_loadusr(self, args: list[str]) -> None:
        """``loadusr [-W | -Wn name] [-w [-i]] program args...``."""
        wait_ready: Optional[str] = None
        wait_exit = ignore = False
        while args and args[0].startswith("-"):
            flag, args = args[0], args[1:]
            if flag == "-W":
                wait_ready = ""
            elif flag == "-Wn" and args:
                wait_ready, args = args[0], args[1:]
            elif flag == "-w":
                wait_exit = True
            elif flag == "-i":
                ignore = True
            else:
                raise CommandError(f"loadusr: unknown flag '{flag}'")
        if not args:
            raise CommandError("execv(): No such file or directory")
        prog = args[0]
        if self._locked(LOCK_LOAD):
            raise CommandError("HAL is locked, loading of programs is not "
                               "permitted")
        try:
            child = subprocess.Popen([_program_path(prog), *args[1:]],
                                     stdin=subprocess.DEVNULL,
                                     cwd=self.workdir)
        except OSError as exc:
            raise CommandError(f"execv({prog}): {exc.strerror}",
                               f"program '{prog}' failed, returned 1"
                               ) from None
        self.children.append(child)
        if wait_ready is not None:
            name = wait_ready or os.path.basename(prog)
            while True:
                comp = _core.find("component", name)
                if comp is not None and comp.ready:
                    self.info(f"Component '{name}' ready")
                    break
                if child.poll() is not None:
                    raise CommandError(f"{prog} exited without becoming "
                                       "ready")
                time.sleep(0.01)
        self.info(f"Program '{prog}' started")
        if wait_exit:
            code = child.wait()
            if code and not ignore:
                raise CommandError(f"program '{prog}' failed, returned "
                                   f"{code if code > 0 else 128 - code}")

    def cmd_waitusr(self, args: list[str]) -> None:
        name = args[0]
        comp = _core.find("component", name)
        if comp is None:
            return              # nothing to wait for, as in the reference
        if comp.realtime:
            raise CommandError(f"component '{name}' is not a userspace "
                               "component")
        while comp.exists and comp.alive:
            time.sleep(0.01)

    def cmd_unloadusr(self, args: list[str]) -> None:
        name = args[0]
        if name == "all":
            names = [c.name for c in _core.items("component")
                     if not c.realtime and c.id != self.comp_id]
        else:
            comp = _core.find("component", name)
            if comp is None:
                return          # the reference says nothing either
            if comp.realtime:
                raise CommandError(f"component '{name}' is not a userspace "
                                   "component")
            names = [name]
        for comp_name in names:
            try:
                self.hal.unload(comp_name)
            except HalError as exc:
                raise CommandError(f"unloadusr failed: {exc}") from None

    # ------------------------------------------------------------ signals

    def cmd_newsig(self, args: list[str]) -> None:
        name, tword = args
        t = SIG_TYPES.get(tword.lower())
        if t is None:
            raise CommandError(f"Unknown signal type '{tword}'",
                               "newsig failed")
        if self._locked(LOCK_CONFIG):
            raise hal_error("signal_new called while HAL is locked",
                            "newsig failed")
        if _core.find("signal", name) is not None:
            raise hal_error(f"duplicate signal '{name}'", "newsig failed")
        try:
            _core.signal_new(name, t)
        except HalError as exc:
            raise hal_error(str(exc), "newsig failed") from None
        self.created("signal", [name])

    def cmd_delsig(self, args: list[str]) -> None:
        name = args[0]
        if self._locked(LOCK_CONFIG):
            raise hal_error("signal_delete called while HAL locked")
        if name == "all":
            for sig in _core.items("signal"):
                _core.signal_delete(sig.name)
            return
        if _core.find("signal", name) is None:
            raise hal_error(f"signal '{name}' not found")
        _core.signal_delete(name)

    def cmd_sets(self, args: list[str]) -> None:
        sig = self._signal(args[0])
        if sig.writers:             # io pins do not count, as in the reference
            raise CommandError(f"signal '{args[0]}' already has writer(s)")
        try:
            value = parse_value(sig.type, args[1])
        except ValueError:
            raise CommandError(
                f"value '{args[1]}' invalid for {_value_word(sig.type)}",
                "sets failed") from None
        sig.write(value)            # the reference's sets ignores locks

    def cmd_gets(self, args: list[str]) -> None:
        sig = self._signal(args[0])
        self.out(value_text(sig.type, sig.value) + "\n")

    def cmd_stype(self, args: list[str]) -> None:
        sig = self._signal(args[0])
        self.out(type_name(sig.type) + "\n")

    # ------------------------------------------------------------ values

    def cmd_setp(self, args: list[str], name: str = "setp") -> None:
        item = find("param", args[0]) or find("pin", args[0])
        if item is None:
            raise CommandError(f"parameter or pin '{args[0]}' not found")
        if isinstance(item, _core.Param):
            if item.direction == _core.RO:
                raise CommandError(f"param '{args[0]}' is not writable")
        else:
            if item.direction == _core.OUT:
                raise CommandError(f"pin '{args[0]}' is not writable")
            if item.signal is not None:
                raise CommandError(f"pin '{args[0]}' is connected to a "
                                   "signal")
        try:
            value = parse_value(item.type, args[1])
        except ValueError:
            raise CommandError(
                f"value '{args[1]}' invalid for {_value_word(item.type)}",
                "setp failed") from None
        item.write(value)
        self.info(f"setting parameter '{args[0]}' to '{args[1]}'")
        kind = "Pin" if isinstance(item, _core.Pin) else "Parameter"
        self.info(f"{kind} '{args[0]}' set to {args[1]}")

    def cmd_getp(self, args: list[str]) -> None:
        item = self._item(args[0])
        self.out(value_text(item.type, item.value) + "\n")

    def cmd_ptype(self, args: list[str]) -> None:
        item = self._item(args[0])
        self.out(type_name(item.type) + "\n")

    # ------------------------------------------------------------ links

    def _link(self, pin_name: str, sig_name: str, what: str) -> None:
        if self._locked(LOCK_CONFIG):
            raise hal_error("link called while HAL locked",
                            f"{what} failed")
        pin = find("pin", pin_name)
        if pin is None:
            raise hal_error(f"pin '{pin_name}' not found", f"{what} failed")
        sig = _core.find("signal", sig_name)
        if sig is None:
            raise hal_error(f"signal '{sig_name}' not found",
                            f"{what} failed")
        if pin.type != sig.type:
            raise hal_error(f"type mismatch '{pin_name}' <- '{sig_name}'",
                            f"{what} failed")
        current = pin.signal
        if current is not None:
            raise hal_error(f"pin '{pin.name}' is linked to '{current.name}'"
                            f", cannot link to '{sig_name}'", f"{what} failed")
        if pin.direction in (_core.OUT, _core.IO) and \
                (sig.writers or sig.bidirs and pin.direction == _core.OUT):
            raise hal_error(f"signal '{sig_name}' already has output or "
                            "I/O pin(s)", f"{what} failed")
        _core.link(pin.name, sig_name)

    def cmd_linkps(self, args: list[str]) -> None:
        self._link(args[0], args[1], "link")

    def cmd_linksp(self, args: list[str]) -> None:
        self._link(args[1], args[0], "link")

    def cmd_linkpp(self, args: list[str]) -> None:
        if not self._linkpp_warned:         # once, as the reference does
            self._linkpp_warned = True
            self.error("Warning: linkpp command is deprecated, use 'net'")
        first, second = args
        pin = find("pin", first)
        if pin is None:
            raise CommandError(f"pin '{first}' not found")
        other = find("pin", second)
        if other is None:
            raise CommandError(f"pin '{second}' not found")
        if other.type != pin.type:
            raise CommandError(f"pins '{first}' and '{second}' not of the "
                               "same type")
        if _core.find("signal", first) is None:
            _core.signal_new(first, pin.type)
            self.created("signal", [first])
        self._link(first, first, "linkpp")
        self._link(second, first, "linkpp")

    def cmd_unlinkp(self, args: list[str]) -> None:
        if self._locked(LOCK_CONFIG):
            raise hal_error("unlink called while HAL locked",
                            "unlink failed")
        pin = find("pin", args[0])
        if pin is None:
            raise hal_error(f"pin '{args[0]}' not found", "unlink failed")
        _core.unlink(pin.name)

    def cmd_net(self, args: list[str]) -> None:
        signame = args[0]
        pins = [a for a in args[1:] if a not in ARROWS]
        if find("pin", signame) is not None:
            raise CommandError(f"Signal name '{signame}' must not be the "
                               "same as a pin.  Did you omit the signal "
                               "name?")
        if not pins:
            raise CommandError("'net' requires at least one pin, none given")
        sig = _core.find("signal", signame)
        handles = []
        for name in pins:
            pin = find("pin", name)
            if pin is None:
                raise CommandError(f"Pin '{name}' does not exist")
            if pin.signal is not None and pin.signal.name != signame:
                raise CommandError(f"Pin '{name}' was already linked to "
                                   f"signal '{pin.signal.name}'")
            if sig is not None and sig.type != pin.type:
                raise CommandError(
                    f"Signal '{signame}' of type '{type_name(sig.type)}' "
                    f"cannot add pin '{name}' of type "
                    f"'{type_name(pin.type)}'")
            if sig is not None and pin.signal is None:
                self._check_writer(sig, pin)
            handles.append(pin)
        stype = sig.type if sig is not None else handles[0].type
        for pin in handles:
            if pin.type != stype:
                raise hal_error(f"type mismatch '{pin.name}' <- "
                                f"'{signame}'", "link failed")
        writers = sig.writers if sig is not None else 0
        bidirs = sig.bidirs if sig is not None else 0
        for pin in handles:
            if pin.signal is not None:
                continue
            if pin.direction == _core.OUT and (writers or bidirs) or \
                    pin.direction == _core.IO and writers:
                raise hal_error(f"signal '{signame}' already has output or "
                                "I/O pin(s)", "link failed")
            writers += pin.direction == _core.OUT
            bidirs += pin.direction == _core.IO
        if self._locked(LOCK_CONFIG):
            raise hal_error("signal_new called while HAL is locked") \
                if sig is None else \
                hal_error("link called while HAL locked", "link failed")
        if sig is None:
            _core.signal_new(signame, stype)
            self.created("signal", [signame])
        for pin in handles:
            if pin.signal is None:
                _core.link(pin.name, signame)
                self.info(f"Pin '{pin.name}' linked to signal '{signame}'")

    def _check_writer(self, sig, pin) -> None:
        """The reference's check for a pin joining an existing signal."""
        if pin.direction not in (_core.OUT, _core.IO):
            return
        for other in sorted(sig.pins, key=lambda p: p.name.encode()):
            if other.direction == _core.OUT or (
                    other.direction == _core.IO and
                    pin.direction == _core.OUT):
                raise CommandError(
                    f"Signal '{sig.name}' can not add "
                    f"{_core.DIR_NAMES[pin.direction]} pin '{pin.name}', "
                    f"it already has {_core.DIR_NAMES[other.direction]} "
                    f"pin '{other.name}'")

    # ------------------------------------------------------------ threads

    def cmd_addf(self, args: list[str]) -> None:
        funct, thread = args[0], args[1]
        position = -1
        if len(args) > 2:
            position = _atoi(args[2])
            if position == 0:
                raise hal_error("bad position: 0", "addf failed")
        if self._locked(LOCK_CONFIG):
            raise hal_error("add_funct_to_thread called while HAL is "
                            "locked", "addf failed")
        if _core.find("function", funct) is None:
            raise hal_error(f"function '{funct}' not found", "addf failed")
        handle = _core.find("thread", thread)
        if handle is None:
            raise hal_error(f"thread '{thread}' not found", "addf failed")
        n = len(handle.functions)
        if position > n + 1:
            raise hal_error(f"position '{position}' is too high",
                            "addf failed")
        if position < -(n + 1):
            raise hal_error(f"position '{position}' is too low",
                            "addf failed")
        try:
            self.hal.addf(funct, thread, position)
        except HalError as exc:
            raise hal_error(str(exc), "addf failed") from None
        self.info(f"Function '{funct}' added to thread '{thread}'")

    def cmd_delf(self, args: list[str]) -> None:
        if not args:
            raise hal_error("missing function name", "delf failed")
        if len(args) < 2:
            raise hal_error("missing thread name", "delf failed")
        funct, thread = args
        if self._locked(LOCK_CONFIG):
            raise hal_error("del_funct_from_thread called while HAL is "
                            "locked", "delf failed")
        handle = _core.find("function", funct)
        if handle is None:
            raise hal_error(f"function '{funct}' not found", "delf failed")
        if handle.users == 0:
            raise hal_error(f"function '{funct}' is not in use",
                            "delf failed")
        if _core.find("thread", thread) is None:
            raise hal_error(f"thread '{thread}' not found", "delf failed")
        try:
            self.hal.delf(funct, thread)
        except HalError as exc:
            raise hal_error(str(exc), "delf failed") from None

    def cmd_start(self, args: list[str]) -> None:
        if self._locked(LOCK_RUN):
            raise hal_error("start_threads called while HAL is locked")
        self.hal.start()

    def cmd_stop(self, args: list[str]) -> None:
        if self._locked(LOCK_RUN):
            raise hal_error("stop_threads called while HAL is locked")
        self.hal.stop()

    # ------------------------------------------------------------ aliases

    def cmd_alias(self, args: list[str]) -> None:
        kind, name, alias = args
        if kind not in ("pin", "param"):
            raise CommandError("alias failed")
        if self._locked(LOCK_CONFIG):
            raise hal_error(f"{kind}_alias called while HAL locked",
                            "alias failed")
        item = find(kind, name)
        if item is None:
            raise hal_error(f"{kind} '{name}' not found", "alias failed")
        if find("pin", alias) is not None or find("param", alias) is not None:
            raise hal_error(f"duplicate pin/alias name '{alias}'",
                            "alias failed")
        try:
            _core.alias(kind, item.name, alias)
        except HalError as exc:
            raise hal_error(str(exc), "alias failed") from None
        self.created(kind, [alias])
        self.info(f"{kind} '{name}' aliased to '{alias}'")

    def cmd_unalias(self, args: list[str]) -> None:
        kind, alias = args
        if kind not in ("pin", "param"):
            return              # the reference ignores other kinds
        item = _core.find(kind, alias)
        if item is None or item.alias_of is None:
            raise hal_error(f"{kind} '{alias}' not found", "unalias failed")
        _core.unalias(kind, alias)

    # ------------------------------------------------------------ locks

    def cmd_lock(self, args: list[str]) -> None:
        word = args[0] if args else "all"
        if word in LOCK_WORDS:
            _core.set_lock(_core.get_lock() | LOCK_WORDS[word])

    def cmd_unlock(self, args: list[str]) -> None:
        word = args[0] if args else "all"
        if word in LOCK_WORDS:
            _core.set_lock(_core.get_lock() & ~LOCK_WORDS[word] & 255)

    # ------------------------------------------------------------ output

    def cmd_show(self, args: list[str]) -> None:
        what = args[0] if args else "all"
        if not self.shower.show(what, args[1:]):
            raise CommandError(f"Unknown 'show' type '{what}'")

    def cmd_list(self, args: list[str]) -> None:
        if not self.shower.names(args[0], args[1:]):
            raise CommandError(f"Unknown 'list' type '{args[0]}'")

    def cmd_save(self, args: list[str]) -> None:
        what = args[0] if args else "all"
        if len(args) < 2:
            if not Saver(self.out, self.hal.loadrt_args()).save(what):
                raise CommandError(f"Unknown 'save' type '{what}'")
            return
        lines: list[str] = []
        if not Saver(lines.append, self.hal.loadrt_args()).save(what):
            raise CommandError(f"Unknown 'save' type '{what}'")
        try:
            with open(args[1], "w", encoding="utf-8") as f:
                f.write("".join(lines))
        except OSError as exc:
            raise CommandError(f"Can't open 'save' destination "
                               f"'{args[1]}': {exc.strerror}") from None

    def cmd_status(self, args: list[str]) -> None:
        what = args[0] if args else "all"
        if not status(self.out, what):
            raise CommandError(f"Unknown 'status' type '{what}'")

    def cmd_help(self, args: list[str]) -> None:
        if not args:
            self.out("Commands (help COMMAND for one):\n")
            names = sorted(HELP)
            for i in range(0, len(names), 6):
                self.out("  " + " ".join(names[i:i + 6]) + "\n")
            return
        text = HELP.get(args[0])
        if text is None:
            raise CommandError(lines=[f"No help for unknown command "
                                      f"'{args[0]}'"])
        self.out(text + "\n")

    def cmd_debug(self, args: list[str]) -> None:
        level = _atoi(args[0])
        _core.set_msg_level(max(0, min(5, level)))

    def cmd_print(self, args: list[str]) -> None:
        text = " ".join(args) if args else "(null)"
        self.error(f"HALCMD MSG: {text}")

    def cmd_setexact_for_test_suite_only(self, args: list[str]) -> None:
        # simulated time (Hal.step) is always exact; only the warning
        self.error("Warning: HAL_LIB: HAL will pretend that the exact base "
                   "period requested is possible.")
        self.err("This mode is not suitable for running real hardware.\n")

    def cmd_echo(self, args: list[str]) -> None:
        self.echo = True
        self.out("Echo on\n")

    def cmd_unecho(self, args: list[str]) -> None:
        self.echo = False
        self.out("Echo off\n")

    def cmd_source(self, args: list[str]) -> None:
        if self.run_file(args[0], keep_going=False):
            raise CommandError()
        # errors inside were reported with the sourced file's lines

    def cmd_quit(self, args: list[str]) -> None:
        raise Quit()

    cmd_exit = cmd_quit


def _value_word(t: int) -> str:
    return _TYPE_WORD.get(t, "?")


def _atoi(text: str) -> int:
    m = re.match(r"\s*([-+]?\d+)", text)
    return int(m.group(1)) if m else 0


def _discard(text: str) -> None:
    pass


def _writer(stream) -> Out:
    def write(text: str) -> None:
        stream.write(text)
        stream.flush()
    return write
