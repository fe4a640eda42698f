"""Twopass loading of the HAL files listed in an INI file.

The reference triggers it with ``halrun FILE.ini`` (or the LinuxCNC
start-up script) when the INI file has a non-empty ``[HAL]TWOPASS``; the
files are the ``[HAL]HALFILE`` entries, in order.  halsdk does the same:

* **pass 0** reads every file.  ``loadusr`` commands run now; ``loadrt``
  commands are only collected, per module, in the order modules first
  appear: ``count=`` and ``num_chan=`` values are added up, ``names=`` and
  ``personality=`` lists are joined with commas, ``debug=`` values are
  OR-ed and any other parameter is kept.  One module may use only one of
  ``count=``/``num_chan=``/``names=``.  Every other command waits.  At
  the end of the pass each module is loaded once with the merged
  parameters.
* **pass 1** reads the files again and runs everything except ``loadrt``
  of the modules already loaded and ``loadusr``; ``addf`` runs in place,
  so the order of functions in threads is the order of the files.

A file holding a line that starts with ``#NOTWOPASS`` (blanks and case
ignored) is not part of this: it is run at once, before pass 0, as with
``halcmd -k -v -f``.  ``[HAL]TWOPASS`` words ``verbose`` (progress lines)
and ``nodelete`` (accepted; halsdk makes no temporary files) are options.
A relative ``HALFILE`` is looked up next to the INI file.

``getp``, ``gets``, ``ptype`` and ``stype`` print nothing here: the
reference runs the files as Tcl, where they return their value instead.
Output follows the reference's script: progress lines start with
``twopass:``, a failing command ends the reading of its file with
``twopass: Error in file FILE:`` and the command's messages indented by
four blanks, and the exit status is 1 when anything failed.
"""

from __future__ import annotations

import os
from typing import Optional

from halsdk.halcmd.commands import CommandRunner
from halsdk.halcmd.lexer import (
    IniFile,
    SubstitutionError,
    logical_lines,
    tokenize,
)

_FORMS = ("count", "num_chan", "names")
# the reference runs the files as Tcl, where these commands return their
# value instead of printing it: their output is dropped
_SILENT = ("getp", "ptype", "stype", "gets")


class TwopassError(Exception):
    """A problem that ends twopass processing (message as printed)."""


def ini_values(path: str, section: str, key: str) -> list[str]:
    """Every value of ``[section]key`` in an INI file, in order."""
    return IniFile(path).all(section, key)


def is_twopass_ini(path: str) -> bool:
    """True when the INI file has a non-empty ``[HAL]TWOPASS``."""
    return any(ini_values(path, "HAL", "TWOPASS"))


def _excluded(lines: list[str]) -> bool:
    """A ``#NOTWOPASS`` magic comment (blanks and case ignored)."""
    return any("".join(line.split()).lower().startswith("#notwopass")
               for line in lines)


class _Module:
    """The merged ``loadrt`` parameters of one module."""

    def __init__(self, name: str):
        self.name = name
        self.form: Optional[str] = None
        self.count = 0
        self.names: list[str] = []
        self.personality: list[str] = []
        self.debug: Optional[int] = None
        self.other: list[str] = []

    def add(self, words: list[str]) -> None:
        for word in words:
            # read as the module loader does (double quotes removed)
            item, _, value = word.replace('"', "").partition("=")
            if item in _FORMS:
                if self.form is None:
                    self.form = item
                elif self.form != item:
                    # the reference's words (its closing parenthesis
                    # is missing too)
                    raise TwopassError(
                        "loadrt_substitute: cannot mix count=, num_chan= "
                        f"and names= forms (module={self.name}, first "
                        f"used form={self.form}")
            if item in ("count", "num_chan"):
                self.count += _int(value)
            elif item == "names":
                self.names.append(value)
            elif item == "personality":
                self.personality.append(value)
            elif item == "debug":
                self.debug = (self.debug or 0) | _int(value)
            else:
                self.other.append(word)

    def words(self) -> list[str]:
        out = [self.name]
        if self.form in ("count", "num_chan"):
            out.append(f"{self.form}={self.count}")
        elif self.form == "names":
            names = ",".join(self.names)
            if any(ch.isspace() for ch in names):
                names = f'"{names}"'
            out.append("names=" + names)
        if self.personality:
            out.append("personality=" + ",".join(self.personality))
        if self.debug is not None:
            out.append(f"debug={self.debug}")
        return out + self.other


def _discard(text: str) -> None:
    pass


def _int(text: str) -> int:
    try:
        return int(text, 0)
    except ValueError:
        raise TwopassError(f"loadrt: bad number '{text}'") from None


