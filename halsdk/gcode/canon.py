"""Canonical machine commands emitted by the G-code interpreter.

Each command is a small frozen dataclass. Positions are 9-tuples
``(x, y, z, a, b, c, u, v, w)`` in *machine* coordinates and machine units:
work offsets (G54..G59.3), G92 offsets and the tool length offset are already
applied, so the machine layer can hand them to motion unchanged. ``line`` is
the 1-based source line the command came from (0 when not tied to a line).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

Pose = tuple[float, float, float, float, float, float, float, float, float]


@dataclass(frozen=True)
class Command:
    """Base of all canonical commands."""


@dataclass(frozen=True)
class StraightTraverse(Command):
    """Rapid move (G0, rapid parts of G28/G30 and canned cycles)."""
    end: Pose
    line: int = 0


@dataclass(frozen=True)
class StraightFeed(Command):
    """Linear move at ``feed`` machine units per minute."""
    end: Pose
    feed: float
    line: int = 0


@dataclass(frozen=True)
class ArcFeed(Command):
    """Circular/helical move in ``plane`` (17, 18 or 19).

    ``center`` holds the two in-plane machine coordinates of the arc centre
    (X/Y for G17, Z/X for G18, Y/Z for G19). ``turn`` is positive for
    counter-clockwise (G3) and negative for clockwise (G2); its magnitude is
    1 for a partial arc plus the extra full turns asked for with P.
    """
    end: Pose
    center: tuple[float, float]
    plane: int
    turn: int
    feed: float
    line: int = 0


@dataclass(frozen=True)
class SyncedFeed(Command):
    """Spindle-synchronised move (G33): ``pitch`` units per revolution."""
    end: Pose
    pitch: float
    line: int = 0


@dataclass(frozen=True)
class Probe(Command):
    """Probing move; ``kind`` is '38.2', '38.3', '38.4' or '38.5'."""
    end: Pose
    kind: str
    feed: float
    line: int = 0


@dataclass(frozen=True)
class Dwell(Command):
    seconds: float
    line: int = 0


@dataclass(frozen=True)
class SetFeedRate(Command):
    """Feed rate in machine units per minute (units-per-minute mode)."""
    feed: float
    line: int = 0


@dataclass(frozen=True)
class SetFeedMode(Command):
    """``'inverse_time'`` (G93) or ``'units_per_minute'`` (G94)."""
    mode: str
    line: int = 0


@dataclass(frozen=True)
class SpindleSpeed(Command):
    rpm: float
    line: int = 0


@dataclass(frozen=True)
class SpindleOn(Command):
    """Start the spindle; ``direction`` is +1 (M3) or -1 (M4)."""
    direction: int
    rpm: float
    line: int = 0


@dataclass(frozen=True)
class SpindleOff(Command):
    line: int = 0


@dataclass(frozen=True)
class SelectTool(Command):
    """Prepare ``tool`` found in ``pocket`` (T word)."""
    tool: int
    pocket: int
    line: int = 0


@dataclass(frozen=True)
class ChangeTool(Command):
    """Load the prepared tool from ``pocket`` into the spindle (M6)."""
    tool: int
    pocket: int
    line: int = 0


@dataclass(frozen=True)
class ChangeToolNumber(Command):
    """Declare ``tool`` (from ``pocket``) to be in the spindle (M61)."""
    tool: int
    pocket: int
    line: int = 0


@dataclass(frozen=True)
class UseToolLengthOffset(Command):
    """Tool length offset, 9 axes, machine units (G43/G43.1/G49)."""
    offset: Pose
    line: int = 0


@dataclass(frozen=True)
class SetToolTableEntry(Command):
    """Tool table pocket update (G10 L1/L10/L11)."""
    pocket: int
    tool: int
    offset: Pose
    diameter: float
    frontangle: float
    backangle: float
    orientation: int
    line: int = 0


@dataclass(frozen=True)
class SetG5xOffset(Command):
    """Active work coordinate system ``index`` (1=G54 .. 9=G59.3)."""
    index: int
    offset: Pose
    line: int = 0


@dataclass(frozen=True)
class SetG92Offset(Command):
    offset: Pose
    line: int = 0


@dataclass(frozen=True)
class Coolant(Command):
    """``kind`` is 'mist' (M7), 'flood' (M8) or 'off' (M9)."""
    kind: str
    line: int = 0


@dataclass(frozen=True)
class SetTermCond(Command):
    """Path control: 'exact_path' (G61), 'exact_stop' (G61.1), 'blend' (G64)."""
    mode: str
    p: Optional[float] = None
    q: Optional[float] = None
    line: int = 0


@dataclass(frozen=True)
class SetPlane(Command):
    plane: int
    line: int = 0


@dataclass(frozen=True)
class SyncDout(Command):
    """Digital output ``index`` set with the next motion (M62/M63)."""
    index: int
    on: bool
    line: int = 0


@dataclass(frozen=True)
class DoutNow(Command):
    """Digital output ``index`` set immediately (M64/M65)."""
    index: int
    on: bool
    line: int = 0


@dataclass(frozen=True)
class SyncAout(Command):
    """Analog output set with the next motion (M67)."""
    index: int
    value: float
    line: int = 0


@dataclass(frozen=True)
class AoutNow(Command):
    """Analog output set immediately (M68)."""
    index: int
    value: float
    line: int = 0


@dataclass(frozen=True)
class WaitInput(Command):
    """Wait on an input (M66). ``digital`` picks P (True) or E (False);
    ``mode`` 0 immediate, 1 rise, 2 fall, 3 high, 4 low; ``timeout`` in s.
    The machine layer reports the value via ``Interpreter.input_result``."""
    index: int
    digital: bool
    mode: int
    timeout: float
    line: int = 0


@dataclass(frozen=True)
class ProgramPause(Command):
    """M0."""
    line: int = 0


@dataclass(frozen=True)
class OptionalPause(Command):
    """M1 (honoured only when optional stop is enabled)."""
    line: int = 0


@dataclass(frozen=True)
class ProgramEnd(Command):
    """M2 (``rewind`` False) or M30 (``rewind`` True)."""
    rewind: bool = False
    line: int = 0


@dataclass(frozen=True)
class Message(Command):
    text: str
    line: int = 0


@dataclass(frozen=True)
class UserMCode(Command):
    """A user M-code (M100-M199): run the executable ``path`` with the
    block's P and Q (-1.0 when the block has none, as the reference) and
    wait for it to finish, with the machine at rest."""
    code: int
    path: str
    p: float = -1.0
    q: float = -1.0
    line: int = 0


class Canon:
    """Receiver of canonical commands; subclasses override :meth:`emit`."""

    def emit(self, command: Command) -> None:
        raise NotImplementedError


@dataclass
class RecordingCanon(Canon):
    """A canon that keeps every command in :attr:`commands` (tests, previews)."""
    commands: list[Command] = field(default_factory=list)

    def emit(self, command: Command) -> None:
        self.commands.append(command)

    def of_type(self, *types: type) -> list[Command]:
        """The recorded commands that are instances of ``types``."""
        return [c for c in self.commands if isinstance(c, types)]


@dataclass(frozen=True)
class Trace(Command):
    """A call of the reference's standalone interpreter that has no
    machine meaning (``COMMENT(...)``, ``START_CHANGE()``,
    ``SET_FEED_MODE(0, 0)`` ...), already in its text form.

    Emitted only to canons whose ``reference_calls`` attribute is true
    (:class:`halsdk.gcode.canon_text.TextCanon`); ``kind`` is 'call' for a
    numbered canonical call and 'print' for text printed as is
    (``(PRINT, ...)`` comments).
    """
    text: str
    kind: str = "call"
    line: int = 0


@dataclass(frozen=True)
class LogOpen(Command):
    """``(LOGOPEN,name)`` (``append`` False: the file is emptied) or
    ``(LOGAPPEND,name)``; ``path`` is the name as written."""
    path: str
    append: bool = False
    line: int = 0


@dataclass(frozen=True)
class Log(Command):
    """``(LOG,text)``: ``text`` with its parameters already expanded."""
    text: str
    line: int = 0


@dataclass(frozen=True)
class LogClose(Command):
    """``(LOGCLOSE)``."""
    line: int = 0


@dataclass(frozen=True)
class ProbeOpen(Command):
    """``(PROBEOPEN name)``: where the following probe moves stopped
    goes to ``path`` (emptied first), one line each."""
    path: str
    line: int = 0


@dataclass(frozen=True)
class ProbeClose(Command):
    """``(PROBECLOSE)``."""
    line: int = 0
