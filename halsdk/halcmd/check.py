"""Netlist check of a HAL file: ``halcmd --check FILE``.

The file is read by the normal executor, but against a throwaway private
instance that is removed at the end: ``loadrt`` loads the components (so
their real pins, parameters and functions are known), while nothing
runs: ``start`` is skipped, no ``loadusr`` program is started and
``save`` writes nothing.  The process must not already use another HAL
instance (the CLI runs in its own process).

Each finding is printed as ``file:line: error: message`` or
``file:line: warning: message``, with the line of the command that caused
it.  Severities:

errors (exit status 1)
    a command that fails (unknown name, bad value, wrong arguments ...);
    a second writer (out pin) on a signal; a pin whose type differs from
    its signal; an out pin and an io pin on the same signal.
    The reference HAL refuses these, so the file does not work as written.

warnings (exit status 0 when there are only warnings)
    a signal with readers but no writer that is never given a value with
    ``sets``; a signal with no pins; an input pin of a loaded component
    that is neither connected nor set with ``setp``; a function never
    added to a thread; a function reading a signal before the function
    writing it in the same thread (one period of delay, sometimes
    wanted); a name breaking the naming conventions (only lowercase
    letters, digits, ``.``, ``-`` and ``_``); a name longer than the
    reference's 47 characters (halsdk accepts it, the reference would
    not); a ``loadusr`` that the checker does not run (pins of that
    program are then unknown: a missing pin after it is a warning).
"""

from __future__ import annotations

import os
import re
import sys
from dataclasses import dataclass
from typing import Optional

from halsdk.errors import HalError, Rule
from halsdk.halcmd.commands import (
    ARROWS,
    REFERENCE_NAME_LEN,
    CommandError,
    CommandRunner,
)
from halsdk.types import Direction, type_word

_NAME_OK = re.compile(r"[a-z0-9._-]+")
# commands that would run something or write files: not executed
_SKIPPED = ("start", "stop", "loadusr", "waitusr", "unloadusr", "save",
            "setexact_for_test_suite_only")
_DIR = {Direction.IN: "in", Direction.OUT: "out", Direction.IO: "io"}
# the refusals of a link that _explain details
_LINK_RULES = (Rule.TYPE_MISMATCH, Rule.SECOND_WRITER, Rule.WRITER_AND_IO)


@dataclass(frozen=True)
class Finding:
    """One problem found: where, how bad, what."""

    file: str
    line: int
    severity: str       # "error" or "warning"
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: {self.severity}: {self.message}"


Loc = tuple[str, int]