class Twopass:
    """Runs the ``[HAL]HALFILE`` files of an INI file in two passes."""

    def __init__(self, ex: CommandRunner, ini_path: str):
        self.ex = ex
        self.ini_path = ini_path
        options = " ".join(ini_values(ini_path, "HAL", "TWOPASS")).lower()
        self.verbose = "verbose" in options
        self.options = [w for w in ("verbose", "nodelete") if w in options]
        self.files: list[tuple[str, list[str]]] = []
        self.modules: dict[str, _Module] = {}
        self.loaded: set[str] = set()
        self.failures = 0
        if ex.ini is None:
            ex.ini = IniFile(ini_path)

    def say(self, text: str) -> None:
        self.ex.out(text + "\n")

    def note(self, text: str) -> None:
        if self.verbose:
            self.say(f"twopass: {text}")

    # ------------------------------------------------------------ files

    def find(self, name: str) -> str:
        """A HALFILE as the reference finds it: absolute, or relative to
        the INI file's folder."""
        if os.path.isabs(name):
            path = name
        else:
            path = os.path.join(os.path.dirname(self.ini_path) or ".",
                                name)
        if not os.access(path, os.R_OK):
            raise TwopassError(f"twopass:CANNOT FIND FILE FOR:{name}")
        return path

    def prepare(self) -> None:
        for entry in ini_values(self.ini_path, "HAL", "HALFILE"):
            name = entry.split()[0] if entry.split() else entry
            path = self.find(name)
            self.say(f"twopass:found {path}")
            if not path.endswith(".hal"):
                raise TwopassError(f"twopass: {path}: only .hal files are "
                                   "supported by halsdk (no Tcl)")
            with open(path, encoding="utf-8", errors="replace") as f:
                lines = f.readlines()
            if _excluded(lines):
                self.say(f"twopass:Sourcing {path} WITHOUT twopass "
                         "processing")
                verbose, self.ex.verbose = self.ex.verbose, 1
                try:
                    self.ex.run_lines(lines, path, keep_going=True)
                finally:
                    self.ex.verbose = verbose
                continue
            self.files.append((path, lines))

    # ------------------------------------------------------------ passes

    def run(self) -> int:
        """Both passes; returns the exit status (0 or 1)."""
        opts = "" if not self.options else " ".join(self.options)
        self.say(f"twopass:invoked with <{opts}> options")
        try:
            self.note("pass0:BEGIN")
            self.prepare()
            self.source_all(0)
            if self.failures:
                return 1
            self.load_modules()
            self.note("pass0:END")
            self.note("pass1:BEGIN")
            self.source_all(1)
            self.note("pass1:END")
        except TwopassError as exc:
            self.say(str(exc))
            return 1
        return 1 if self.failures else 0

    def source_all(self, passno: int) -> None:
        for path, lines in self.files:
            self.note(f"sourcing: {path}")
            message = self.source(path, lines, passno)
            if message is not None:
                self.failures += 1
                self.say(f"twopass: Error in file {path}:\n    {message}")

    def source(self, path: str, lines: list[str],
               passno: int) -> Optional[str]:
        """One file in one pass; the error message that stopped it."""
        ex = self.ex
        for number, text in logical_lines(lines):
            try:
                words = tokenize(text, ex.ini)
            except SubstitutionError as exc:
                return str(exc)
            if not words:
                continue
            cmd = words[0]
            if passno == 0:
                try:
                    if cmd == "loadrt" and len(words) > 1:
                        self.collect(words[1], words[2:])
                    elif cmd == "loadusr":
                        self.say("twopass:pass0: loadusr "
                                 + " ".join(words[1:]))
                        failed = self.run_words(words, path, number)
                        if failed is not None:
                            return failed
                except TwopassError as exc:
                    return str(exc)
                continue
            if cmd == "loadusr" or (cmd == "loadrt" and len(words) > 1 and
                                    words[1] in self.loaded):
                continue
            failed = self.run_words(words, path, number)
            if failed is not None:
                return failed
        return None

    def run_words(self, words: list[str], path: str,
                  number: int) -> Optional[str]:
        """Run a command; None or its messages (without file:line)."""
        ex = self.ex
        captured: list[str] = []
        saved = ex.err, ex.out, ex.filename, ex.lineno
        ex.err, ex.filename, ex.lineno = captured.append, None, number
        if words[0] in _SILENT:
            ex.out = _discard
        try:
            ok = ex.run_words(words)
        finally:
            ex.err, ex.out, ex.filename, ex.lineno = saved
        if ok:
            # warnings of a successful command are passed on
            for text in captured:
                ex.err(f"{path}:{number}: {text}")
            return None
        return "".join(captured).rstrip("\n")

    def collect(self, module: str, words: list[str]) -> None:
        if module not in self.modules:
            self.modules[module] = _Module(module)
        self.modules[module].add(words)

    def load_modules(self) -> None:
        failed = False
        for module in self.modules.values():
            words = module.words()
            self.note("loadrt " + " ".join(words))
            message = self.run_words(["loadrt"] + words, "", 0)
            if message is not None:
                self.say(f"\ntwopass: load_the_modules cmd=<loadrt "
                         f"{' '.join(words)}>\n{message}\n")
                failed = True
            else:
                self.loaded.add(module.name)
        if failed:
            raise TwopassError("twopass: loading the modules failed")


def run(ex: CommandRunner, ini_path: str) -> int:
    """Twopass-load the ``[HAL]HALFILE`` files of ``ini_path`` with the
    executor ``ex``; returns the exit status (0 or 1)."""
    return Twopass(ex, ini_path).run()
