"""The HAL command runner shared by halrun, halcmd and Python.

:class:`CommandRunner` runs one command (a list of words) or a whole file and
prints what the reference halcmd prints: results to ``out``, errors to
``err`` as ``file:line: message`` (no prefix on the command line).
"""

from __future__ import annotations

import os
import re
import sys
import time
from collections.abc import Iterable
from typing import TYPE_CHECKING, Callable, Optional

from halsdk import console
from halsdk.compat import program_env
from halsdk.component import Component
from halsdk.errors import HalError, HostGoneError, LockTimeoutError, Rule
from halsdk.hal import Hal, is_halcmd_comp
from halsdk.halcmd.helptext import HELP
from halsdk.halcmd.lexer import (
    IniFile,
    SubstitutionError,
    logical_lines,
    strip_comment,
    tokenize,
)
from halsdk.halcmd.messages import lookup, words
from halsdk.halcmd.save import Saver, status
from halsdk.halcmd.show import Shower, type_name, value_text
from halsdk.types import Direction, HalType, parse_type
from halsdk.values import parse_word

if TYPE_CHECKING:
    import subprocess

# shutil and subprocess are imported by loadusr, where they are used: a
# halcmd that does not start programs starts faster

Out = Callable[[str], None]

# lock bits of the core (same values as the reference)
LOCK_LOAD, LOCK_CONFIG, LOCK_PARAMS, LOCK_RUN = (
    Hal.LOCK_LOAD, Hal.LOCK_CONFIG, Hal.LOCK_PARAMS, Hal.LOCK_RUN)
LOCK_WORDS = {"all": 255, "tune": LOCK_LOAD | LOCK_CONFIG, "none": 0}
ARROWS = ("=>", "<=", "<=>")

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
# kinds of objects whose new names are reported to CommandRunner.created()
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


def _program_path(prog: str) -> str:
    """A program for loadusr: on PATH, else a launcher that halcompile
    put in a HALSDK_PATH folder or the user component folder."""
    import shutil
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


#: a word as halcmd reads it (kept under its old name)
parse_value = parse_word