class CheckRunner(CommandRunner):
    """An executor that records where objects come from and what went
    wrong, without running threads or programs."""

    def __init__(self, hal, ini: Optional[str] = None):
        super().__init__(hal, out=_discard, err=self._capture,
                         keep_going=True, ini=ini, register=False,
                         warn_long_names=False)
        self.findings: list[Finding] = []
        self.origin: dict[tuple[str, str], Loc] = {}
        self.linked_at: dict[str, Loc] = {}
        self.setp_pins: set[str] = set()
        self.sets_signals: set[str] = set()
        self.addf_at: dict[tuple[str, str], tuple[int, Loc]] = {}
        self.loadusr_at: Optional[Loc] = None
        self._captured: list[str] = []
        self._specific: Optional[Loc] = None
        self._serial = 0
        self._refused: Optional[Rule] = None

    # ------------------------------------------------------------ records

    @property
    def loc(self) -> Loc:
        return (self.filename or "<command line>", self.lineno)

    def add(self, severity: str, message: str,
            loc: Optional[Loc] = None) -> None:
        file, line = loc or self.loc
        self.findings.append(Finding(file, line, severity, message))

    def _capture(self, text: str) -> None:
        self._captured.append(text)

    def error(self, message: str) -> None:     # no file:line prefix here
        self._captured.append(message + "\n")

    def created(self, kind: str, names: list[str]) -> None:
        """Record where names come from; one finding per rule and kind
        for the names of one command."""
        long_names, bad_names = [], []
        for name in names:
            self.origin.setdefault((kind, name), self.loc)
            if len(name) > REFERENCE_NAME_LEN:
                long_names.append(name)
            if not _NAME_OK.fullmatch(name):
                bad_names.append(name)
        if long_names:
            self.add("warning", f"{kind} name(s) longer than the "
                     f"reference's {REFERENCE_NAME_LEN} characters: "
                     + _listed(long_names))
        if bad_names:
            self.add("warning", f"{kind} name(s) breaking the naming "
                     "conventions (lowercase letters, digits, '.', '-' and "
                     "'_' only): " + _listed(bad_names))

    # ------------------------------------------------------------ running

    def run_words(self, words: list[str]) -> bool:
        saved = self._captured, self._specific     # source nests
        self._captured, self._specific = [], None
        try:
            ok = super().run_words(words)
            captured, specific = self._captured, self._specific
        finally:
            self._captured, self._specific = saved
        text = "; ".join(line.strip() for line in "".join(
            captured).splitlines() if line.strip())
        if not ok and specific != self.loc and text:
            severity = "error"
            if self.loadusr_at is not None and re.search(
                    r"[Pp]in '[^']*' (does not exist|not found)", text):
                severity = "warning"
                text += (" (perhaps a pin of the program started by "
                         f"loadusr at line {self.loadusr_at[1]})")
            self.add(severity, text)
        elif ok and text:
            self.add("warning", text)
        return ok

    def dispatch(self, words: list[str]) -> None:
        cmd = words[0]
        if cmd in _SKIPPED:
            if cmd == "loadusr":
                prog = next((w for w in words[1:]
                             if not w.startswith("-")), "?")
                self.loadusr_at = self.loc
                self.add("warning", f"loadusr '{prog}' is not run by the "
                         "checker; the pins it makes are unknown")
            return
        super().dispatch(words)

    # ------------------------------------------------------------ commands

    def failure(self, command: str, exc: HalError, variant=None,
                **fields) -> CommandError:
        self._refused = exc.rule
        return super().failure(command, exc, variant, **fields)

    def cmd_net(self, args: list[str]) -> None:
        signame = args[0]
        names = [a for a in args[1:] if a not in ARROWS]
        pins = [p for p in (self.hal.find("pin", n) for n in names)
                if p is not None]
        sig = self.hal.find("signal", signame)
        self._linking(signame, sig, pins, super().cmd_net, args)
        for pin in pins:
            self.linked_at.setdefault(pin.name, self.loc)

    def _link(self, pin_name: str, sig_name: str, what: str) -> None:
        pin = self.hal.find("pin", pin_name)
        sig = self.hal.find("signal", sig_name)
        self._linking(sig_name, sig, [pin] if pin is not None else [],
                      super()._link, pin_name, sig_name, what)
        if pin is not None:
            self.linked_at.setdefault(pin.name, self.loc)

    def _linking(self, signame: str, sig, pins: list, run, *args) -> None:
        """Run a linking command; when the core refuses it for a type or
        a writer conflict, explain which pins conflict."""
        self._refused = None
        try:
            run(*args)
        except CommandError:
            if self._refused in _LINK_RULES and (sig is not None
                                                 or pins):
                self._explain(signame, sig, pins)
            raise

    def _explain(self, signame: str, sig, new_pins: list) -> None:
        """The type and writer conflicts of a refused link, all of them."""
        pins = {p.name: p for p in (sig.pins if sig is not None else [])}
        for pin in new_pins:
            pins.setdefault(pin.name, pin)
        if new_pins:
            stype = sig.type if sig is not None else new_pins[0].type
            for pin in new_pins:
                if pin.type != stype:
                    self._specific = self.loc
                    self.add("error", f"type mismatch: pin '{pin.name}' is "
                             f"{type_word(pin.type)}, signal '{signame}' "
                             f"is {type_word(stype)}")
        outs = sorted(n for n, p in pins.items()
                      if p.direction == Direction.OUT)
        ios = sorted(n for n, p in pins.items()
                     if p.direction == Direction.IO)
        if len(outs) > 1:
            self._specific = self.loc
            self.add("error", f"signal '{signame}' has more than one "
                     f"writer: {', '.join(repr(n) for n in outs)}")
        if outs and ios:
            self._specific = self.loc
            self.add("error", f"signal '{signame}' has an out pin "
                     f"({', '.join(repr(n) for n in outs)}) and io pin(s) "
                     f"({', '.join(repr(n) for n in ios)})")

    def cmd_source(self, args: list[str]) -> None:
        # unlike a real run, keep reading a sourced file after a failure
        self.run_file(args[0], keep_going=True)

    def cmd_sets(self, args: list[str]) -> None:
        super().cmd_sets(args)
        self.sets_signals.add(args[0])

    def cmd_setp(self, args: list[str], name: str = "setp") -> None:
        super().cmd_setp(args, name)
        item = self.hal.find("pin", args[0])
        if item is not None:
            self.setp_pins.add(item.name)

    def cmd_addf(self, args: list[str]) -> None:
        super().cmd_addf(args)
        self._serial += 1
        self.addf_at[(args[0], args[1])] = (self._serial, self.loc)

    # ------------------------------------------------------------ analysis

    def analyse(self) -> None:
        """Findings about the final netlist."""
        self._signals()
        self._inputs()
        self._functions()
        self._order()

    def _where(self, kind: str, name: str) -> Loc:
        return self.origin.get((kind, name), (self.filename or "?", 0))

    def _signals(self) -> None:
        for sig in self.hal.items("signal"):
            loc = self._where("signal", sig.name)
            if not sig.pins:
                self.add("warning", f"signal '{sig.name}' has no pins", loc)
            elif not (sig.writers or sig.bidirs) and \
                    sig.name not in self.sets_signals:
                readers = ", ".join(repr(p.name) for p in sig.pins)
                self.add("warning", f"signal '{sig.name}' has reader(s) "
                         f"({readers}) but no writer and is never set "
                         "with sets", loc)

    def _inputs(self) -> None:
        for pin in self.hal.items("pin"):
            loc = self.origin.get(("pin", pin.name))
            if loc is None or pin.direction != Direction.IN or pin.linked or \
                    pin.name in self.setp_pins:
                continue
            self.add("warning", f"input pin '{pin.name}' is not connected "
                     "and never set with setp", loc)

    def _functions(self) -> None:
        for funct in self.hal.items("function"):
            if funct.users == 0:
                self.add("warning", f"function '{funct.name}' is never "
                         "added to a thread",
                         self._where("function", funct.name))

    def _order(self) -> None:
        functs: dict[int, list[str]] = {}
        for funct in self.hal.items("function"):
            functs.setdefault(funct.owner_id, []).append(funct.name)
        threads = [(t.name, {f: i for i, f in enumerate(t.functions)})
                   for t in self.hal.items("thread")]
        for sig in self.hal.items("signal"):
            writers = [p for p in sig.pins
                       if p.direction in (Direction.OUT, Direction.IO)]
            if len(writers) != 1:
                continue
            wf = _function_of(writers[0], functs)
            if wf is None:
                continue
            for reader in sig.pins:
                if reader.direction != Direction.IN:
                    continue
                rf = _function_of(reader, functs)
                if rf is None or rf == wf:
                    continue
                for tname, pos in threads:
                    if rf in pos and wf in pos and pos[rf] < pos[wf]:
                        later = max(self.addf_at.get((rf, tname), (0, None)),
                                    self.addf_at.get((wf, tname), (0, None)),
                                    key=lambda x: x[0])[1]
                        self.add("warning", f"in thread '{tname}', "
                                 f"'{rf}' reads signal '{sig.name}' before "
                                 f"'{wf}' writes it (one period late)",
                                 later or self._where("signal", sig.name))


