"""The data of the Show page (halshow): listings, details, live values and
the changes, over the public layer only.

Every listing is made of :meth:`halsdk.Hal.snapshot` records (a
consistent picture taken under the instance lock); live values are read
through handles (:meth:`halsdk.Hal.find`), which is cheap enough to do
for the visible rows many times a second; every change goes through
halcmd's :class:`~halsdk.halcmd.CommandRunner` as a list of words, so a
name is never parsed as HAL language (or anything else) and a refusal
comes back in halcmd's own words.

Nothing here is asynchronous: :class:`halsdk.web.app` runs these calls
on one worker thread, one at a time.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import Any, Optional

from halsdk.errors import HalError
from halsdk.hal import Hal
from halsdk.halcmd import CommandRunner, Quit, logical_lines
from halsdk.halcmd.commands import ARG_COUNTS
from halsdk.halcmd.lexer import SubstitutionError, split_words, strip_comment
from halsdk.halcmd.show import value_text
from halsdk.types import Direction, dir_word, type_word

#: the kinds of the tree, in the page's order, and the snapshot kind of each
KINDS = {"components": "component", "pins": "pin", "params": "param",
         "signals": "signal", "functions": "function", "threads": "thread"}
#: the kinds whose values are live
VALUE_KINDS = ("pin", "param", "signal")

#: halcmd commands that only read: all the command line allows read-only
READ_COMMANDS = frozenset({"show", "list", "getp", "gets", "ptype", "stype",
                           "save", "status", "help", "echo", "unecho"})
#: halcmd commands the web command line never runs, with why: they start
#: programs, read files of the server or wait for a program, none of which
#: a page may ask for
REFUSED_COMMANDS = {
    "loadusr": "starts a program on the server",
    "waitusr": "waits for a program of the server",
    "source": "reads a file of the server",
}

_GLOB = re.compile(r"([*?\[])")


class Refused(Exception):
    """A request the workbench does not run (read-only, a refused
    command): its message says why; the server answers 403."""


def exact(name: str) -> str:
    """A glob pattern that matches ``name`` only."""
    return _GLOB.sub(r"[\1]", name)


def value_json(type_: int, value: Any) -> str:
    """A value as the page shows it: as halcmd's ``getp`` prints it."""
    return value_text(type_, value)


def _dir(d: int) -> str:
    return dir_word(d).strip()


class _PageRunner(CommandRunner):
    """halcmd's runner for the words of a page's change: a command and
    its arguments, never the ``NAME = VALUE`` form of the language (a
    signal may be named ``=``: ``sets = 1`` sets it)."""

    def dispatch(self, words: list[str]) -> None:
        cmd = words[0]
        if len(words) == 3 and words[1] == "=" and cmd in ARG_COUNTS:
            least, most = ARG_COUNTS[cmd]
            if least <= 2 and (most is None or most >= 2):
                getattr(self, "cmd_" + cmd)(words[1:])
                return
        super().dispatch(words)


