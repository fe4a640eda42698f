"""The tool table: the reference's text file format and the toolchanger model.

A tool table maps *pockets* to :class:`ToolEntry` records.  Pocket 0 is
always the spindle.  How the other pockets are numbered depends on the kind
of toolchanger:

* **nonrandom** (manual changers, turrets, racks): every tool has a home
  pocket it always returns to.  On load the tools are put into internal
  slots 1, 2, 3, ... in file order; the pocket written in the file is kept
  in :attr:`ToolEntry.pocket` and written back on save.  A tool change
  *copies* the home slot to pocket 0.  Tool 0 means "no tool".
* **random** (carousels): the pocket numbers are the changer's real ones
  (0..1000, 0 being the spindle) and a tool change *swaps* pocket 0 with the
  selected pocket.  Tool 0 is an ordinary tool.

File format, one tool a line, words in any order separated by blanks::

    T1 P17 Z12.5 D6 ;6 mm end mill

``T`` tool number and ``P`` pocket (both required, integers), ``X Y Z A B C
U V W`` offsets, ``D`` diameter, ``I`` front angle, ``J`` back angle (real
numbers), ``Q`` orientation (integer 0..9); everything after ``;`` is the
comment.  Blank lines and lines holding only a comment are skipped.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from dataclasses import dataclass
from decimal import Decimal
from typing import Optional

from halsdk.atomicfile import write_atomic
from halsdk.errors import HalError

__all__ = ["AXES", "EMPTY", "MAX_RANDOM_POCKET", "ToolEntry", "ToolTable",
           "ToolTableError"]

#: The axis letters of the nine offsets, in :attr:`ToolEntry.offset` order.
AXES = "XYZABCUVW"
#: The largest pocket number of a random toolchanger.
MAX_RANDOM_POCKET = 1000

_REAL_WORDS = {"D": "diameter", "I": "frontangle", "J": "backangle"}
_INT_WORDS = "TPQ"


class ToolTableError(HalError, ValueError):
    """A malformed tool table file or an impossible tool table operation.

    For file errors ``str(e)`` is ``FILE:LINE: message``.
    """

    def __init__(self, message: str, file: str = "", line: int = 0):
        self.message = message
        self.file = file
        self.line = line
        text = f"{file}:{line}: {message}" if file else message
        super().__init__(text)


@dataclass(frozen=True)
class ToolEntry:
    """What the table knows about one tool.

    ``tool`` is -1 for an empty pocket.  ``pocket`` is the pocket number as
    written in the file: on a nonrandom changer the tool's home pocket (also
    for the copy held in the spindle), on a random one the pocket the entry
    is currently in.
    """

    tool: int = -1
    pocket: int = 0
    offset: tuple[float, ...] = (0.0,) * 9
    diameter: float = 0.0
    frontangle: float = 0.0
    backangle: float = 0.0
    orientation: int = 0
    comment: str = ""

    def __post_init__(self) -> None:
        if len(self.offset) != 9:
            raise ValueError("a tool offset has 9 components (X..W)")
        object.__setattr__(self, "offset",
                           tuple(float(v) for v in self.offset))

    @property
    def empty(self) -> bool:
        return self.tool < 0


#: An empty pocket.
EMPTY = ToolEntry()


def _format_number(value: float) -> str:
    """The shortest decimal text that reads back as exactly ``value``
    (never in exponent notation, which other tools may not accept)."""
    text = format(Decimal(repr(float(value))), "f")
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return text or "0"


def _parse_line(text: str, file: str, line: int) -> Optional[ToolEntry]:
    """One line of a tool table file; ``None`` for blank/comment lines."""
    data, sep, comment = text.partition(";")
    words = data.split()
    if not words:
        return None
    seen: dict[str, str] = {}
    ints: dict[str, int] = {}
    reals: dict[str, float] = {}
    for word in words:
        letter, number = word[0].upper(), word[1:]
        if letter not in AXES and letter not in _REAL_WORDS \
                and letter not in _INT_WORDS:
            raise ToolTableError(f"unknown word '{word}' (expected T, P, "
                                 "X..W, D, I, J, Q or ;comment)", file, line)
        if letter in seen:
            raise ToolTableError(f"word {letter} given twice ('{seen[letter]}'"
                                 f" and '{word}')", file, line)
        seen[letter] = word
        if not number:
            raise ToolTableError(f"word {letter} has no number", file, line)
        if letter in _INT_WORDS:
            try:
                ints[letter] = int(number)
            except ValueError:
                raise ToolTableError(f"{letter} needs an integer, not "
                                     f"'{number}'", file, line) from None
        else:
            try:
                value = float(number)
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                raise ToolTableError(f"{letter} needs a number, not "
                                     f"'{number}'", file, line)
            reals[letter] = value
    for required, name in (("T", "tool number"), ("P", "pocket number")):
        if required not in ints:
            raise ToolTableError(f"missing {required} word ({name})",
                                 file, line)
    if ints["T"] < 0:
        raise ToolTableError(f"tool number {ints['T']} is negative",
                             file, line)
    orientation = ints.get("Q", 0)
    if not 0 <= orientation <= 9:
        raise ToolTableError(f"orientation Q{orientation} is not in 0..9",
                             file, line)
    return ToolEntry(
        tool=ints["T"], pocket=ints["P"],
        offset=tuple(reals.get(a, 0.0) for a in AXES),
        diameter=reals.get("D", 0.0), frontangle=reals.get("I", 0.0),
        backangle=reals.get("J", 0.0), orientation=orientation,
        comment=comment.strip() if sep else "")


def format_entry(entry: ToolEntry, pocket: int) -> str:
    """The file line of ``entry`` with pocket number ``pocket``."""
    parts = [f"T{entry.tool}", f"P{pocket}"]
    parts += [f"{a}{_format_number(v)}" for a, v in zip(AXES, entry.offset)
              if v != 0.0]
    for letter, field in _REAL_WORDS.items():
        value = getattr(entry, field)
        if value != 0.0:
            parts.append(f"{letter}{_format_number(value)}")
    if entry.orientation:
        parts.append(f"Q{entry.orientation}")
    if entry.comment:
        # one line per tool: line breaks inside a comment become blanks
        parts.append(";" + " ".join(entry.comment.splitlines()).strip())
    return " ".join(parts)


class ToolTable:
    """The tool table and the toolchanger model of the machine.

    Pocket numbers in this API (``pocket_of``, ``entry``, ``prepare``) are
    the *internal* ones: on a random changer the real pocket numbers, on a
    nonrandom one the slot index given at load time (1, 2, ... in file
    order), with 0 the spindle in both.
    """

    def __init__(self, random: bool = False,
                 path: Optional[str] = None) -> None:
        self.random = bool(random)
        #: the file :meth:`save` writes by default (set by :meth:`load`)
        self.path = path
        self._slots: dict[int, ToolEntry] = {}
        self._spindle = EMPTY if random else ToolEntry(tool=0)
        #: internal pocket chosen by the last :meth:`prepare`, or None
        self.selected_pocket: Optional[int] = None
        #: tool number chosen by the last :meth:`prepare`, or None
        self.selected_tool: Optional[int] = None
        #: nonrandom: the slot the spindle's tool was loaded from (0: none)
        self.current_pocket = 0

    # -- loading and saving ------------------------------------------------

    @classmethod
    def load(cls, path: str, random: bool = False) -> ToolTable:
        """Read a tool table file; raises :class:`ToolTableError`
        (``FILE:LINE: what``) on bad content."""
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            raise ToolTableError(f"cannot read tool table: {e.strerror}",
                                 path, 0) from None
        except UnicodeDecodeError:
            raise ToolTableError("tool table is not UTF-8 text",
                                 path, 0) from None
        return cls.parse(text, random=random, file=path, path=path)

    @classmethod
    def parse(cls, text: str, random: bool = False, file: str = "<string>",
              path: Optional[str] = None) -> ToolTable:
        """Build a table from file content (``file`` names it in errors)."""
        table = cls(random=random, path=path)
        tools: dict[int, int] = {}
        pockets: dict[int, int] = {}
        for number, raw in enumerate(text.splitlines(), start=1):
            entry = _parse_line(raw, file, number)
            if entry is None:
                continue
            if entry.tool in tools:
                raise ToolTableError(f"tool {entry.tool} already defined at "
                                     f"line {tools[entry.tool]}", file,
                                     number)
            tools[entry.tool] = number
            if random:
                if not 0 <= entry.pocket <= MAX_RANDOM_POCKET:
                    raise ToolTableError(
                        f"pocket P{entry.pocket} is not in 0.."
                        f"{MAX_RANDOM_POCKET}", file, number)
                if entry.pocket in pockets:
                    raise ToolTableError(
                        f"pocket P{entry.pocket} already used at line "
                        f"{pockets[entry.pocket]}", file, number)
                pockets[entry.pocket] = number
                if entry.pocket == 0:
                    table._spindle = entry
                else:
                    table._slots[entry.pocket] = entry
            else:
                if entry.tool == 0:
                    raise ToolTableError("T0 means 'no tool' on a nonrandom "
                                         "toolchanger and may not appear in "
                                         "the table", file, number)
                if entry.pocket <= 0:
                    raise ToolTableError(
                        f"pocket P{entry.pocket} must be positive on a "
                        "nonrandom toolchanger (0 is the spindle)", file,
                        number)
                table._slots[len(table._slots) + 1] = entry
        return table

    def lines(self) -> list[str]:
        """The file lines :meth:`save` writes."""
        if self.random:
            items = sorted(self.pockets())
        else:
            items = [(e.pocket, e) for _, e in sorted(self._slots.items())]
        return [format_entry(e, p) for p, e in items if not e.empty]

    def save(self, path: Optional[str] = None) -> None:
        """Write the table atomically (temporary file, then rename).

        Nonrandom: every tool in its home pocket (the spindle is only a
        copy).  Random: what each pocket holds, the spindle as ``P0``.
        """
        path = path or self.path
        if not path:
            raise ToolTableError("no file to save the tool table to")
        text = "".join(line + "\n" for line in self.lines())
        write_atomic(path, text)

    def _autosave(self) -> None:
        if self.path:
            self.save()

    # -- lookups -----------------------------------------------------------

    @property
    def spindle(self) -> ToolEntry:
        """The entry in pocket 0 (the tool in the spindle)."""
        return self._spindle

    @property
    def tool_in_spindle(self) -> int:
        """The loaded tool number; 0 when none (also for an empty spindle
        of a random changer)."""
        return max(self._spindle.tool, 0)

    def pockets(self) -> Iterator[tuple[int, ToolEntry]]:
        """(internal pocket, entry) for the spindle and every slot."""
        yield 0, self._spindle
        yield from sorted(self._slots.items())

    def tools(self) -> list[int]:
        """The tool numbers in the table (not counting the spindle copy of
        a nonrandom changer)."""
        found = [e.tool for _, e in sorted(self._slots.items())
                 if not e.empty]
        if self.random and not self._spindle.empty:
            found.insert(0, self._spindle.tool)
        return found

    def pocket_of(self, tool: int) -> Optional[int]:
        """The internal pocket of ``tool``, None when it is not in the table.

        Nonrandom: the home slot (never 0), and 0 for T0 ("no tool").
        Random: where the tool is now, 0 when it is in the spindle.
        """
        if self.random:
            if not self._spindle.empty and self._spindle.tool == tool:
                return 0
        elif tool == 0:
            return 0
        for pocket, entry in self._slots.items():
            if entry.tool == tool and not entry.empty:
                return pocket
        return None

    def entry(self, pocket: int) -> ToolEntry:
        """The entry in internal pocket ``pocket`` (EMPTY if nothing)."""
        self._check_pocket(pocket)
        if pocket == 0:
            return self._spindle
        return self._slots.get(pocket, EMPTY)

    def file_pocket(self, pocket: int) -> int:
        """The pocket number the hardware knows for internal ``pocket``:
        the file's pocket on a nonrandom changer, the same on a random."""
        if self.random or pocket == 0:
            return pocket
        return self.entry(pocket).pocket

    def set_entry(self, pocket: int, entry: ToolEntry) -> None:
        """Replace the entry of internal pocket ``pocket`` (no save)."""
        self._check_pocket(pocket)
        if self.random:
            entry = dataclasses.replace(entry, pocket=pocket)
        elif pocket != 0 and entry.pocket <= 0:
            old = self._slots.get(pocket)
            home = old.pocket if old is not None and old.pocket > 0 \
                else pocket
            entry = dataclasses.replace(entry, pocket=home)
        if pocket == 0:
            self._spindle = entry
        elif entry.empty:
            self._slots.pop(pocket, None)
        else:
            self._slots[pocket] = entry

    def _check_pocket(self, pocket: int) -> None:
        limit = MAX_RANDOM_POCKET if self.random else len(self._slots)
        if not isinstance(pocket, int) or not 0 <= pocket <= limit:
            raise ToolTableError(f"pocket {pocket} is not in 0..{limit}")

    def _require(self, tool: int) -> int:
        pocket = self.pocket_of(tool)
        if pocket is None:
            raise ToolTableError(f"tool {tool} is not in the tool table")
        return pocket

    # -- the toolchanger operations ------------------------------------------

    def prepare(self, tool: int) -> int:
        """``Txxx``: select ``tool`` for the next change; returns its
        internal pocket (0 for T0 on a nonrandom changer)."""
        pocket = self._require(tool)
        self.selected_pocket = pocket
        self.selected_tool = tool
        return pocket

    def change(self) -> int:
        """``M6``: load the selected tool; returns the file pocket it came
        from.  Nonrandom copies the selected slot to pocket 0 (T0 empties
        the spindle); random swaps pocket 0 and the selected pocket and
        saves the table."""
        if self.selected_pocket is None:
            raise ToolTableError("M6 without a prepared tool (T word)")
        pocket = self.selected_pocket
        from_pocket = self.file_pocket(pocket)
        if self.random:
            if pocket != 0:
                new = self.entry(pocket)
                old = self._spindle
                self.set_entry(0, new)
                self.set_entry(pocket, old)
            self.current_pocket = 0
            self._autosave()
        else:
            self._load_slot(pocket)
        self.selected_pocket = None
        self.selected_tool = None
        return from_pocket

    def _load_slot(self, pocket: int) -> None:
        self._spindle = self.entry(pocket) if pocket else ToolEntry(tool=0)
        self.current_pocket = pocket

    def set_tool_number(self, tool: int) -> None:
        """``M61 Qn``: declare that ``tool`` is in the spindle, without any
        hardware move.  Nonrandom: pocket 0 becomes a copy of the tool's
        home slot (Q0: empty).  Random: the table is corrected by swapping
        the tool's pocket with pocket 0."""
        pocket = self._require(tool)
        if self.random:
            if pocket != 0:
                new, old = self.entry(pocket), self._spindle
                self.set_entry(0, new)
                self.set_entry(pocket, old)
                self._autosave()
        else:
            self._load_slot(pocket)

    def set_offsets(self, tool: int, *,
                    offset: Optional[tuple[float, ...]] = None,
                    diameter: Optional[float] = None,
                    frontangle: Optional[float] = None,
                    backangle: Optional[float] = None,
                    orientation: Optional[int] = None,
                    comment: Optional[str] = None) -> int:
        """``G10 L1/L10/L11``: change the data of ``tool``; returns the
        internal pocket updated, then saves.

        Nonrandom: the tool's home slot, copied to pocket 0 too when it is
        the loaded tool.  Random: pocket 0 when it is loaded, else its
        pocket; nothing else is touched.
        """
        if not self.random and tool == 0:
            raise ToolTableError("T0 is 'no tool' on a nonrandom "
                                 "toolchanger and has no offsets")
        pocket = self._require(tool)
        if orientation is not None and not 0 <= orientation <= 9:
            raise ToolTableError(f"orientation {orientation} is not in 0..9")
        old = self.entry(pocket)
        entry = dataclasses.replace(
            old,
            offset=old.offset if offset is None else tuple(offset),
            diameter=old.diameter if diameter is None else diameter,
            frontangle=old.frontangle if frontangle is None else frontangle,
            backangle=old.backangle if backangle is None else backangle,
            orientation=(old.orientation if orientation is None
                         else orientation),
            comment=old.comment if comment is None else comment)
        self.set_entry(pocket, entry)
        if not self.random and self.current_pocket == pocket:
            self._spindle = entry
        self._autosave()
        return pocket

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ToolTable):
            return NotImplemented
        return (self.random == other.random
                and list(self.pockets()) == list(other.pockets()))

    def __repr__(self) -> str:
        kind = "random" if self.random else "nonrandom"
        return f"<ToolTable {kind} {len(self._slots)} tools>"
