"""A canon that prints canonical commands in the text format of the
reference's standalone interpreter (``rs274``).

Every call is one line: a running number (5 wide), the block's N word
(``N.....`` when it has none) and the call, e.g.::

        7 N..... STRAIGHT_FEED(10.0000, 5.0000, 0.0000, 0.0000, 0.0000, 0.0000)

Positions are printed as the reference's interpreter hands them to its
canon: in *program* coordinates (work offsets, G92 and the tool length
offset not applied) and program units (G20/G21), X Y Z A B C.  Our
interpreter works in machine coordinates, so :class:`TextCanon` turns each
position back with the offsets in force when the command is emitted.
Calls that have no machine meaning (comments, ``START_CHANGE()``, feed
mode changes ...) come from the interpreter as :class:`~.canon.Trace`
commands, which it emits only to a canon with ``reference_calls = True``.
"""

from __future__ import annotations

from typing import Any, Callable, Optional

from . import canon as C

PLANE_NAMES = {17: "XY", 18: "XZ", 19: "YZ"}
#: plane -> (first, second, normal) axis indices of ARC_FEED's arguments
ARC_AXES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}


def f4(value: float) -> str:
    """``%.4f``, the reference's number format for most arguments.

    The value is first rounded to 10 decimals: our positions come back
    from machine units (inches) with an error in the last bits, which
    would otherwise decide a tie such as 9.20625 the other way than the
    reference, which computes in program units."""
    return f"{round(value, 10):.4f}"