class Show:
    """The Show page's view of one instance.

    :param hal: the instance (attached or hosted).
    :param read_only: refuse every change (:class:`Refused`).
    """

    def __init__(self, hal: Hal, *, read_only: bool = False):
        self.hal = hal
        self.read_only = read_only
        self._handles: dict[str, Any] = {}

    # ------------------------------------------------------------ listing

    def _snap(self, kind: str, pattern: Any = "*",
              sort: bool = True) -> list[Any]:
        """Records of a kind (their types differ by kind: :class:`Any`)."""
        return list(self.hal.snapshot(kind, pattern, sort=sort))

    def _one(self, kind: str, name: str) -> Optional[Any]:
        found = [r for r in self._snap(kind, exact(name), sort=False)
                 if r.name == name]
        return found[0] if found else None

    def info(self) -> dict[str, Any]:
        return {"instance": self.hal.instance, "read_only": self.read_only,
                "lock_level": self.hal.lock_level,
                "counts": self.hal.counts()}

    def tree(self) -> dict[str, Any]:
        """Every component, pin, param, signal, function and thread, by
        name, with what the tree and the search show of each."""
        return {
            **self.info(),
            "components": [
                {"name": c.name, "id": c.id, "realtime": c.realtime,
                 "ready": c.ready, "pid": c.pid, "alive": c.alive,
                 "dead": c.dead}
                for c in self._snap("component")],
            "pins": [
                {"name": p.name, "type": type_word(p.type),
                 "dir": _dir(p.direction), "owner": p.owner,
                 "signal": p.signal, "value": value_json(p.type, p.value)}
                for p in self._snap("pin")],
            "params": [
                {"name": p.name, "type": type_word(p.type),
                 "dir": _dir(p.direction), "owner": p.owner,
                 "value": value_json(p.type, p.value)}
                for p in self._snap("param")],
            "signals": [
                {"name": s.name, "type": type_word(s.type),
                 "value": value_json(s.type, s.value),
                 "writers": s.writers, "readers": s.readers,
                 "bidirs": s.bidirs}
                for s in self._snap("signal")],
            "functions": [
                {"name": f.name, "owner": f.owner, "users": f.users,
                 "realtime": f.realtime}
                for f in self._snap("function")],
            "threads": [
                {"name": t.name, "period": t.period, "running": t.running,
                 "functions": list(t.functions)}
                for t in self._snap("thread")],
        }

    def _linked(self, signal: Any) -> dict[str, list[dict[str, str]]]:
        """The pins of a signal record, as writers, readers and bidirs."""
        owners = {p.name: p.owner for p in self._snap(
            "pin", [exact(lp.name) for lp in signal.pins] or [""])}
        groups: dict[str, list[dict[str, str]]] = {
            "writers": [], "readers": [], "bidirs": []}
        group = {Direction.OUT: "writers", Direction.IN: "readers",
                 Direction.IO: "bidirs"}
        for lp in signal.pins:
            groups[group.get(Direction(lp.direction), "readers")].append(
                {"name": lp.name, "dir": _dir(lp.direction),
                 "owner": owners.get(lp.name, "")})
        return groups

    def detail(self, kind: str, name: str) -> dict[str, Any]:
        """What the detail view shows of one item; ``{"kind": ...,
        "name": ..., "exists": False}`` when there is none."""
        if kind not in KINDS.values():
            raise ValueError(f"unknown kind {kind!r}")
        rec = self._one(kind, name)
        out: dict[str, Any] = {"kind": kind, "name": name,
                               "exists": rec is not None}
        if rec is None:
            return out
        if kind in ("pin", "param"):
            out.update(type=type_word(rec.type), dir=_dir(rec.direction),
                       value=value_json(rec.type, rec.value),
                       owner=rec.owner, alias_of=rec.alias_of)
        if kind == "pin":
            out["signal"] = rec.signal
            if rec.signal:
                sig = self._one("signal", rec.signal)
                if sig is not None:
                    out.update(self._linked(sig))
        elif kind == "signal":
            out.update(type=type_word(rec.type),
                       value=value_json(rec.type, rec.value),
                       **self._linked(rec))
        elif kind == "component":
            out.update(id=rec.id, realtime=rec.realtime, ready=rec.ready,
                       pid=rec.pid, alive=rec.alive, dead=rec.dead)
            for key, what in (("pins", "pin"), ("params", "param"),
                              ("functions", "function")):
                out[key] = [r.name for r in self._snap(what)
                            if r.owner == name]
        elif kind == "function":
            out.update(owner=rec.owner, users=rec.users,
                       realtime=rec.realtime, reentrant=rec.reentrant,
                       time=rec.time, tmax=rec.tmax,
                       threads=[t.name for t in self._snap("thread")
                                if name in t.functions])
        elif kind == "thread":
            out.update(period=rec.period, running=rec.running,
                       functions=list(rec.functions), time=rec.time,
                       tmax=rec.tmax, cycles=rec.cycles,
                       overruns=rec.overruns)
        return out

    # ------------------------------------------------------------ values

    def values(self, keys: Iterable[str]) -> dict[str, Optional[str]]:
        """The values of ``kind:name`` keys (pin, param or signal), as
        the page shows them; None for an item that does not exist (or a
        key that names none)."""
        out: dict[str, Optional[str]] = {}
        for key in keys:
            kind, _, name = key.partition(":")
            if kind not in VALUE_KINDS:
                out[key] = None
                continue
            item = self._handles.get(key)
            try:
                if item is None or not item.exists:
                    item = self.hal.find(kind, name)
                    if item is None:
                        self._handles.pop(key, None)
                        out[key] = None
                        continue
                    self._handles[key] = item
                out[key] = value_json(item.type, item.value)
            except HalError:            # deleted meanwhile
                self._handles.pop(key, None)
                out[key] = None
        return out

    # ------------------------------------------------------------ changes

    def run_words(self, words: list[str]) -> dict[str, Any]:
        """Run one halcmd command given as words (never parsed again):
        ``{"ok", "output", "error"}``, with halcmd's output and its own
        words when it refuses.  :class:`Refused` when read-only."""
        self._allowed(words)
        out: list[str] = []
        err: list[str] = []
        runner = _PageRunner(self.hal, out=out.append, err=err.append,
                             register=False)
        try:
            ok = runner.run_words(list(words))
        except Quit:
            ok = True
        return {"ok": ok, "output": "".join(out), "error": "".join(err)}

    def command(self, text: str) -> dict[str, Any]:
        """Run the lines of halcmd's command line; stops at the first
        line that fails.  Every line is checked (read-only, refused
        commands) before any runs.

        The words are not substituted: ``$NAME`` and ``[SECTION]KEY``
        stay as they are typed, since the server's environment (which
        may hold secrets) and INI file are not the page's."""
        try:
            lines = [words for _, line in logical_lines(
                text.splitlines(True))
                if (words := split_words(strip_comment(
                    line.split("\0", 1)[0])))]
        except SubstitutionError as exc:      # an unterminated quote
            return {"ok": False, "output": "", "error": f"{exc}\n"}
        for words in lines:
            self._allowed(words)
        out: list[str] = []
        err: list[str] = []
        runner = CommandRunner(self.hal, out=out.append, err=err.append,
                               register=False)
        ok = True
        try:
            for words in lines:
                if not runner.run_words(words):
                    ok = False
                    break
        except Quit:
            pass
        return {"ok": ok, "output": "".join(out), "error": "".join(err)}

    def _allowed(self, words: list[str]) -> None:
        if not words:
            raise Refused("no command")
        cmd = words[0]
        if cmd in REFUSED_COMMANDS:
            raise Refused(f"{cmd}: not from the web workbench (it "
                          f"{REFUSED_COMMANDS[cmd]}); use halcmd")
        if cmd == "save" and len(words) > 2:
            raise Refused("save FILE: not from the web workbench (it "
                          "writes a file of the server); use halcmd")
        if self.read_only and (cmd not in READ_COMMANDS
                               or (len(words) == 3 and words[1] == "=")):
            raise Refused(f"{cmd}: read-only: this workbench was started "
                          "with --read-only and changes nothing")