def _function_of(pin, functs: dict[int, list[str]]) -> Optional[str]:
    """The function that uses a pin: the only function of its owner, or
    the one whose name (or a dotted prefix of it) prefixes the pin's."""
    candidates = functs.get(pin.owner_id, [])
    if len(candidates) == 1:
        return candidates[0]
    best: list[tuple[int, str]] = []
    for fname in candidates:
        parts = fname.split(".")
        for n in range(len(parts), 0, -1):
            prefix = ".".join(parts[:n])
            if pin.name.startswith(prefix + "."):
                best.append((len(prefix), fname))
                break
    if not best:
        return None
    best.sort(reverse=True)
    if len(best) > 1 and best[0][0] == best[1][0]:
        return None         # ambiguous: several functions share the pin
    return best[0][1]


def _listed(names: list[str], most: int = 4) -> str:
    shown = ", ".join(repr(n) for n in names[:most])
    return shown + (f" and {len(names) - most} more"
                    if len(names) > most else "")


def _discard(text: str) -> None:
    pass


def check_file(path: str, ini: Optional[str] = None) -> list[Finding]:
    """Check a HAL file; returns the findings in file and line order.

    Uses a private instance created and removed here, so the calling
    process must not be using another one.
    """
    from halsdk import Hal
    files: dict[str, int] = {path: 0}
    with Hal(instance=f"check-{os.getpid()}", create=True) as hal:
        ex = CheckRunner(hal, ini=ini)
        ex.run_file(path)
        if ex._captured and not ex.findings:
            # the file itself could not be opened
            ex.add("error", "".join(ex._captured).strip(), (path, 0))
        ex.analyse()
        findings = ex.findings
    for f in findings:
        files.setdefault(f.file, len(files))
    return sorted(findings, key=lambda f: (files[f.file], f.line))


def main(path: str, ini: Optional[str] = None) -> int:
    """Print the findings of ``path``; 1 when there is an error."""
    if not os.path.exists(path):
        print(f"{path}:0: error: cannot open the file", file=sys.stderr)
        return 1
    findings = check_file(path, ini)
    for finding in findings:
        print(finding)
    errors = sum(f.severity == "error" for f in findings)
    warnings = len(findings) - errors
    print(f"{path}: {errors} error(s), {warnings} warning(s)",
          file=sys.stderr)
    return 1 if errors else 0