class CommandRunner:
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
        self.shower = Shower(hal, self.out, script)
        self.filename: Optional[str] = None
        self.lineno = 0
        self.errors = 0
        self.comp_id: Optional[int] = None
        self.component: Optional[Component] = None
        self._linkpp_warned = False     # linkpp warns once per process
        self.children: list[subprocess.Popen] = []
        if register:
            self.register()

    # ------------------------------------------------------------ identity

    def register(self) -> None:
        """(Re)create the ``halcmd<pid>`` component, as the newest one."""
        self.unregister()
        comp = self.hal.new_component(f"halcmd{os.getpid()}")
        comp.ready()
        self.component = comp
        self.comp_id = comp.id

    def unregister(self) -> None:
        comp, self.component, self.comp_id = self.component, None, None
        if comp is not None:
            try:
                comp.exit()
            except HalError as exc:     # a damaged instance: say so
                self.error(str(exc))

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
        if not self.children:
            return
        import subprocess
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
        if self.echo:           # on stderr, as the reference's halcmd
            self.err(f"({self.lineno})<echo>: {strip_comment(text)}\n")
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
            if isinstance(exc.__context__, (HostGoneError, LockTimeoutError)):
                # the instance failed, not the command (its host died, a
                # stopped process holds the lock): one line that says so
                self.error(str(exc.__context__))
                return False
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

    def _counts(self) -> dict[str, int]:
        return self.hal.counts()

    def _report_new(self, before: dict[str, int]) -> None:
        """Report the objects created since the ``before`` counts (the
        core lists objects in creation order)."""
        after = self.hal.counts()
        for kind in _CREATED_KINDS:
            added = after[kind] - before[kind]
            if added > 0:
                self.created(kind, [it.name for it in self.hal.snapshot(
                    kind, sort=False)[-added:]])

    def _locked(self, bit: int) -> bool:
        return bool(self.hal.lock_level & bit)

    def _item(self, name: str):
        item = self.hal.find("param", name) or self.hal.find("pin", name)
        if item is None:
            raise CommandError(f"pin or parameter '{name}' not found")
        return item

    def failure(self, command: str, exc: HalError,
                variant: Optional[str] = None, **fields) -> CommandError:
        """The reference's words for an error of the core (messages.py);
        an error the table does not know keeps the core's message."""
        entry = lookup(command, exc, variant)
        if entry is None:
            return hal_error(str(exc), f"{command} failed")
        hal_line, message = words(entry, exc, **fields)
        return CommandError(*(message or "").split("\n"),
                            lines=[f"HAL: ERROR: {hal_line}"]
                            if hal_line is not None else [])

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
        if args[0] != "all" and self.hal.find("component", args[0]) is None:
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
                    or self.hal.component_by_id(self.comp_id) is None):
                self.component = None
                self.comp_id = None
                self.register()

    def _rt_modules(self) -> set[str]:
        return {c.name for c in self.hal.snapshot("component", sort=False)
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
            # the compat hal/linuxcnc modules importable, as the
            # reference's halrun makes its own for the programs it starts
            # and ends with the host, however the host ends
            import subprocess
            child = self.hal.spawn([_program_path(prog), *args[1:]],
                                   stdin=subprocess.DEVNULL,
                                   cwd=self.workdir, env=program_env())
        except OSError as exc:
            raise CommandError(f"execv({prog}): {exc.strerror}",
                               f"program '{prog}' failed, returned 1"
                               ) from None
        self.children.append(child)
        if wait_ready is not None:
            self._wait_ready(wait_ready or os.path.basename(prog), prog,
                             child)
        self.info(f"Program '{prog}' started")
        if wait_exit:
            code = child.wait()
            if code and not ignore:
                raise CommandError(f"program '{prog}' failed, returned "
                                   f"{code if code > 0 else 128 - code}")

    #: ``loadusr -W`` says what it waits for after this many seconds,
    #: then adds a dot every WAIT_DOT_SECONDS, as the reference does
    WAIT_SAY_SECONDS = 2.0
    WAIT_DOT_SECONDS = 0.1

    def _wait_ready(self, name: str, prog: str,
                    child: subprocess.Popen) -> None:
        """Wait until the component ``name`` is ready or ``child`` ends
        (CommandError).  It waits as long as the program runs, as the
        reference does, but not silently: after WAIT_SAY_SECONDS it says
        which component it waits for (Ctrl-C ends the wait)."""
        start = time.monotonic()
        next_say = start + self.WAIT_SAY_SECONDS
        said = False
        try:
            while True:
                comp = self.hal.find("component", name)
                if comp is not None and comp.ready:
                    break
                if child.poll() is not None:
                    raise CommandError(f"{prog} exited without becoming "
                                       "ready")
                now = time.monotonic()
                if now >= next_say:
                    self.err("." if said else
                             f"Waiting for component '{name}' to become "
                             "ready")
                    said = True
                    next_say = now + self.WAIT_DOT_SECONDS
                time.sleep(0.01)
        finally:
            if said:
                self.err("\n")
        self.info(f"Component '{name}' ready")

    def cmd_waitusr(self, args: list[str]) -> None:
        name = args[0]
        comp = self.hal.find("component", name)
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
            # never this process (halcmd would end itself with SIGTERM)
            # nor another halcmd session, as in the reference
            me = os.getpid()
            names = [c.name
                     for c in self.hal.snapshot("component", sort=False)
                     if not c.realtime and c.id != self.comp_id
                     and c.pid != me and not is_halcmd_comp(c.name, c.pid)
                     and not c.name.startswith("__")]
        else:
            comp = self.hal.find("component", name)
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
        try:
            t = parse_type(tword)
        except HalError:
            raise CommandError(f"Unknown signal type '{tword}'",
                               "newsig failed") from None
        try:
            self.hal.newsig(name, t)
        except HalError as exc:
            raise self.failure("newsig", exc) from None
        self.created("signal", [name])

    def cmd_delsig(self, args: list[str]) -> None:
        try:
            self.hal.delsig(args[0])
        except HalError as exc:
            raise self.failure("delsig", exc) from None

    def cmd_sets(self, args: list[str]) -> None:
        try:
            # the reference's sets ignores locks
            self.hal.sets(args[0], args[1], ignore_lock=True, wrap=True)
        except HalError as exc:
            raise self._value_failure("sets", exc, "signal", args[0],
                                      args[1]) from None

    def cmd_gets(self, args: list[str]) -> None:
        try:
            sig = self.hal.signal(args[0])
        except HalError as exc:
            raise self.failure("gets", exc) from None
        self.out(value_text(sig.type, sig.value) + "\n")

    def cmd_stype(self, args: list[str]) -> None:
        try:
            sig = self.hal.signal(args[0])
        except HalError as exc:
            raise self.failure("gets", exc) from None
        self.out(type_name(sig.type) + "\n")

    # ------------------------------------------------------------ values

    def cmd_setp(self, args: list[str], name: str = "setp") -> None:
        try:
            # the reference's setp ignores locks
            self.hal.setp(args[0], args[1], ignore_lock=True, wrap=True)
        except HalError as exc:
            raise self._value_failure("setp", exc, "param", args[0],
                                      args[1]) from None
        self.info(f"setting parameter '{args[0]}' to '{args[1]}'")
        kind = "Pin" if self.hal.find("param", args[0]) is None \
            else "Parameter"
        self.info(f"{kind} '{args[0]}' set to {args[1]}")

    def _value_failure(self, command: str, exc: HalError, kind: str,
                       name: str, text: str) -> CommandError:
        if exc.rule != Rule.BAD_VALUE:
            return self.failure(command, exc)
        item = self.hal.find(kind, name) or self.hal.find("pin", name)
        return self.failure(command, exc, value=text,
                            type_word=HalType(item.type).value_word)

    def cmd_getp(self, args: list[str]) -> None:
        item = self._item(args[0])
        self.out(value_text(item.type, item.value) + "\n")

    def cmd_ptype(self, args: list[str]) -> None:
        item = self._item(args[0])
        self.out(type_name(item.type) + "\n")

    # ------------------------------------------------------------ links

    def _link(self, pin_name: str, sig_name: str, what: str) -> None:
        try:
            self.hal.linkps(pin_name, sig_name)
        except HalError as exc:
            raise self.failure("link", exc, exc.kind,
                               failed=f"{what} failed") from None

    def cmd_linkps(self, args: list[str]) -> None:
        self._link(args[0], args[1], "link")

    def cmd_linksp(self, args: list[str]) -> None:
        self._link(args[1], args[0], "link")

    def cmd_linkpp(self, args: list[str]) -> None:
        if not self._linkpp_warned:         # once, as the reference does
            self._linkpp_warned = True
            self.error("Warning: linkpp command is deprecated, use 'net'")
        first, second = args
        pin = self.hal.find("pin", first)
        if pin is None:
            raise CommandError(f"pin '{first}' not found")
        other = self.hal.find("pin", second)
        if other is None:
            raise CommandError(f"pin '{second}' not found")
        if other.type != pin.type:
            raise CommandError(f"pins '{first}' and '{second}' not of the "
                               "same type")
        if self.hal.find("signal", first) is None:
            self.hal.newsig(first, pin.type)
            self.created("signal", [first])
        self._link(first, first, "linkpp")
        self._link(second, first, "linkpp")

    def cmd_unlinkp(self, args: list[str]) -> None:
        try:
            self.hal.unlinkp(args[0])
        except HalError as exc:
            raise self.failure("unlinkp", exc) from None

    def cmd_net(self, args: list[str]) -> None:
        signame = args[0]
        pins = [a for a in args[1:] if a not in ARROWS]
        existed = self.hal.find("signal", signame) is not None
        handles = [self.hal.find("pin", name) for name in pins]
        new = [p for p in handles if p is not None and p.signal is None]
        try:
            self.hal.net(signame, *pins)
        except HalError as exc:
            raise self._net_failure(exc, existed) from None
        if not existed:
            self.created("signal", [signame])
        for pin in new:
            self.info(f"Pin '{pin.name}' linked to signal '{signame}'")

    def _net_failure(self, exc: HalError, existed: bool) -> CommandError:
        """The reference's words for a refused ``net``: they depend on
        whether the signal existed and whether the pin the new one
        conflicts with was on it already (nothing changed: it still is)."""
        if exc.rule == Rule.TYPE_MISMATCH:
            sig = self.hal.find("signal", exc.names[0])
            pin = self.hal.find("pin", exc.names[1])
            return self.failure(
                "net", exc, "existing" if existed else "new",
                sig_type=type_name(sig.type) if sig else "",
                pin_type=type_name(pin.type) if pin else "")
        if exc.rule in (Rule.SECOND_WRITER, Rule.WRITER_AND_IO):
            pin = self.hal.find("pin", exc.names[1])
            other = self.hal.find("pin", exc.names[2]) \
                if len(exc.names) > 2 else None
            if other is None or other.signal is None:
                return self.failure("net", exc, "new")
            return self.failure("net", exc, "existing",
                                pin_dir=Direction(pin.direction).word,
                                other_dir=Direction(other.direction).word)
        return self.failure("net", exc, exc.kind)

    # ------------------------------------------------------------ threads

    def cmd_addf(self, args: list[str]) -> None:
        funct, thread = args[0], args[1]
        position = -1
        if len(args) > 2:
            position = _atoi(args[2])
            if position == 0:
                raise hal_error("bad position: 0", "addf failed")
        try:
            self.hal.addf(funct, thread, position)
        except HalError as exc:
            raise self.failure("addf", exc, exc.kind, position=position,
                               high_low="high" if position > 0 else "low"
                               ) from None
        self.info(f"Function '{funct}' added to thread '{thread}'")

    def cmd_delf(self, args: list[str]) -> None:
        if not args:
            raise hal_error("missing function name", "delf failed")
        if len(args) < 2:
            raise hal_error("missing thread name", "delf failed")
        funct, thread = args
        try:
            self.hal.delf(funct, thread)
        except HalError as exc:
            raise self.failure("delf", exc, exc.kind) from None

    def cmd_start(self, args: list[str]) -> None:
        try:
            self.hal.start()
        except HalError as exc:
            raise self.failure("start", exc) from None

    def cmd_stop(self, args: list[str]) -> None:
        try:
            self.hal.stop()
        except HalError as exc:
            raise self.failure("stop", exc) from None

    # ------------------------------------------------------------ aliases

    def cmd_alias(self, args: list[str]) -> None:
        kind, name, alias = args
        if kind not in ("pin", "param"):
            raise CommandError("alias failed")
        try:
            self.hal.alias(kind, name, alias)
        except HalError as exc:
            raise self.failure("alias", exc) from None
        self.created(kind, [alias])
        self.info(f"{kind} '{name}' aliased to '{alias}'")

    def cmd_unalias(self, args: list[str]) -> None:
        kind, alias = args
        if kind not in ("pin", "param"):
            return              # the reference ignores other kinds
        try:
            self.hal.unalias(kind, alias)
        except HalError as exc:
            raise self.failure("unalias", exc) from None

    # ------------------------------------------------------------ locks

    def cmd_lock(self, args: list[str]) -> None:
        word = args[0] if args else "all"
        if word in LOCK_WORDS:
            self.hal.lock_level |= LOCK_WORDS[word]

    def cmd_unlock(self, args: list[str]) -> None:
        word = args[0] if args else "all"
        if word in LOCK_WORDS:
            self.hal.lock_level &= ~LOCK_WORDS[word] & 255

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
            if not Saver(self.hal, self.out, self.hal.loadrt_args()).save(what):
                raise CommandError(f"Unknown 'save' type '{what}'")
            return
        lines: list[str] = []
        if not Saver(self.hal, lines.append, self.hal.loadrt_args()).save(what):
            raise CommandError(f"Unknown 'save' type '{what}'")
        try:
            with open(args[1], "w", encoding="utf-8") as f:
                f.write("".join(lines))
        except OSError as exc:
            raise CommandError(f"Can't open 'save' destination "
                               f"'{args[1]}': {exc.strerror}") from None

    def cmd_status(self, args: list[str]) -> None:
        what = args[0] if args else "all"
        if not status(self.hal, self.out, what):
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
        self.hal.msg_level = max(0, min(5, level))

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


def _atoi(text: str) -> int:
    """C's atoi, as the reference reads these numbers: the leading
    digits, saturated to a long, then taken as a 32-bit int
    ("2147483648" is -2147483648)."""
    m = re.match(r"\s*([-+]?\d+)", text)
    if not m:
        return 0
    value = max(-2**63, min(2**63 - 1, int(m.group(1))))
    return (value + 2**31) % 2**32 - 2**31


def _discard(text: str) -> None:
    pass


def _writer(stream) -> Out:
    def write(text: str) -> None:
        try:
            stream.write(text)
            stream.flush()
        except BrokenPipeError:
            # the reader went away ("halcmd show pin | head -1"): as the
            # reference, say nothing and run the rest of the file, so a
            # HAL file is never left half applied; what follows goes to
            # /dev/null
            if stream is not sys.stdout:
                raise
            console.silence_stdout()
    return write