class TextCanon(C.Canon):
    """Prints each canonical command as the reference's ``rs274`` does.

    ``write`` receives each finished line (with its newline).  Set
    :attr:`interp` to the interpreter that emits to this canon before the
    first command (positions are converted with its offsets).
    """

    reference_calls = True

    def __init__(self, write: Callable[[str], Any]) -> None:
        self.write = write
        self.interp: Any = None
        self.count = 0

    # -- output ------------------------------------------------------------
    def call(self, text: str) -> None:
        """Print one numbered call."""
        self.count += 1
        self.write(f"{self.count:5d} {self._nword()} {text}\n")

    def _nword(self) -> str:
        block = getattr(self.interp, "line_block", None)
        number: Optional[float] = getattr(block, "line_number", None)
        if number is None:
            return "N....."
        return f"N{int(number):<5d}"

    # -- conversions -------------------------------------------------------
    def _k(self, axis: int) -> float:
        return float(self.interp._k(axis))

    def _prog(self, pose: Any) -> list[float]:
        """Machine ``pose`` -> program coordinates in program units."""
        it = self.interp
        d = it._unrotated(list(pose))
        return [(d[i] - it.g92[i]) / self._k(i) for i in range(9)]

    def _units(self, values: Any) -> list[float]:
        """Machine-unit lengths (offsets) -> program units."""
        return [values[i] / self._k(i) for i in range(9)]

    def _six(self, values: list[float]) -> str:
        return ", ".join(f4(v) for v in values[:6])

    def start(self) -> None:
        """The calls the reference prints before the program."""
        it = self.interp
        self.call("USE_LENGTH_UNITS(CANON_UNITS_"
                  f"{'MM' if it.program_metric else 'INCHES'})")
        self.call(f"SET_G5X_OFFSET({it.coord_index}, "
                  f"{self._six(self._units(it._g5x()))})")
        self.call(f"SET_G92_OFFSET({self._six(self._units(it.g92))})")
        self.call(f"SET_XY_ROTATION({it.rotation:.4f})")
        self.call("SET_FEED_REFERENCE(CANON_XYZ)")
        self.call("ON_RESET()")

    # -- dispatch ----------------------------------------------------------
    def emit(self, command: C.Command) -> None:
        handler = getattr(self, "_" + type(command).__name__, None)
        if handler is not None:
            handler(command)

    def _Trace(self, c: C.Trace) -> None:
        if c.kind == "print":
            self.write(c.text + "\n")
        else:
            self.call(c.text)

    def _StraightTraverse(self, c: C.StraightTraverse) -> None:
        self.call(f"STRAIGHT_TRAVERSE({self._six(self._prog(c.end))})")

    def _StraightFeed(self, c: C.StraightFeed) -> None:
        self.call(f"STRAIGHT_FEED({self._six(self._prog(c.end))})")

    def _ArcFeed(self, c: C.ArcFeed) -> None:
        end = self._prog(c.end)
        a1, a2, n = ARC_AXES[c.plane]
        centre = list(c.end)
        centre[a1], centre[a2] = c.center
        cp = self._prog(centre)
        self.call(f"ARC_FEED({f4(end[a1])}, {f4(end[a2])}, {f4(cp[a1])}, "
                  f"{f4(cp[a2])}, {c.turn}, {f4(end[n])}, {f4(end[3])}, "
                  f"{f4(end[4])}, {f4(end[5])})")

    def _SyncedFeed(self, c: C.SyncedFeed) -> None:
        self.call(f"START_SPEED_FEED_SYNC({c.pitch / self._k(0):f},0)")
        self.call(f"STRAIGHT_FEED({self._six(self._prog(c.end))})")
        self.call("STOP_SPEED_FEED_SYNCH()")

    def _Probe(self, c: C.Probe) -> None:
        self.call("TURN_PROBE_ON()")
        self.call(f"STRAIGHT_PROBE({self._six(self._prog(c.end))})")
        self.call("TURN_PROBE_OFF()")

    def _Dwell(self, c: C.Dwell) -> None:
        self.call(f"DWELL({f4(c.seconds)})")

    def _SpindleOn(self, c: C.SpindleOn) -> None:
        way = "CLOCKWISE" if c.direction > 0 else "COUNTERCLOCKWISE"
        self.call(f"START_SPINDLE_{way}(0)")

    def _SpindleOff(self, c: C.SpindleOff) -> None:
        self.call("STOP_SPINDLE_TURNING(0)")

    def _SelectTool(self, c: C.SelectTool) -> None:
        self.call(f"SELECT_TOOL({c.tool})")

    def _ChangeTool(self, c: C.ChangeTool) -> None:
        self.call(f"CHANGE_TOOL({c.pocket})")

    def _ChangeToolNumber(self, c: C.ChangeToolNumber) -> None:
        self.call(f"CHANGE_TOOL_NUMBER({c.pocket})")

    def _UseToolLengthOffset(self, c: C.UseToolLengthOffset) -> None:
        o = self._units(c.offset)
        self.call("USE_TOOL_LENGTH_OFFSET("
                  f"{f4(o[0])} {f4(o[1])} {f4(o[2])}, "
                  f"{f4(o[3])} {f4(o[4])} {f4(o[5])}, "
                  f"{f4(o[6])} {f4(o[7])} {f4(o[8])})")

    def _SetToolTableEntry(self, c: C.SetToolTableEntry) -> None:
        offsets = " ".join(f4(v) for v in c.offset)
        self.call(f"SET_TOOL_TABLE_ENTRY({c.pocket}, {c.tool}, {offsets}, "
                  f"{f4(c.frontangle)}, {f4(c.backangle)}, "
                  f"{c.orientation})")

    def _SetG5xOffset(self, c: C.SetG5xOffset) -> None:
        self.call(f"SET_G5X_OFFSET({c.index}, "
                  f"{self._six(self._units(c.offset))})")

    def _SetG92Offset(self, c: C.SetG92Offset) -> None:
        self.call(f"SET_G92_OFFSET({self._six(self._units(c.offset))})")

    def _Coolant(self, c: C.Coolant) -> None:
        if c.kind == "mist":
            self.call("MIST_ON()")
        elif c.kind == "flood":
            self.call("FLOOD_ON()")
        else:
            self.call("MIST_OFF()")
            self.call("FLOOD_OFF()")

    def _SetTermCond(self, c: C.SetTermCond) -> None:
        if c.mode == "exact_path":
            self.call("SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)")
        elif c.mode == "exact_stop":
            self.call("SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)")
        else:
            k = self._k(0)
            p = (c.p or 0.0) / k
            q = (c.q or 0.0) / k
            self.call(f"SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, {p:f})")
            self.call(f"SET_NAIVECAM_TOLERANCE({f4(q)})")

    def _SetPlane(self, c: C.SetPlane) -> None:
        self.call(f"SELECT_PLANE(CANON_PLANE_{PLANE_NAMES[c.plane]})")

    def _SyncDout(self, c: C.SyncDout) -> None:
        self.call(f"{'SET' if c.on else 'CLEAR'}_MOTION_OUTPUT_BIT({c.index})")

    def _DoutNow(self, c: C.DoutNow) -> None:
        self.call(f"{'SET' if c.on else 'CLEAR'}_AUX_OUTPUT_BIT({c.index})")

    def _SyncAout(self, c: C.SyncAout) -> None:
        self.call(f"SET_MOTION_OUTPUT_VALUE({c.index},{c.value:f})")

    def _AoutNow(self, c: C.AoutNow) -> None:
        self.call(f"SET_AUX_OUTPUT_VALUE({c.index},{c.value:f})")

    def _ProgramPause(self, c: C.ProgramPause) -> None:
        self.call("PROGRAM_STOP()")

    def _OptionalPause(self, c: C.OptionalPause) -> None:
        self.call("OPTIONAL_PROGRAM_STOP()")

    def _ProgramEnd(self, c: C.ProgramEnd) -> None:
        self.call("PROGRAM_END()")

    def _Message(self, c: C.Message) -> None:
        self.call(f'MESSAGE("{c.text}")')
