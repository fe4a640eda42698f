"""The RS274/NGC interpreter: turns evaluated blocks into canonical commands.

Conventions
-----------
* Positions inside the interpreter and in every emitted command are machine
  coordinates in machine units (``units``); program values are converted
  from G20/G21 units on entry.  Rotary axes (A, B, C) are never scaled.
* program position = machine position - G5x offset - G92 offset - TLO.
* Work offsets #5221.., G92 offsets #5211.., G28/G30 homes #5161/#5181 and
  tool data #5400.. hold machine units; probe results #5061.. hold the
  probed point in the active program coordinates and program units.
* ``tools`` is the interpreter's own copy of the tool table (the reference
  keeps one in interp and one in IO); M6, M61 and G10 L1/L10/L11 update it
  the way the developer manual's tool section describes, and the matching
  canon commands let the machine layer update its copy.
* Cutter radius compensation (G41/G42 with D = tool number, radius from
  the tool table) covers lines and arcs in G17 and G18; see cutter_radius
  for what is refused.
* G84 is the floating-chuck tap of the reference manual: feed in, spindle
  reversed for a feed out at the same rate, no spindle synchronisation;
  it needs the spindle on clockwise (M3).  G88 feeds in, dwells, stops the
  spindle and pauses the program so the operator can withdraw the tool by
  hand, then restarts the spindle; it needs the spindle on.
* G10 L2/L20 R rotates the coordinate system in XY about its origin.
* G76 threads: passes of growing depth, each a spindle-synchronised feed.
* Not supported (clear error): G87.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from typing import Any, Callable, Optional

from . import canon as C
from ._fast import fast_move
from .block import Block, code_key
from .cutter_radius import CutterComp, CutterRadiusError
from .messages import PLANE_NAME, arc_radius_differs, unused_word, zero_radius_arc
from .modal import AXIS_USERS_GROUP0, ModalState, group_codes
from .nurbs import polyline as nurbs_polyline
from .program import Program

_DEBUG_PARAM = re.compile(r"#\s*<([^>]*)>|#\s*(\d+)")


def last_comment(text: str) -> Optional[tuple[str, str]]:
    """The last ``( )`` comment of a line as ``(kind, text)``: kind is
    'msg', 'debug', 'print', 'log', 'logopen', 'logappend', 'logclose',
    'py' or '' (plain); see :func:`comment_kind`.  ``;`` ends the scan (the
    reference does not report ``;`` comments)."""
    found: Optional[tuple[str, str]] = None
    i = 0
    while i < len(text):
        char = text[i]
        if char == ";":
            break
        if char == "(":
            end = text.find(")", i + 1)
            if end < 0:
                break
            found = comment_kind(text[i + 1:end])
            i = end + 1
            continue
        i += 1
    return found


#: the active comments with a comma, as the reference recognises them
_ACTIVE = ("msg", "debug", "print", "log", "logopen", "logappend", "py")


def comment_kind(body: str) -> tuple[str, str]:
    """The kind and text of the comment ``body`` (between the brackets),
    as the reference reads it: leading white space is skipped, then the
    keyword and its comma must follow exactly (any case: ``( msg,x)``
    but not ``(MSG ,x)`` or ``(M S G,x)``); ``logclose`` must be the
    whole comment.  The text after the comma is kept as written; a plain
    comment (kind '') loses its leading white space only."""
    text = body.lstrip()
    head, comma, rest = text.partition(",")
    kind = head.lower()
    if comma and kind in _ACTIVE:
        return kind, rest
    if text.lower() == "logclose":
        return "logclose", ""
    return "", text


def probe_comment(text: str) -> Optional[tuple[str, str]]:
    """``('open', name)`` for a plain comment ``PROBEOPEN name`` (upper
    case, the name after the white space kept as written), ``('close',
    '')`` for ``PROBECLOSE``, else None (the reference's rules)."""
    if text.startswith("PROBEOPEN"):
        return "open", text[len("PROBEOPEN"):].lstrip()
    if text.startswith("PROBECLOSE"):
        return "close", ""
    return None


AXES = "xyzabcuvw"
ROTARY = (3, 4, 5)
ZERO9: C.Pose = (0.0,) * 9
#: plane -> (first axis, second axis, normal axis, first/second centre words)
PLANES = {170: (0, 1, 2, "ij"), 180: (2, 0, 1, "ki"), 190: (1, 2, 0, "jk")}
COORD_CODES = (540, 550, 560, 570, 580, 590, 591, 592, 593)
CANNED = (730, 810, 820, 830, 840, 850, 860, 880, 890)
UNSUPPORTED_MOTION = {870: "G87"}


def _rotate(x: float, y: float, degrees: float) -> tuple[float, float]:
    """(x, y) turned counter-clockwise by ``degrees``."""
    t = math.radians(degrees)
    c, s = math.cos(t), math.sin(t)
    return x * c - y * s, x * s + y * c


def _bezier(points: list[tuple[float, float]], t: float
            ) -> tuple[float, float]:
    """The point at ``t`` of the Bezier curve of ``points`` (de Casteljau)."""
    pts = list(points)
    while len(pts) > 1:
        pts = [((1 - t) * a[0] + t * b[0], (1 - t) * a[1] + t * b[1])
               for a, b in zip(pts, pts[1:])]
    return pts[0]


#: Letters every block may hold (the others need a code that uses them).
ALWAYS_ALLOWED = frozenset(AXES + "fstno")


def _pose(values: Any) -> C.Pose:
    return tuple(map(float, values))  # type: ignore[return-value]


class Interpreter:
    """Executes :class:`~halsdk.gcode.block.Block` objects one at a time."""

    def __init__(self, params: Any, tools: Any, canon: C.Canon, *,
                 random_toolchanger: bool = False, units: str = "mm",
                 program_units: Optional[str] = None,
                 ini: Optional[Callable[[str, str], Optional[str]]] = None
                 ) -> None:
        program_units = program_units or units
        for value in (units, program_units):
            if value not in ("mm", "inch"):
                raise ValueError(
                    f"units must be 'mm' or 'inch', not {value!r}")
        self.params = params
        self.tools = tools
        self.canon = canon
        #: ``ini(SECTION, KEY)``: the INI value behind ``#<_ini[s]k>``
        self.ini = ini
        #: ``user_m(number)``: the executable of a user M-code M100-M199
        #: or None (a machine sets it; without it they are unknown)
        self.user_m: Optional[Callable[[int], Optional[str]]] = None
        #: ``hal_value(name)``: the value behind ``#<_hal[name]>`` or None
        #: (a machine sets it; rs274 has no HAL, as the reference's)
        self.hal_value: Optional[Callable[[str], Optional[float]]] = None
        #: emit the reference's informational calls (COMMENT, START_CHANGE
        #: ...) as Trace commands: only for canons that ask for them
        self.ref = bool(getattr(canon, "reference_calls", False))
        self.random = random_toolchanger
        self.machine_metric = units == "mm"
        self.modal = ModalState(units=210 if program_units == "mm" else 200)
        if self.ref:
            self.modal.retract = 990    # the reference starts in G99
            self.modal.motion = 800     # and in G80
        self.pos = [0.0] * 9
        self.tlo = [0.0] * 9
        self.g92 = [0.0] * 9
        if params.get(5210) == 1:
            self.g92 = [params.get(5211 + i) for i in range(9)]
        index = int(params.get(5220)) or 1
        self.modal.coord_system = COORD_CODES[min(max(index, 1), 9) - 1]
        self.params.set(5220, index)
        self.feed = 0.0
        #: the last F number as written (the feed in program units)
        self.feed_value = 0.0
        self.speed = 0.0
        self.current_tool = -1 if self.random else 0
        spindle = getattr(tools, "spindle", None)
        if spindle is not None and spindle.tool >= 0:
            self.current_tool = int(spindle.tool)
        self.selected_tool = -1
        self.selected_pocket = -1
        self.diameter_mode = False
        #: #<_task>: 1 when the interpreter runs a machine's programs (the
        #: task controller sets it), 0 for rs274 and previews
        self.task = False
        #: M48-M53 (rs274): feed and speed override, adaptive feed and
        #: feed hold enabled
        self.override_enables = {"feed": True, "speed": True,
                                 "adaptive": False, "hold": True}
        self._previous_motion = 10
        self._sync: Optional[float] = None      # G76: pitch being synced
        self._spline_pq = (0.0, 0.0)            # G5: the last P, Q
        #: REMAP= codes and the [PYTHON] plugin (halsdk.gcode.remap)
        self.remap: Any = None
        #: G5.2: the control points so far (machine position, weight)
        #: and the order
        self._nurbs_points: Optional[list[tuple[list[float], float]]] = None
        self._nurbs_order = 3
        #: the program being run (for M73: its call level)
        self._program: Any = None
        #: M70 state and the M73 state with its call level
        self._saved: Optional[dict[str, Any]] = None
        self._autosaved: list[tuple[int, dict[str, Any]]] = []
        self.cycle_il: Optional[float] = None
        self.blend: tuple[Optional[float], Optional[float]] = (None, None)
        self.cycle: dict[str, float] = {}
        self.line = 0
        self.ended = False
        self.line_block: Optional[Block] = None
        self.comp = CutterComp(canon.emit)
        params.set_predefined(self._predefined)

    # -- units and coordinates -------------------------------------------
    @property
    def program_metric(self) -> bool:
        return self.modal.units == 210

    def _k(self, axis: int = 0) -> float:
        """Factor program units -> machine units for ``axis``."""
        if axis in ROTARY or self.program_metric == self.machine_metric:
            return 1.0
        return 25.4 if self.machine_metric else 1 / 25.4

    def _len(self, value: float) -> float:
        return value * self._k()

    @property
    def coord_index(self) -> int:
        return COORD_CODES.index(self.modal.coord_system) + 1

    def _g5x(self, index: int = 0) -> list[float]:
        base = 5201 + 20 * (index or self.coord_index)
        return self.params.numbered(base, 9)

    @property
    def rotation(self) -> float:
        """The XY rotation of the active coordinate system (degrees,
        G10 L2 R): its parameter follows the nine offsets."""
        return float(self.params.get(5210 + 20 * self.coord_index))

    def _unrotated(self, machine: list[float]) -> list[float]:
        """``machine`` less the G5x offset and the TLO, turned back by the
        rotation: G92-shifted program coordinates."""
        g5x = self._g5x()
        d = [machine[i] - g5x[i] - self.tlo[i] for i in range(9)]
        angle = self.rotation
        if angle:
            d[0], d[1] = _rotate(d[0], d[1], -angle)
        return d

    def program_position(self) -> list[float]:
        """Current position in program coordinates, machine units.

        program = rotate(machine - G5x - TLO, -R) - G92: the reference's
        order (the rotation turns about the G5x origin)."""
        d = self._unrotated(self.pos)
        return [d[i] - self.g92[i] for i in range(9)]

    def _to_machine(self, prog: list[float]) -> list[float]:
        g5x = self._g5x()
        v = [prog[i] + self.g92[i] for i in range(9)]
        angle = self.rotation
        if angle:
            v[0], v[1] = _rotate(v[0], v[1], angle)
        return [v[i] + g5x[i] + self.tlo[i] for i in range(9)]

    def _axis_words(self, block: Block) -> list[str]:
        return [a for a in AXES if a in block.words]

    def _target(self, block: Block, g53: bool = False) -> list[float]:
        """The machine end point of a move from the block's axis words."""
        if g53:
            end = list(self.pos)
            for i, a in enumerate(AXES):
                if a in block.words:
                    end[i] = block.words[a] * self._k(i) + self.tlo[i]
            return end
        angle = self.rotation
        if angle:
            prog = self.program_position()
        else:
            # program_position() and _to_machine() with one reading of
            # the offsets (the same arithmetic, no rotation)
            g5x, g92, tlo, pos = self._g5x(), self.g92, self.tlo, self.pos
            prog = [pos[i] - g5x[i] - g92[i] - tlo[i] for i in range(9)]
        incremental = self.modal.distance == 910
        words = block.words
        k = self._k()
        diameter = self.diameter_mode
        for i, a in enumerate(AXES):
            if a in words:
                value = words[a] * (1.0 if i in ROTARY else k)
                if i == 0 and diameter:
                    value /= 2      # G7: X words are diameters
                prog[i] = prog[i] + value if incremental else value
        if angle:
            return self._to_machine(prog)
        return [prog[i] + g5x[i] + g92[i] + tlo[i] for i in range(9)]

    def _emit(self, command: C.Command) -> None:
        if not self.comp.hold(command):
            self.canon.emit(command)

    def _trace(self, text: str, kind: str = "call") -> None:
        """A reference-only call (see :class:`canon.Trace`)."""
        if self.ref:
            self._emit(C.Trace(text, kind, self.line))

    def _last_comment(self, block: Block) -> Optional[tuple[str, str]]:
        """The last comment of the line as :func:`last_comment` gives it;
        None when there is none or when it was Python code (a ``;py,``
        line, a ``(py,...)`` comment), which this runs."""
        if self._py_line(block):
            return None
        found = last_comment(block.text)
        if found is not None and found[0] == "py":
            self._py_comment(found[1], block)
            return None
        return found

    def _comment_trace(self, block: Block) -> None:
        """The last comment of the line, as the reference reports it."""
        found = self._last_comment(block)
        if found is None:
            return
        kind, text = found
        if kind == "":
            self._trace(f'COMMENT("{text}")')
        elif kind == "msg":
            self._trace(f'MESSAGE("{text}")')
        elif kind == "debug":
            self._trace(f'MESSAGE("{self._substitute(text)}")')
        elif kind == "print":
            self._trace(self._substitute(text), "print")
        elif kind == "log":
            self._trace(f'LOG("{self._substitute(text)}")')
        elif kind == "logclose":
            self._trace("LOGCLOSE()")
        else:                       # logopen, logappend: the name as is
            self._trace(f'{kind.upper()}("{text}")')

    @staticmethod
    def inert_comments(text: str) -> bool:
        """True if the line ``text``, of plain comments only, is one that
        :meth:`execute` does nothing with but name it the current line,
        when :meth:`quiet_comments` holds: no ``;py,`` line, and its last
        comment is neither an active one nor PROBEOPEN/PROBECLOSE (see
        :meth:`_comment_canon`).  The program's control flow does not
        hand out the blocks of such lines (``_flow.run``)."""
        if text.startswith(";py,"):
            return False
        found = last_comment(text)
        return found is None or (found[0] == ""
                                 and probe_comment(found[1]) is None)

    def quiet_comments(self) -> bool:
        """Whether a block of plain comments does nothing now (see
        :meth:`inert_comments` and :meth:`execute`): no REMAP, not the
        reference's output (its COMMENT calls), no M73 restore pending."""
        return self.remap is None and not self.ref and not self._autosaved

    def _comment_canon(self, block: Block) -> None:
        """The file comments of the line on a machine (see
        :func:`last_comment` and :func:`probe_comment`): LOG* and PROBE*
        canon commands, which the machine's executor carries out; and the
        Python comments (:meth:`_py_comment`)."""
        found = self._last_comment(block)
        if found is None:
            return
        kind, text = found
        line = self.line
        if kind == "log":
            self._emit(C.Log(self._substitute(text), line))
        elif kind in ("logopen", "logappend"):
            self._emit(C.LogOpen(text, kind == "logappend", line))
        elif kind == "logclose":
            self._emit(C.LogClose(line))
        elif kind == "":
            probe = probe_comment(text)
            if probe is not None:
                self._emit(C.ProbeOpen(probe[1], line) if probe[0] == "open"
                           else C.ProbeClose(line))

    def _py_line(self, block: Block) -> bool:
        """A line that starts with ``;py,`` (nothing before it, lower
        case) runs the Python statement after the comma; True if so."""
        if not block.text.startswith(";py,"):
            return False
        self._py_comment(block.text[4:], block)
        return True

    def _py_comment(self, code: str, block: Block) -> None:
        """Run ``;py,code`` or ``(py,code)`` in the namespace of the
        ``[PYTHON]`` plugin (see :func:`halsdk.gcode.remap.py_comment`)."""
        from .remap import py_comment
        py_comment(self, code, block)

    def _substitute(self, text: str) -> str:
        def one(match: re.Match[str]) -> str:
            key: Any = (match.group(1) if match.group(1) is not None
                        else int(match.group(2)))
            try:
                return f"{self.params.get(key):.6f}"
            except Exception:
                return "######"
        return _DEBUG_PARAM.sub(one, text)

    # -- public API ------------------------------------------------------
    @property
    def program(self) -> Any:
        """The program being run (its ``o<name> call`` finds the Python
        subroutines of the interpreter's plugin)."""
        return self._program

    @program.setter
    def program(self, program: Any) -> None:
        self._program = program
        if self.remap is not None and program is not None:
            from .remap import python_sub
            program.python_subs = lambda name: python_sub(self, name)

    def run(self, program: Any) -> None:
        """Execute every block of ``program`` until it ends."""
        self.program = program
        # plain moves run as the program reads them (compiled), unless a
        # subclass executes blocks its own way
        fast = type(self).execute is Interpreter.execute and \
            isinstance(program, Program)
        for block in program.blocks(self) if fast else program.blocks():
            self.execute(block)
            if self.ended:
                break
        self.comp.stop()

    def execute(self, block: Block) -> None:
        """Execute one block in the documented order of execution."""
        # plain moves (most blocks of a CAM program) take a short path,
        # compiled: it does what this method, _target, _straight_feed and
        # _traverse do for them, so a change to those belongs there too
        if self.remap is not None:
            remap = self.remap.first(block)
            if remap is not None:       # REMAP= code (halsdk.gcode.remap)
                self.remap.execute(self, block, remap)
                return
        if not (block.g or block.m or block.words) and not self.ref \
                and block.message is None and not self._autosaved:
            # comments alone (in a subroutine's body, every call): only a
            # LOG, PROBEOPEN or py comment does something
            self.line = block.line
            self.line_block = block
            self._comment_canon(block)
            return
        if fast_move(self, block):
            return
        self._execute(block)

    def _execute(self, block: Block) -> None:
        """:meth:`execute` without the short path of plain moves."""
        self.line = block.line
        self.line_block = block
        gs, ms = group_codes(block)
        self._check(block, gs, ms)
        line = block.line
        ref = self.ref
        self._auto_restore(block)
        if ref:
            self._comment_trace(block)
        elif block.message:
            self._emit(C.Message(block.message, line))
        if block.comments and not ref:
            self._comment_canon(block)
        if 14 in gs:
            self._spindle_mode(block, gs[14])
        if 5 in gs:
            self._feed_mode(block, gs[5])
        if "f" in block.words:
            f = block.words["f"]
            if f < 0:
                raise block.error("Negative f word used", "f")
            self.feed_value = f
            if ref:
                if self.modal.feed_mode != 930:
                    self._trace(f"SET_FEED_RATE({f:.4f})")
                    self.feed = self._len(f)
            elif self.modal.feed_mode == 940:
                self.feed = self._len(f)
                self._emit(C.SetFeedRate(self.feed, line))
        if "s" in block.words:
            s = block.words["s"]
            if s < 0:
                raise block.error("Negative spindle speed used", "s")
            self.speed = s
            if ref:
                self._trace(f"SET_SPINDLE_SPEED(0, {s:.4f})")
            else:
                self._emit(C.SpindleSpeed(s, line))
        if "t" in block.words:
            self._select_tool(block)
        if 5 in ms:
            self._hal_io(block, ms[5])
        if 6 in ms:
            self._tool_change(block, ms[6])
        if 7 in ms:                 # M70-M73 share the spindle's group
            if ms[7] == 190:
                self._orient(block)
            elif ms[7] >= 700:
                self._modal_state(block, ms[7])
            else:
                self._spindle(ms[7], line)
        if 8 in ms:
            code = ms[8]
            self.modal.mist = code == 70 or (self.modal.mist and code != 90)
            self.modal.flood = code == 80 or (self.modal.flood and code != 90)
            self._emit(C.Coolant({70: "mist", 80: "flood", 90: "off"}[code],
                                 line))
        if 9 in ms:
            self._overrides(block, ms[9])
        if 10 in ms:
            self._user_m_code(block, ms[10])
        if gs.get(0) == 40:
            if "p" not in block.words:
                raise block.error("Dwell time missing with g4", "g4")
            p = block.words["p"]
            if p < 0:
                raise block.error("Dwell time missing with g4", "p")
            self._emit(C.Dwell(p, line))
        if 2 in gs:
            if self.comp.active and gs[2] != self.modal.plane:
                raise block.error("Cannot change planes with cutter radius "
                                  "compensation on",
                                  code_key("g", gs[2] / 10))
            self.modal.plane = gs[2]
            self._emit(C.SetPlane(gs[2] // 10, line))
        if 6 in gs:
            self.modal.units = gs[6]
            self._trace("USE_LENGTH_UNITS(CANON_UNITS_"
                        f"{'MM' if gs[6] == 210 else 'INCHES'})")
        if 15 in gs:
            if not ref:
                raise block.error(f"G{gs[15] // 10} (lathe diameter/radius "
                                  "mode) is not supported",
                                  code_key("g", gs[15] / 10))
            diameter = gs[15] == 70
            if diameter != self.diameter_mode:
                self._trace('COMMENT("interpreter: Lathe diameter mode '
                            f'changed to {"diameter" if diameter else "radius"}'
                            '")')
            self.diameter_mode = diameter
        if 7 in gs:
            self._cutter_comp(block, gs[7])
        if 8 in gs:
            self._tool_length(block, gs[8])
        if 12 in gs:
            if ref and gs[12] == self.modal.coord_system:
                self._trace('COMMENT("interpreter: continuing to use same '
                            'coordinate system")')
            else:
                self.modal.coord_system = gs[12]
                self.params.set(5220, self.coord_index)
                self._emit(C.SetG5xOffset(self.coord_index,
                                          _pose(self._g5x()), line))
                if ref:
                    self._emit(C.SetG92Offset(_pose(self.g92), line))
                    self._trace(f"SET_XY_ROTATION({self.rotation:.4f})")
        if 13 in gs:
            self._control(block, gs[13])
        if 3 in gs:
            if gs[3] != self.modal.distance:
                self._trace('COMMENT("interpreter: distance mode changed to '
                            f'{"absolute" if gs[3] == 900 else "incremental"}'
                            '")')
            self.modal.distance = gs[3]
        if 4 in gs:
            if gs[4] != self.modal.arc_distance:
                self._trace('COMMENT("interpreter: IJK distance mode changed '
                            f'to {"absolute" if gs[4] == 901 else "incremental"}'
                            '")')
            self.modal.arc_distance = gs[4]
        if 10 in gs:
            self.modal.retract = gs[10]
            self._trace('COMMENT("interpreter: retract mode set to '
                        f'{"old_z" if gs[10] == 980 else "r_plane"}")')
        g0 = gs.get(0)
        if g0 in (100,):
            self._g10(block)
        elif g0 in (280, 300):
            if self.comp.active:
                raise block.error("Cannot use g28 or g30 with cutter radius comp",
                                  code_key("g", g0 / 10))
            self._go_home(block, g0)
        elif g0 in (281, 301):
            home = list(self.pos)       # the machine position, as stored
            base = 5161 if g0 == 281 else 5181
            for i in range(9):
                self.params.set(base + i, home[i])
        elif g0 in (920, 921, 922, 923):
            self._g92(block, g0)
        self._motion(block, gs)
        if 4 in ms:
            self._stop(ms[4], line)

    # -- M70-M73: saving and restoring the modal state --------------------
    def _state(self) -> dict[str, Any]:
        m = self.modal
        return {"units": m.units, "plane": m.plane, "distance": m.distance,
                "arc_distance": m.arc_distance, "feed_mode": m.feed_mode,
                "feed": self.feed, "feed_value": self.feed_value,
                "speed": self.speed,
                "spindle": m.spindle, "mist": m.mist, "flood": m.flood,
                "coord_system": m.coord_system, "control": m.control,
                "blend": self.blend, "retract": m.retract,
                "diameter": self.diameter_mode}

    def _modal_state(self, block: Block, code: int) -> None:
        if code == 700:
            self._saved = self._state()
        elif code == 710:
            self._saved = None
        elif code == 720:
            if self._saved is None:
                raise block.error("Cannot restore context from invalid stack "
                                  "frame - missing M70/M73?",
                                  "m72")
            self._restore(self._saved, block.line)
        else:
            # in the main program (level 0) it is never restored
            level = getattr(self.program, "call_level", 0)
            self._autosaved.append((level, self._state()))

    def _auto_restore(self, block: Block) -> None:
        """M73: the state comes back when its subroutine has returned."""
        level = getattr(self.program, "call_level", 0)
        while self._autosaved and self._autosaved[-1][0] > level:
            _, state = self._autosaved.pop()
            self._restore(state, block.line)

    def _restore(self, state: dict[str, Any], line: int) -> None:
        """Bring back a saved modal state, in the reference's order, with
        a call for each setting that changed."""
        m = self.modal
        if state["units"] != m.units:
            m.units = state["units"]
            self._trace("USE_LENGTH_UNITS(CANON_UNITS_"
                        f"{'MM' if m.units == 210 else 'INCHES'})")
        if state["feed_mode"] != m.feed_mode:
            self._feed_mode_calls(state["feed_mode"], line)
        elif state["feed"] != self.feed:
            if self.ref:
                self._trace(f"SET_FEED_RATE({state['feed_value']:.4f})")
            else:
                self._emit(C.SetFeedRate(state["feed"], line))
        self.feed, self.feed_value = state["feed"], state["feed_value"]
        if state["speed"] != self.speed:
            self.speed = state["speed"]
            if self.ref:
                self._trace(f"SET_SPINDLE_SPEED(0, {self.speed:.4f})")
            else:
                self._emit(C.SpindleSpeed(self.speed, line))
        if state["spindle"] != m.spindle:
            self._spindle(state["spindle"], line)
        # coolant as one M code (flood counts before mist), as the
        # reference compares it
        def coolant(mist: bool, flood: bool) -> str:
            return "flood" if flood else "mist" if mist else "off"
        saved = coolant(state["mist"], state["flood"])
        if saved != coolant(m.mist, m.flood):
            self._emit(C.Coolant(saved, line))
            m.mist, m.flood = saved == "mist", saved == "flood"
        if state["plane"] != m.plane:
            m.plane = state["plane"]
            self._emit(C.SetPlane(m.plane // 10, line))
        if state["coord_system"] != m.coord_system:
            m.coord_system = state["coord_system"]
            self.params.set(5220, self.coord_index)
            self._emit(C.SetG5xOffset(self.coord_index, _pose(self._g5x()),
                                      line))
            if self.ref:
                self._emit(C.SetG92Offset(_pose(self.g92), line))
                self._trace(f"SET_XY_ROTATION({self.rotation:.4f})")
        if (state["control"], state["blend"]) != (m.control, self.blend):
            m.control, self.blend = state["control"], state["blend"]
            mode = {610: "exact_path", 611: "exact_stop"}.get(m.control,
                                                              "blend")
            self._emit(C.SetTermCond(mode, self.blend[0], self.blend[1],
                                     line))
        if state["distance"] != m.distance:
            m.distance = state["distance"]
            self._trace('COMMENT("interpreter: distance mode changed to '
                        f'{"absolute" if m.distance == 900 else "incremental"}'
                        '")')
        if state["retract"] != m.retract:
            m.retract = state["retract"]
            self._trace('COMMENT("interpreter: retract mode set to '
                        f'{"old_z" if m.retract == 980 else "r_plane"}")')
        if state["arc_distance"] != m.arc_distance:
            m.arc_distance = state["arc_distance"]
            self._trace('COMMENT("interpreter: IJK distance mode changed to '
                        f'{"absolute" if m.arc_distance == 901 else "incremental"}'
                        '")')
        self.diameter_mode = state["diameter"]

    def _feed_mode(self, block: Block, code: int) -> None:
        if code == 950 and not self.ref:
            raise block.error("G95 (feed per revolution) is not supported",
                              "g95")
        self._feed_mode_calls(code, block.line)

    def _feed_mode_calls(self, code: int, line: int) -> None:
        self.modal.feed_mode = code
        if not self.ref:
            self._emit(C.SetFeedMode(
                "inverse_time" if code == 930 else "units_per_minute",
                line))
            return
        what = {930: "inverse time", 940: "units per minute",
                950: "units per revolution"}[code]
        self._trace(f'COMMENT("interpreter: feed mode set to {what}")')
        self._trace(f"SET_FEED_MODE(0, {1 if code == 950 else 0})")
        if code != 930:
            self._trace("SET_FEED_RATE(0.0000)")
            self.feed = self.feed_value = 0.0

    def _orient(self, block: Block) -> None:
        if not self.ref:
            raise block.error("M19 (spindle orientation) is not supported",
                              "m19")
        words = block.words
        if not ("r" in words or "q" in words or "p" in words):
            return
        r = words.get("r", 0.0)
        self._trace(f"ORIENT_SPINDLE(0, {r:.4f}, {int(words.get('p', 0))})")
        if "q" in words:
            self._trace(f"SPINDLE.0.WAIT_ORIENT_COMPLETE({words['q']:.4f})")

    def _spindle_mode(self, block: Block, code: int) -> None:
        """G96 (constant surface speed, up to D rpm; rs274 only: a
        machine's spindle has no such mode yet) and G97 (rpm)."""
        if block.words.get("s", 0.0) < 0:
            return                      # the S word's error comes next
        if code == 960:
            if not self.ref:
                raise block.error("G96 (constant surface speed) is not "
                                  "supported", "g96")
            if "s" not in block.words:
                raise block.error("S word missing with G96", "g96")
            limit = abs(block.words.get("d", 1e30))
            self._trace(f"SET_SPINDLE_MODE(0 {limit:.4f})")
        else:
            self._trace("SET_SPINDLE_MODE(0 0.0000)")
        self.modal.spindle_mode = code

    def _overrides(self, block: Block, code: int) -> None:
        key = code_key("m", code / 10)
        if not self.ref:
            raise block.error(f"M{code // 10} (override control) is not "
                              "supported", key)
        on = block.words.get("p", 1.0) != 0
        enables = self.override_enables
        if code in (480, 490):
            enables["feed"] = enables["speed"] = code == 480
        else:
            enables[{500: "feed", 510: "speed", 520: "adaptive",
                     530: "hold"}[code]] = on
        if code == 480:
            self._trace("ENABLE_FEED_OVERRIDE()")
            self._trace("ENABLE_SPEED_OVERRIDE(0)")
        elif code == 490:
            self._trace("DISABLE_FEED_OVERRIDE()")
            self._trace("DISABLE_SPEED_OVERRIDE(0)")
        elif code == 500:
            self._trace(f"{'EN' if on else 'DIS'}ABLE_FEED_OVERRIDE()")
        elif code == 510:
            self._trace(f"{'EN' if on else 'DIS'}ABLE_SPEED_OVERRIDE(0)")
        elif code == 520:
            self._trace(f"{'EN' if on else 'DIS'}ABLE_ADAPTIVE_FEED()")
        else:
            self._trace(f"{'EN' if on else 'DIS'}ABLE_FEED_HOLD()")

    def pos_without_tlo(self) -> list[float]:
        return [self.pos[i] - self.tlo[i] for i in range(9)]

    def probe_result(self, position: Any, tripped: bool) -> None:
        """Report where a G38.x probe move stopped (machine coordinates)."""
        self.pos = [float(v) for v in position]
        prog = self.program_position()
        for i in range(9):
            self.params.set(5061 + i, prog[i] / self._k(i))
        self.params.set(5070, 1.0 if tripped else 0.0)

    def input_result(self, value: float) -> None:
        """Report the value read by M66 (stored in #5399; -1 on timeout)."""
        self.params.set(5399, float(value))

    # -- checks ----------------------------------------------------------
    def _need(self, block: Block, letter: str, what: str) -> float:
        if letter not in block.words:
            raise block.error(f"{what} needs a {letter.upper()} word",
                              what.split()[0].lower())
        return block.words[letter]

    @staticmethod
    def _arc_turns(block: Block) -> int:
        """The turns of an arc: its P word, a whole number from 1."""
        p = block.words.get("p", 1.0)
        if abs(p - round(p)) > 1e-6:
            raise block.error("P value not an integer with M19 G2 or G3", "p")
        if p < 1:
            raise block.error("P value should be 1 or greater with G2 or G3",
                              "p")
        return int(round(p))

    def _g76_words(self, block: Block) -> None:
        """The words G76 must have, in the reference's order."""
        w = block.words
        if w.get("p", -1.0) == -1.0:    # (P-1 reads as no P there)
            raise block.error("P word missing with G76", "g76")
        if not any(a in w for a in AXES):
            raise block.error("All axes missing with motion code", "g76")
        if any(letter not in w for letter in "ijk"):
            raise block.error("I J or K words missing with G76", "g76")
        if "z" not in w:
            raise block.error("Z word missing with G76", "g76")

    def _arc_message(self, zero: bool, names: str, start: list[float],
                     end: list[float], centre: tuple[float, float],
                     a1: int, a2: int) -> str:
        """The reference's message of an arc whose start and end are not
        on one circle: the points in program coordinates and units."""
        middle = list(start)
        middle[a1], middle[a2] = centre
        k = self._k()
        pts = []
        for machine in (start, middle, end):
            d = self._unrotated(machine)
            pts.append(((d[a1] - self.g92[a1]) / k,
                        (d[a2] - self.g92[a2]) / k))
        s, c, e = pts
        r1 = math.dist(s, c)
        r2 = math.dist(e, c)
        make = zero_radius_arc if zero else arc_radius_differs
        return make(names, s, c, e, r1, r2)

    def _check(self, block: Block, gs: dict[int, int],
               ms: dict[int, int]) -> None:
        if 10 in ms:
            self._user_m_path(block, ms[10])
        axes = self._axis_words(block)
        g0 = gs.get(0)
        user0 = g0 in AXIS_USERS_GROUP0
        if g0 in AXIS_USERS_GROUP0 and gs.get(1, 800) != 800:
            # (even without axis words, as the reference)
            raise block.error(
                "Cannot use two g codes that both use axis values",
                code_key("g", gs[1] / 10))
        if block.words.get("l", 0.0) < 0:
            raise block.error("Negative l word used", "l")
        if gs.get(1) in (20, 30) and "p" in block.words and \
                0 not in gs and not ms:
            self._arc_turns(block)      # checked before the line runs
        if g0 == 920 and not axes:
            raise block.error("All axes missing with g52 or g92", "g92")
        if gs.get(1) == 760:        # G76 is checked before the line runs
            self._g76_words(block)
        if 1 in gs and not axes and (gs[1] in CANNED or gs[1] in (
                870, 330, 382, 383, 384, 385, 50, 51)):
            raise block.error("All axes missing with motion code",
                              code_key("g", gs[1] / 10))

        if g0 == 530 and gs.get(1, self.modal.motion) not in (0, 10):
            raise block.error("Must use g0 or g1 with g53", "g53")
        if g0 == 530 and gs.get(3, self.modal.distance) == 910:
            raise block.error("Cannot use g53 incremental", "g53")
        motion = gs.get(1, self.modal.motion)
        if 1 not in gs and motion in (50, 51):
            motion = 800        # a spline is not repeated by axis words
        g43_2_h = gs.get(8) == 432 and "h" in block.words   # (below)
        if axes and not user0 and gs.get(8) != 431 and not g43_2_h \
                and motion == 800:
            raise block.error(
                "Cannot use axis values with g80" if gs.get(1) == 800 else
                "Cannot use axis values without a g code that uses them",
                axes[0])
        users: Optional[set[str]] = None
        for letter in sorted(block.words):      # the reference's order
            if letter in ALWAYS_ALLOWED:
                continue
            if letter == "q" and self.ref and block.words["q"] == -1.0:
                continue            # the reference's "no Q" value
            if users is None:
                users = self._word_users(block, gs, ms, motion)
            if letter not in users:
                raise block.error(unused_word(letter), letter)
        if g43_2_h and axes:
            raise block.error("G43.2: Can not have both H and axis words",
                              "g43.2")
        if gs.get(1) == 330 and "k" not in block.words:
            raise block.error("K word missing with g33/g33.1", "g33")

    def _word_users(self, block: Block, gs: dict[int, int],
                    ms: dict[int, int], motion: int) -> set[str]:
        """The letters the codes of a block (and the modal motion) use."""
        allowed = set(AXES) | set("fstno")
        g0 = gs.get(0)
        moving = (motion != 800 and g0 not in AXIS_USERS_GROUP0
                  and gs.get(8) != 431
                  and (1 in gs or bool(self._axis_words(block))))
        if motion in (20, 30) and g0 not in AXIS_USERS_GROUP0:
            # (the modal arc takes them even on a line without axes)
            allowed |= set("ijkrp")

        elif moving and motion == 330:
            allowed.add("k")
        elif moving and motion == 760:
            allowed |= set("pijkrqhel")
        elif moving and motion == 50:
            allowed |= set("ijpq")
        elif moving and motion == 51:
            allowed |= set("ij")
        elif moving and motion == 52:
            allowed |= set("pl")
        elif moving and (motion in CANNED or motion in UNSUPPORTED_MOTION):
            allowed |= set("rl")
            if motion in (820, 840, 860, 880, 890):
                allowed.add("p")        # a dwell
            if motion in (730, 830):
                allowed.add("q")        # a peck
            if motion == 870:
                allowed |= set("ijk")
        if g0 == 40:
            allowed.add("p")
        elif g0 == 100:
            allowed |= set("lprijq")
        if gs.get(8) in (430, 432):
            allowed.add("h")
        if gs.get(13) == 640:
            allowed |= set("pq")
        if 7 in gs or gs.get(14) == 960:
            allowed.add("d")
        if 5 in ms:
            allowed |= set("pelq")
        if ms.get(6) == 610:
            allowed.add("q")
        if ms.get(7) == 190:
            allowed |= set("rqp")
        if 9 in ms:
            allowed.add("p")
        if 10 in ms:
            allowed |= set("pq")
        return allowed

    # -- tools -----------------------------------------------------------
    def current_pocket(self) -> int:
        """``#<_current_pocket>``: the pocket the tool in the spindle came
        from (0: no tool, or a tool not in the table)."""
        tool = self.current_tool
        if tool <= 0 or not self.tools:
            return 0
        pocket = self.tools.pocket_of(tool)
        return 0 if pocket is None else int(pocket)

    def _tool_of(self, tool: int) -> Any:
        """The tool table entry of ``tool`` or None for 'no tool'."""
        if tool < 0 or (tool == 0 and not self.random):
            return None
        pocket = self.tools.pocket_of(tool) if self.tools else None
        if pocket is None:
            return None
        return self.tools.entry(pocket)

    def _update_tool_params(self) -> None:
        entry = self._tool_of(self.current_tool)
        p = self.params
        p.set(5400, max(self.current_tool, 0), internal=True)
        offset = entry.offset if entry is not None else ZERO9
        for i in range(9):
            p.set(5401 + i, offset[i], internal=True)
        p.set(5410, entry.diameter if entry is not None else 0.0,
              internal=True)
        p.set(5411, entry.frontangle if entry is not None else 0.0,
              internal=True)
        p.set(5412, entry.backangle if entry is not None else 0.0,
              internal=True)
        p.set(5413, entry.orientation if entry is not None else 0.0,
              internal=True)

    def _tool_number(self, block: Block, letter: str) -> int:
        value = block.words[letter]
        if letter == "q" and value < 0:
            raise block.error("Need non-negative Q-word to specify tool "
                              "number with M61", letter)
        if letter == "t" and value < 0:
            raise block.error("Negative tool id (tool not found)", letter)
        if letter == "h" and value < 0:
            raise block.error(f"Requested tool {value:g} not found in the "
                              "tool table", letter)
        if abs(value - round(value)) > 1e-6:
            raise block.error(
                "G41 requires D word to be a whole number" if letter == "d"
                else "Non integer value for integer", letter)
        if value < 0:
            raise block.error(f"{letter.upper()} must be a non-negative "
                              f"integer, not {value:g}", letter)
        return int(round(value))

    def _pocket_for(self, block: Block, tool: int, letter: str) -> int:
        if tool == 0 and not self.random:
            return 0
        pocket = self.tools.pocket_of(tool) if self.tools else None
        if pocket is None:
            raise block.error(f"Requested tool {tool} not found in the tool "
                              "table", letter)
        return int(pocket)

    def _select_tool(self, block: Block) -> None:
        tool = self._tool_number(block, "t")
        pocket = self._pocket_for(block, tool, "t")
        self.selected_tool, self.selected_pocket = tool, pocket
        self._emit(C.SelectTool(tool, pocket, block.line))

    def _tool_change(self, block: Block, code: int) -> None:
        if code == 60:
            if self.selected_tool < 0 and self.ref:
                self.selected_tool = self.selected_pocket = 0
            if self.selected_tool < 0:
                raise block.error("M6 without a tool selected by a T word",
                                  "m6")
            tool, pocket = self.selected_tool, self.selected_pocket
            if self.ref:
                self._trace("START_CHANGE()")
                self._trace("STOP_SPINDLE_TURNING(0)")
                self.modal.spindle = 50
            self._emit(C.ChangeTool(tool, pocket, block.line))
            if self.random:
                if pocket != 0:
                    old, new = self.tools.entry(0), self.tools.entry(pocket)
                    self.tools.set_entry(0, replace(new, pocket=0))
                    self.tools.set_entry(pocket, replace(old, pocket=pocket))
                self.selected_pocket = 0
            else:
                self._load_spindle(pocket)
        else:
            if "q" not in block.words:
                raise block.error("Need non-negative Q-word to specify tool "
                                  "number with M61", "m61")
            tool = self._tool_number(block, "q")
            pocket = self._pocket_for(block, tool, "q")
            self._emit(C.ChangeToolNumber(tool, pocket, block.line))
            if not self.random:
                # (the reference's rs274 leaves its spindle entry as it
                # was: a G43 after M61 applies no offset there)
                if not self.ref:
                    self._load_spindle(pocket)
            elif pocket != 0:
                old, new = self.tools.entry(0), self.tools.entry(pocket)
                self.tools.set_entry(0, replace(new, pocket=0))
                self.tools.set_entry(pocket, replace(old, pocket=pocket))
        self.current_tool = tool
        self._update_tool_params()

    def _cutter_comp(self, block: Block, code: int) -> None:
        key = code_key("g", code / 10)
        if code != 400 and self.modal.plane not in (170, 180):
            raise block.error("Cutter radius compensation allowed only in "
                              "XY, XZ planes", key)
        if code != 400 and "d" in block.words:
            self._pocket_for(block, self._tool_number(block, "d"), "d")
        self._trace('COMMENT("interpreter: cutter radius compensation '
                    f'{ {400: "off", 410: "on left", 420: "on right"}[code] }")')
        if code == 400:
            self.comp.stop()
        else:
            tool = (self._tool_number(block, "d") if "d" in block.words
                    else self.current_tool)
            if "d" in block.words:
                self._pocket_for(block, tool, "d")
            entry = self._tool_of(tool)
            radius = entry.diameter / 2 if entry is not None else 0.0
            try:
                self.comp.start(1 if code == 410 else -1, radius,
                                self.modal.plane // 10)
            except CutterRadiusError as e:
                raise block.error(str(e), key) from None
        self.modal.cutter_comp = code

    def _load_spindle(self, pocket: int) -> None:
        """Nonrandom: copy the tool of ``pocket`` to the spindle (0: none)."""
        if self.tools is None:
            return
        if pocket:
            self.tools.set_entry(0, replace(self.tools.entry(pocket)))
        else:
            self.tools.set_entry(0, replace(
                self.tools.entry(0), tool=0, offset=ZERO9, diameter=0.0,
                frontangle=0.0, backangle=0.0, orientation=0))

    def _tool_length(self, block: Block, code: int) -> None:
        if self.comp.active:
            raise block.error("Cannot change tool offset with cutter radius "
                              "compensation on", code_key("g", code / 10))
        if code == 490:
            offset = [0.0] * 9
        elif code == 431:
            offset = [0.0] * 9
            for i, a in enumerate(AXES):
                if a in block.words:
                    offset[i] = block.words[a] * self._k(i)
        else:
            if code == 432 and "h" not in block.words:
                raise block.error("G43.2: No axes specified and H word "
                                  "missing", "g43.2")
            tool = (self._tool_number(block, "h") if "h" in block.words
                    else self.current_tool)
            if "h" in block.words:
                self._pocket_for(block, tool, "h")
            entry = self._tool_of(tool)
            if self.ref and "h" not in block.words and \
                    self.tools is not None:
                entry = self.tools.entry(0)      # the spindle's entry
            offset = list(entry.offset) if entry is not None else [0.0] * 9
            if code == 432:             # added to the offset in force
                offset = [a + b for a, b in zip(self.tlo, offset)]
        self.modal.tool_length = code
        self.tlo = [float(v) for v in offset]
        self._emit(C.UseToolLengthOffset(_pose(self.tlo), block.line))

    def _g10_tool(self, block: Block, level: float) -> None:
        if "p" not in block.words:
            raise block.error(f"P value out of range with G10 L{level:g}",
                              "g10")
        tool = self._tool_number(block, "p")
        if self.random and tool == self.current_tool:
            pocket = 0
        else:
            pocket = self._pocket_for(block, tool, "p")
            if pocket == 0 and not self.random:
                raise block.error(f"P value out of range with G10 "
                                  f"L{level:g}", "p")
        entry = self.tools.entry(pocket)
        offset = list(entry.offset)
        for i, a in enumerate(AXES):
            if a not in block.words:
                continue
            value = block.words[a] * self._k(i)
            if level == 1:
                offset[i] = value
            else:
                base = self._g5x(9) if level == 11 else [
                    g + h for g, h in zip(self._g5x(), self.g92)]
                offset[i] = self.pos[i] - base[i] - value
        changes: dict[str, Any] = {"offset": _pose(offset)}
        if "r" in block.words:
            changes["diameter"] = 2 * self._len(block.words["r"])
        if "i" in block.words:
            changes["frontangle"] = block.words["i"]
        if "j" in block.words:
            changes["backangle"] = block.words["j"]
        if "q" in block.words:
            changes["orientation"] = int(round(block.words["q"]))
        entry = replace(entry, **changes)
        self.tools.set_entry(pocket, entry)
        self._emit(self._table_command(pocket, entry, block.line))
        if tool == self.current_tool and (self.random or tool > 0):
            if not self.random:
                self.tools.set_entry(0, replace(entry))
                self._emit(self._table_command(0, entry, block.line))
            self._update_tool_params()   # only when the current tool changed

    @staticmethod
    def _table_command(pocket: int, e: Any, line: int) -> C.SetToolTableEntry:
        return C.SetToolTableEntry(pocket, e.tool, _pose(e.offset),
                                   e.diameter, e.frontangle, e.backangle,
                                   e.orientation, line)

    # -- spindle, coolant, I/O, stops ------------------------------------
    def _spindle(self, code: int, line: int) -> None:
        self.modal.spindle = code
        if code == 50:
            self._emit(C.SpindleOff(line))
        else:
            self._emit(C.SpindleOn(1 if code == 30 else -1, self.speed, line))

    def _index(self, block: Block, letter: str, what: str) -> int:
        if letter not in block.words:
            raise block.error(f"No valid {letter.upper()} word with {what}",
                              what.split()[0].lower())
        value = block.words[letter]
        if value < 0 or abs(value - round(value)) > 1e-6:
            raise block.error(f"{letter.upper()} must be a non-negative "
                              f"integer, not {value:g}", letter)
        return int(round(value))

    def _hal_io(self, block: Block, code: int) -> None:
        line = block.line
        if code in (620, 630, 640, 650):
            index = self._index(block, "p", f"M{code // 10}")
            on = code in (620, 640)
            cls = C.SyncDout if code in (620, 630) else C.DoutNow
            self._emit(cls(index, on, line))
        elif code == 660:
            if ("p" in block.words) == ("e" in block.words):
                raise block.error("Invalid to select both a digital and an "
                                  "analog input with M66", "m66")
            digital = "p" in block.words
            index = self._index(block, "p" if digital else "e", "M66")
            mode = int(block.words.get("l", 0))
            if self.ref:
                return          # the reference's rs274 prints nothing
            if not 0 <= mode <= 4:
                raise block.error("M66 L must be 0..4", "l")
            if mode and not digital:
                raise block.error("M66 analog inputs need L0", "l")
            timeout = block.words.get("q", 0.0)
            if mode and timeout <= 0 and "q" not in block.words:
                raise block.error("M66 with L1..L4 needs a Q timeout", "m66")
            self._emit(C.WaitInput(index, digital, mode, timeout, line))
        else:
            index = self._index(block, "e", f"M{code // 10}")
            if "q" not in block.words:
                raise block.error(f"M{code // 10} needs a Q word",
                                  code_key("m", code / 10))
            acls = C.SyncAout if code == 670 else C.AoutNow
            self._emit(acls(index, block.words["q"], line))

    def _stop(self, code: int, line: int) -> None:
        if code == 0:
            self._emit(C.ProgramPause(line))
        elif code == 10:
            self._emit(C.OptionalPause(line))
        elif code == 600:
            self._trace("PALLET_SHUTTLE()")
            self._emit(C.ProgramPause(line))
        elif self.ref:
            self._reference_end(code, line)
        else:
            m = self.modal
            if m.coord_system != 540:
                m.coord_system = 540
                self.params.set(5220, 1)
                self._emit(C.SetG5xOffset(1, _pose(self._g5x()), line))
            self.comp.stop()
            m.plane, m.distance, m.feed_mode = 170, 900, 940
            m.cutter_comp, m.motion = 400, 10
            if m.spindle != 50:
                self._spindle(50, line)
            if m.mist or m.flood:
                m.mist = m.flood = False
                self._emit(C.Coolant("off", line))
            self._emit(C.ProgramEnd(code == 300, line))
            self.ended = True

    def _reference_end(self, code: int, line: int) -> None:
        """M2/M30 with the reference's calls (see :meth:`_stop`)."""
        m = self.modal
        m.coord_system = 540
        self.params.set(5220, 1)
        self._emit(C.SetG5xOffset(1, _pose(self._g5x()), line))
        self._trace(f"SET_XY_ROTATION({self.rotation:.4f})")
        self.comp.stop()
        if m.plane != 170:
            self._emit(C.SetPlane(17, line))
        m.plane, m.distance, m.feed_mode = 170, 900, 940
        m.cutter_comp, m.motion = 400, 10
        self._trace("SET_FEED_MODE(0, 0)")
        self._trace("SET_FEED_RATE(0.0000)")
        self.feed = self.feed_value = 0.0
        if not self.override_enables["feed"]:   # M2 turns it on again
            self.override_enables["feed"] = True
            self._trace("ENABLE_FEED_OVERRIDE()")
        m.spindle = 50
        self._emit(C.SpindleOff(line))
        self._trace("SET_SPINDLE_MODE(0 0.0000)")
        m.spindle_mode = 970
        if m.mist:
            self._trace("MIST_OFF()")
        if m.flood:
            self._trace("FLOOD_OFF()")
        m.mist = m.flood = False
        if code == 300:
            self._trace("PALLET_SHUTTLE()")
        self._emit(C.ProgramEnd(code == 300, line))
        self.ended = True

    def _control(self, block: Block, code: int) -> None:
        if code == 640:
            p = block.words.get("p")
            q = block.words.get("q")
            if q is None and p is not None and self.ref:
                q = p
            self.blend = (None if p is None else self._len(p),
                          None if q is None else self._len(q))
            self._emit(C.SetTermCond("blend", self.blend[0], self.blend[1],
                                     block.line))
        else:
            self._emit(C.SetTermCond(
                "exact_path" if code == 610 else "exact_stop",
                line=block.line))
        self.modal.control = code

    # -- offsets ---------------------------------------------------------
    def _g10(self, block: Block) -> None:
        if "l" not in block.words:
            raise block.error("Line with G10 does not have L0, L1, L10, "
                              "L11, L2, or L20", "g10")
        level = block.words["l"]
        if level in (1, 10, 11):
            self._g10_tool(block, level)
            return
        if level not in (2, 20):
            raise block.error("Line with G10 does not have L0, L1, L10, "
                              "L11, L2, or L20", "l")
        if "i" in block.words or "j" in block.words:
            # (the reference says L2 for L20 too)
            raise block.error("I J words not allowed with G10 L2", "g10")
        if level == 20 and "r" in block.words:
            raise block.error("R not allowed in G10 L20", "r")
        p = block.words.get("p", -1.0)
        if not 0 <= p <= 9 or abs(p - round(p)) > 1e-6:
            raise block.error("P value out of range (0-9) with G10 "
                              f"L{level:g}", "p" if "p" in block.words
                              else "g10")
        p = int(round(p))
        index = p or self.coord_index
        base = 5201 + 20 * index
        angle = float(self.params.get(base + 9))
        if level == 20:
            # the origin that makes the current point read the words
            target = [self.pos[i] - self.tlo[i] for i in range(9)]
            want = self.program_position()
            for i, a in enumerate(AXES):
                if a in block.words:
                    want[i] = block.words[a] * self._k(i)
            v = [want[i] + self.g92[i] for i in range(9)]
            if angle:
                v[0], v[1] = _rotate(v[0], v[1], angle)
        for i, a in enumerate(AXES):
            if a in block.words:
                value = block.words[a] * self._k(i)
                if level == 20:
                    value = target[i] - v[i]
                self.params.set(base + i, value)
        if "r" in block.words:
            self.params.set(base + 9, block.words["r"])
        if index == self.coord_index:
            self._emit(C.SetG5xOffset(index, _pose(self._g5x()), block.line))
            self._trace(f"SET_XY_ROTATION({self.rotation:.4f})")
        else:
            self._trace('COMMENT("interpreter: setting coordinate system '
                        'origin")')

    def _g92(self, block: Block, code: int) -> None:
        if code == 920:
            if not self._axis_words(block):
                raise block.error("All axes missing with g52 or g92", "g92")
            here = self._unrotated(self.pos)
            for i, a in enumerate(AXES):
                if a in block.words:
                    self.g92[i] = here[i] - block.words[a] * self._k(i)
        elif code in (921, 922):
            self.g92 = [0.0] * 9
        else:
            self.g92 = [self.params.get(5211 + i) for i in range(9)]
        if code != 922:
            for i in range(9):
                self.params.set(5211 + i, self.g92[i])
        self.params.set(5210, 0.0 if code in (921, 922) else 1.0)
        self._emit(C.SetG92Offset(_pose(self.g92), block.line))

    def _go_home(self, block: Block, code: int) -> None:
        line = block.line
        base = 5161 if code == 280 else 5181
        # the stored point is where the machine goes (the tool length
        # offset is not added), as in the reference
        home = [self.params.get(base + i) for i in range(9)]
        axes = self._axis_words(block)
        if axes or self.ref:
            middle = self._target(block)
            self._traverse(middle, line)
            end = list(self.pos) if axes else list(home)
            for i, a in enumerate(AXES):
                if a in block.words:
                    end[i] = home[i]
            self._traverse(end, line)
        else:
            self._traverse(home, line)

    # -- motion ----------------------------------------------------------
    def _traverse(self, end: list[float], line: int) -> None:
        self._emit(C.StraightTraverse(_pose(end), line))
        self.pos = list(end)

    def _feed_for(self, block: Block, length: float) -> float:
        if self.modal.feed_mode == 930:
            if "f" not in block.words:
                raise block.error("F word missing with inverse time "
                                  f"{self._move_name()} move", "")
            f = block.words["f"]
            if f <= 0:
                raise block.error("inverse time F must be positive", "f")
            return length * f if length > 0 else f
        if self.feed <= 0:
            raise block.error("Cannot make arc with zero feed rate"
                              if self._move_name() == "arc" else
                              "Cannot do g1 with zero feed rate", "")
        return self.feed

    def _move_name(self) -> str:
        """How the reference names the current move in its messages."""
        return "arc" if self.modal.motion in (20, 30, 50, 51) else "g1"

    def _inverse_time_trace(self, length: float) -> None:
        """G93: the reference sets the feed rate of each move."""
        block = self.line_block
        if self.ref and self.modal.feed_mode == 930 and block is not None:
            rate = length / self._k() * block.words.get("f", 0.0)
            self._trace(f"SET_FEED_RATE({rate:.4f})")

    def _straight_feed(self, block: Block, end: list[float]) -> None:
        length = math.dist(self.pos, end)
        feed = self._feed_for(block, length)
        self._inverse_time_trace(length)
        self._emit(C.StraightFeed(_pose(end), feed, block.line))
        self.pos = list(end)

    def _motion(self, block: Block, gs: dict[int, int]) -> None:
        explicit = gs.get(1)
        self._previous_motion = self.modal.motion
        if explicit is not None:
            if explicit in UNSUPPORTED_MOTION and not self.ref:
                raise block.error(f"{UNSUPPORTED_MOTION[explicit]} is not "
                                  "supported", code_key("g", explicit / 10))
            self.modal.motion = explicit
            if explicit == 800:
                self.cycle = {}
                self._trace('COMMENT("interpreter: motion mode set to '
                            'none")')
        has_axes = bool(self._axis_words(block))
        if gs.get(0) in AXIS_USERS_GROUP0 or gs.get(8) == 431:
            return
        motion = self.modal.motion
        # a centre word alone repeats a modal arc (to where the tool is:
        # a full circle), as in the reference
        centre = motion in (20, 30) and any(w in block.words for w in "ijk")
        if motion == 800 or not (has_axes or explicit is not None or centre):
            return
        line = block.line
        key = code_key("g", motion / 10)
        if motion in (52, 53):
            self._nurbs(block, motion)
            return
        g53 = gs.get(0) == 530
        if self.comp.active and (motion not in (0, 10, 20, 30) or g53):
            if g53:
                text = "Cannot use g53 with cutter radius comp"
            elif motion in CANNED or motion == 870:
                text = "Cannot use canned cycles with cutter compensation on"
            elif 382 <= motion <= 385:
                text = "Cannot probe with cutter radius comp on"
            else:
                text = (f"G{motion / 10:g} while cutter compensation is on "
                        "is not supported")
            raise block.error(text, "g53" if g53 else key)
        if self.comp.active and has_axes and motion in (0, 10):
            end = self._target(block)
            feed = None
            if motion == 10:
                feed = self._feed_for(block, math.dist(self.pos, end))
            try:
                self.comp.move(self.pos, end, feed, line)
            except CutterRadiusError as e:
                raise block.error(str(e), key) from None
            self.pos = end
            return
        if g53 and self.modal.distance == 910:
            raise block.error("Cannot use g53 incremental", "g53")
        if motion in (0, 10, 330) or 382 <= motion <= 385:
            if not has_axes:
                # the reference moves to where it is on a G0/G1 alone
                if motion in (0, 10) and not (self.ref and explicit is not None):
                    return
                if motion not in (0, 10):
                    raise block.error(f"G{motion / 10:g} needs an axis word", key)
            end = self._target(block, g53)
            if motion == 0:
                self._traverse(end, line)
            elif motion == 10:
                self._straight_feed(block, end)
            elif motion == 330:
                if "k" not in block.words or block.words["k"] <= 0:
                    raise block.error("K word missing with g33/g33.1", key)
                self._emit(C.SyncedFeed(_pose(end), self._len(
                    block.words["k"]), line))
                self.pos = end
            else:
                self._probe(block, motion, end)
        elif motion in (20, 30):
            self._arc(block, motion)
        elif motion == 760:
            self._g76(block)
        elif motion in (50, 51):
            self._spline(block, motion)
        else:
            self._canned(block, motion)

    # -- G5, G5.1 splines ----------------------------------------------------
    def _spline(self, block: Block, motion: int) -> None:
        """G5 cubic and G5.1 quadratic B-splines in the XY plane. rs274
        prints the reference's NURBS_FEED call; a machine gets straight
        feeds within 1 um (0.00004 in) of the curve."""
        key = code_key("g", motion / 10)
        w = block.words
        if self.modal.plane != 170:
            raise block.error("Splines must be in the XY plane", key)
        if any(a in w for a in "zabcuvw"):
            raise block.error("Splines may not have motion in Z, A, B, or C",
                              key)
        k = self._k()
        start = list(self.pos)
        end = self._target(block)
        p0 = (start[0], start[1])
        p3 = (end[0], end[1])
        if motion == 50:
            if "p" not in w or "q" not in w:
                raise block.error("Must specify both P and Q with G5", key)
            if "i" in w or "j" in w:
                c1 = (w.get("i", 0.0) * k, w.get("j", 0.0) * k)
            elif self._previous_motion == 50:
                # the reflection of the last G5's second control point
                c1 = (-self._spline_pq[0], -self._spline_pq[1])
            else:
                c1 = (0.0, 0.0)
            pq = (w["p"] * k, w["q"] * k)
            if self.rotation:
                c1 = _rotate(c1[0], c1[1], self.rotation)
                pq = _rotate(pq[0], pq[1], self.rotation)
            controls = [p0, (p0[0] + c1[0], p0[1] + c1[1]),
                        (p3[0] + pq[0], p3[1] + pq[1]), p3]
            self._spline_pq = pq
        else:
            if "i" not in w or "j" not in w:
                raise block.error("Must specify both I and J with G5.1", key)
            c1 = (w["i"] * k, w["j"] * k)
            if self.rotation:
                c1 = _rotate(c1[0], c1[1], self.rotation)
            controls = [p0, (p0[0] + c1[0], p0[1] + c1[1]), p3]
        feed = self._feed_for(block, math.dist(p0, p3))
        if self.ref:
            self._trace(f"NURBS_FEED({len(controls)}, ...)")
            self.pos = list(end)
            return
        n = self._spline_segments(controls)
        for step in range(1, n + 1):
            x, y = _bezier(controls, step / n)
            point = list(end)
            point[0], point[1] = x, y
            self._emit(C.StraightFeed(_pose(point), feed, block.line))
        self.pos = list(end)

    # -- G5.2/G5.3 NURBS blocks ---------------------------------------------
    def _nurbs(self, block: Block, motion: int) -> None:
        """G5.2 adds control points (the first block also the position
        where the tool is), G5.3 ends the block and moves along the
        curve: rs274 prints the reference's NURBS_FEED; a machine gets
        straight feeds within 1 um (0.00004 in) of it (:mod:`.nurbs`).
        The checks and their order are the reference's; a machine also
        refuses what has no meaning for it."""
        key = code_key("g", motion / 10)
        w = block.words
        has_x, has_y = "x" in w, "y" in w
        points = self._nurbs_points if self._previous_motion == 52 else None
        if motion == 53:
            if points is None:
                raise block.error("Cannot use G5.3 without G5.2 first", key)
            self._nurbs_points = None
            self.modal.motion = 800
            if len(points) < self._nurbs_order:
                raise block.error("You must specify a number of control "
                                  "points at least equal to the order L = "
                                  f"{self._nurbs_order}", key)
            self._nurbs_feed(block, points)
            if has_x != has_y:      # (after the curve, as the reference)
                raise block.error("You must specify both X and Y "
                                  "coordinates for Control Points", key)
            return
        if has_x != has_y:
            raise block.error("You must specify both X and Y coordinates "
                              "for Control Points", key)
        order = w.get("l")
        if order is not None and order < 0:
            raise block.error("Negative l word used", "l")
        if order is not None and order != int(order):
            raise block.error("Non integer value for integer", "l")
        weight = w.get("p")
        if not self.ref:
            self._nurbs_machine_checks(block, key, order, weight,
                                       points is None)
        if points is None:
            if self.modal.feed_mode != 930 and self.feed <= 0:
                raise block.error("Cannot make a NURBS with 0 feedrate", key)
            # the start point weighs P when the line has no point of its
            # own, else 1 (as the reference's preview draws it)
            start = 1.0 if has_x or weight is None else weight
            points = [(list(self.pos), start)]
            self._nurbs_points = points
            self._nurbs_order = 3
        else:
            if not has_x:
                raise block.error("Can specify P without X and Y only for "
                                  "the first control point", key)
            if weight is None or weight <= 0:
                raise block.error("Must specify positive weight P for "
                                  "every Control Point", key)
        if order is not None:
            self._nurbs_order = int(order)
        if has_x:
            # (relative to where the tool is, not to the last point, in
            # G91: the reference's position moves only at G5.3)
            end = self._target(block)
            point = list(self.pos)
            point[0], point[1] = end[0], end[1]
            points.append((point, -1.0 if weight is None else weight))

    def _nurbs_machine_checks(self, block: Block, key: str,
                              order: Optional[float],
                              weight: Optional[float], first: bool) -> None:
        """What the reference's rs274 lets through and a machine cannot
        run: a curve outside the XY plane or moving other axes, with
        cutter compensation, in inverse time, without weights."""
        if self.modal.plane != 170:
            raise block.error("a NURBS (G5.2) must be in the XY plane (G17)",
                              key)
        if any(a in block.words for a in "zabcuvw"):
            raise block.error("a NURBS (G5.2) may not move Z, A, B, C, U, V "
                              "or W", key)
        if self.comp.active:
            raise block.error("G5.2 while cutter compensation is on is not "
                              "supported", key)
        if self.modal.feed_mode == 930:
            raise block.error("G5.2 in inverse time feed (G93) is not "
                              "supported", key)
        if weight is not None and weight <= 0:
            raise block.error("NURBS weights P must be above 0", "p")
        if first and weight is None and "x" in block.words:
            # (the reference then weighs the point -1: a curve far off)
            raise block.error("a NURBS control point needs its weight P "
                              "(also on the first line)", key)
        if order is not None and order < 2:
            raise block.error("the NURBS order L must be at least 2", "l")

    def _nurbs_feed(self, block: Block,
                    points: list[tuple[list[float], float]]) -> None:
        end = points[-1][0]
        if self.ref:
            self._trace(f"NURBS_FEED({len(points)}, ...)")
            self.pos = list(end)
            return
        tol = 0.001 if self.machine_metric else 0.00004
        try:
            chords = nurbs_polyline([(p[0], p[1]) for p, _ in points],
                                    [wt for _, wt in points],
                                    self._nurbs_order, tol)
        except ValueError as e:
            raise block.error(f"NURBS: {e}", "g5.3") from None
        length = sum(math.dist(a, b) for a, b in zip(
            [(self.pos[0], self.pos[1])] + chords, chords))
        feed = self._feed_for(block, length)
        for x, y in chords:
            target = list(end)
            target[0], target[1] = x, y
            self._emit(C.StraightFeed(_pose(target), feed, block.line))
        self.pos = list(end)

    def _spline_segments(self, controls: list[tuple[float, float]]) -> int:
        """Segments that keep the chords within the tolerance: a chord
        strays at most |B''| / (8 n^2) from the curve."""
        degree = len(controls) - 1
        bend = max(math.dist((0.0, 0.0), (
            a[0] - 2 * b[0] + c[0], a[1] - 2 * b[1] + c[1]))
            for a, b, c in zip(controls, controls[1:], controls[2:]))
        second = degree * (degree - 1) * bend
        tol = 0.001 if self.machine_metric else 0.00004
        return max(1, min(1000, math.ceil(math.sqrt(second / (8 * tol)))))

    # -- G76 threading ---------------------------------------------------
    def _g76(self, block: Block) -> None:
        """The threading cycle: passes of growing depth (J, J*2^(1/R),
        ... then K), each entered at the compound angle Q, with optional
        entry/exit tapers (E, L) and H spring passes; ends at the start
        X and the end Z."""
        key = "g76"
        w = block.words
        self._g76_words(block)
        k = self._k()
        half = 0.5 if self.diameter_mode else 1.0
        pitch = w["p"] * k
        depth0 = w["j"] * k * half
        full = w["k"] * k * half
        offset = w["i"] * k * half
        degression = w.get("r", 1.0)
        angle = w.get("q", 0.0)
        springs = int(w.get("h", 0))
        taper = w.get("e", 0.0) * k
        ends = int(w.get("l", 0))
        for letter, value in (("p", pitch), ("j", depth0), ("k", full)):
            if value <= 0:
                raise block.error(f"In G76, {letter.upper()} must be greater "
                                  "than 0", letter)
        if degression < 1.0:
            raise block.error("G76 R (depth degression) must be at least 1",
                              "r")
        if springs < 0 or not 0 <= ends <= 3:
            raise block.error("G76 needs H >= 0 and L 0..3", key)
        if ends and taper <= 0:
            raise block.error("G76 L (taper) needs a positive E", "e")
        prog = self.program_position()
        start_x, start_z = prog[0], prog[2]
        end_z = w["z"] * k + (start_z if self.modal.distance == 910 else 0.0)
        way = -1.0 if end_z < start_z else 1.0
        inward = 1.0 if offset > 0 else -1.0     # I > 0: internal thread
        tan_q = math.tan(math.radians(angle))
        taper_pitch = (pitch * math.hypot(taper, full) / taper
                       if taper > 0 else pitch)
        line = block.line

        def at(x: float, z: float) -> list[float]:
            point = list(prog)
            point[0], point[2] = x, z
            return self._to_machine(point)

        def synced(x: float, z: float, rate: float) -> None:
            end = at(x, z)
            if self.ref:
                if self._sync != rate:
                    self._trace(f"START_SPEED_FEED_SYNC({rate / k:f},0)")
                    self._sync = rate
                self._emit(C.StraightFeed(_pose(end), 0.0, line))
            else:
                self._emit(C.SyncedFeed(_pose(end), rate, line))
            self.pos = end

        def thread_pass(depth: float) -> None:
            # the compound angle moves each pass along Z, away from the
            # direction of travel by the depth it has reached
            z0 = start_z + way * depth * tan_q
            z1 = end_z + way * (depth - full) * tan_q
            back = start_x + inward * (depth - full)
            cut = start_x + offset + inward * depth
            self._traverse(at(back, z0), line)
            self._sync = None
            if ends & 1:
                self._trace("DISABLE_FEED_OVERRIDE()")
                synced(cut - inward * full, z0, taper_pitch)
                synced(cut, z0 + way * taper, taper_pitch)
            else:
                self._traverse(at(cut, z0), line)
                self._trace("DISABLE_FEED_OVERRIDE()")
            synced(cut, z1 - way * taper if ends & 2 else z1, pitch)
            if ends & 2:
                synced(cut - inward * full, z1, taper_pitch)
            self._trace("STOP_SPEED_FEED_SYNCH()")
            self._traverse(at(back, z1), line)
            self._trace("ENABLE_FEED_OVERRIDE()")

        n, depth = 1, depth0
        while depth < full:
            thread_pass(depth)
            n += 1
            depth = depth0 * n ** (1.0 / degression)
        for _ in range(1 + springs):
            thread_pass(full)
        self._traverse(at(start_x, end_z), line)

    def _probe(self, block: Block, motion: int, end: list[float]) -> None:
        key = code_key("g", motion / 10)
        if self.modal.feed_mode == 930:
            # (the reference probes at the G94 feed rate)
            raise block.error("Cannot probe with zero feed rate", key)
        if self.feed <= 0:
            raise block.error("Cannot probe with zero feed rate", key)
        if math.dist(self.pos, end) < 1e-9:
            raise block.error("Start point too close to probe point", key)
        self._emit(C.Probe(_pose(end), f"{motion / 10:g}", self.feed,
                           block.line))
        self.pos = list(end)

    def _arc(self, block: Block, motion: int) -> None:
        key = code_key("g", motion / 10)
        a1, a2, _normal, centre_words = PLANES[self.modal.plane]
        other = {170: "k", 180: "j", 190: "i"}[self.modal.plane]
        words = block.words
        if "r" in words and any(w in words for w in "ijk"):
            raise block.error("Mixed radius ijk format for arc", "r")
        if not ("r" in words or any(w in words for w in "ijk")):
            raise block.error("R i j k words all missing for arc", key)
        if other in block.words and "r" not in block.words:
            raise block.error(f"{other.upper()} word given for arc in "
                              f"{PLANE_NAME[self.modal.plane]} plane", other)
        turns = self._arc_turns(block)
        if self.modal.feed_mode == 930 and "f" not in block.words:
            raise block.error("F word missing with inverse time arc move",
                              key)
        if self.modal.feed_mode != 930 and self.feed <= 0:
            raise block.error("Cannot make arc with zero feed rate", key)
        if self.rotation and self.modal.plane != 170:
            raise block.error("arcs outside G17 in a rotated coordinate "
                              "system (G10 L2 R) are not supported", key)
        names = AXES[a1].upper() + AXES[a2].upper()
        in_plane = AXES[a1] in block.words or AXES[a2] in block.words
        start = self.pos
        end = self._target(block)
        s1, s2, e1, e2 = start[a1], start[a2], end[a1], end[a2]
        k = self._k()
        tol = 0.005 if self.machine_metric else 0.0005
        if "r" in block.words:
            if any(w in block.words for w in centre_words):
                raise block.error("arc with both R and centre words", "r")
            if not in_plane:
                raise block.error(f"{names[0]} and {names[1].lower()} words "
                                  "missing for arc in "
                                  f"{PLANE_NAME[self.modal.plane]} plane", key)
            r = block.words["r"] * k
            chord = math.hypot(e1 - s1, e2 - s2)
            if chord < 1e-9:
                raise block.error("Current point same as end point of arc",
                                  "r")
            half = chord / 2
            if abs(r) < 1e-9 or abs(r) < half - tol:
                raise block.error("Arc radius too small to reach end point",
                                  "r")
            h = math.sqrt(max(r * r - half * half, 0.0))
            sign = 1.0 if (motion == 30) != (r < 0) else -1.0
            m1, m2 = (s1 + e1) / 2, (s2 + e2) / 2
            c1 = m1 - sign * h * (e2 - s2) / chord
            c2 = m2 + sign * h * (e1 - s1) / chord
        else:
            w1, w2 = centre_words[0], centre_words[1]
            if w1 not in block.words and w2 not in block.words:
                raise block.error(f"{w1.upper()} and {w2.upper()} words both "
                                  "missing for a centre-format arc", key)
            o1, o2 = block.words.get(w1, 0.0) * k, block.words.get(w2, 0.0) * k
            if self.modal.arc_distance == 901:
                if w1 not in block.words or w2 not in block.words:
                    missing = w1 if w1 not in block.words else w2
                    raise block.error(f"{missing.upper()} word missing in "
                                      "absolute center arc", key)
                point = self.program_position()
                point[a1], point[a2] = o1, o2
                centre = self._to_machine(point)
                c1, c2 = centre[a1], centre[a2]
            else:
                if self.rotation and self.modal.plane == 170:
                    o1, o2 = _rotate(o1, o2, self.rotation)
                c1, c2 = s1 + o1, s2 + o2
            r1 = math.hypot(s1 - c1, s2 - c2)
            r2 = math.hypot(e1 - c1, e2 - c2)
            if r1 < tol or r2 < tol or (abs(r1 - r2) > tol
                                        and abs(r1 - r2) > 0.001 * r1):
                raise block.error(self._arc_message(
                    r1 < tol or r2 < tol, names, start, end, (c1, c2),
                    a1, a2), key)
        turn = turns if motion == 30 else -turns
        length = self._arc_length(start, end, (c1, c2), a1, a2, turn)
        feed = self._feed_for(block, length)
        self._inverse_time_trace(length)
        if self.comp.active:
            try:
                self.comp.arc(self.pos, end, (c1, c2), turn, feed,
                              block.line)
            except CutterRadiusError as e:
                raise block.error(str(e), key) from None
        else:
            self._emit(C.ArcFeed(_pose(end), (c1, c2),
                                 self.modal.plane // 10, turn, feed,
                                 block.line))
        self.pos = list(end)

    @staticmethod
    def _arc_length(start: list[float], end: list[float],
                    c: tuple[float, float], a1: int, a2: int,
                    turn: int) -> float:
        r = math.hypot(start[a1] - c[0], start[a2] - c[1])
        t0 = math.atan2(start[a2] - c[1], start[a1] - c[0])
        t1 = math.atan2(end[a2] - c[1], end[a1] - c[0])
        sweep = t1 - t0
        if turn > 0:
            while sweep <= 1e-12:
                sweep += 2 * math.pi
        else:
            while sweep >= -1e-12:
                sweep -= 2 * math.pi
        sweep = abs(sweep) + 2 * math.pi * (abs(turn) - 1)
        planar = r * sweep
        rest = [end[i] - start[i] for i in range(9) if i not in (a1, a2)]
        return math.hypot(planar, math.hypot(*rest))

    # -- canned cycles ---------------------------------------------------
    def _canned(self, block: Block, motion: int) -> None:
        key = code_key("g", motion / 10)
        line = block.line
        a1, a2, d, _ = PLANES[self.modal.plane]
        dl = AXES[d]
        for letter in ("r", dl, "p", "q", "i", "j", "k"):
            if letter in block.words:
                self.cycle[letter] = block.words[letter]
        for letter in ("r", dl):
            if letter not in self.cycle:
                raise block.error(
                    "R clearance plane unspecified in cycle" if letter == "r"
                    else f"{letter.upper()} value unspecified in "
                    f"{PLANE_NAME[self.modal.plane]} plane canned cycle", key)
        if motion in (730, 830) and self.cycle.get("q", 0) <= 0 and \
                not self.ref:
            raise block.error(f"Q word missing with g{motion // 10}", key)
        if motion == 840 and self.modal.spindle != 30 and not self.ref:
            raise block.error("Spindle not turning in G84"
                              if self.modal.spindle == 50 else
                              "Spindle turning counterclockwise in G84", key)
        if motion == 880 and self.modal.spindle == 50 and not self.ref:
            raise block.error("Spindle not turning in g88", key)
        repeats = int(block.words.get("l", 1))
        if repeats < 0:
            raise block.error("Negative l word used", "l")
        k = self._k()
        prog = self.program_position()
        old = prog[d]
        if self.ref:
            # the reference keeps the level where the cycle started
            if self._previous_motion != motion or self.cycle_il is None:
                self.cycle_il = old
            old = self.cycle_il
        incremental = self.modal.distance == 910
        r = self.cycle["r"] * k + (old if incremental else 0.0)
        bottom = self.cycle[dl] * k + (r if incremental else 0.0)
        if bottom > r:
            raise block.error(f"R less than {dl} in cycle in "
                              f"{PLANE_NAME[self.modal.plane]} plane", "r")
        clear = max(old, r) if self.modal.retract == 980 else r
        if self.feed <= 0 or self.modal.feed_mode == 930:
            raise block.error("Cannot feed with zero feed rate", key)
        if old < r:
            prog[d] = r
            self._traverse(self._to_machine(prog), line)
        wrap = self.modal.control != 610
        if wrap:
            self._trace("SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)")
        if self.ref and motion == 870:
            for letter in "ijk":
                if letter not in self.cycle:
                    raise block.error(f"{letter.upper()} word missing with "
                                      "g87", key)
        if self.ref and motion in (730, 830) and \
                self.cycle.get("q", 0) <= 0:
            raise block.error(f"Q word missing with g{motion // 10}", key)
        if self.ref and motion in (820, 860, 880, 890) and \
                "p" not in self.cycle:
            raise block.error("Dwell time p word missing with "
                              f"g{motion // 10}", key)
        for _ in range(repeats):
            for axis in (a1, a2):
                letter = AXES[axis]
                if letter in block.words:
                    value = block.words[letter] * self._k(axis)
                    prog[axis] = prog[axis] + value if incremental else value
            self._traverse(self._to_machine(prog), line)
            if not (self.ref and prog[d] == r):
                prog[d] = r
                self._traverse(self._to_machine(prog), line)
            if self.ref and motion in (840, 860, 870, 880, 890):
                self._reference_cycle_body(motion, prog, d, bottom, clear,
                                           line)
                continue
            self._cycle_body(motion, prog, d, r, bottom, line)
            prog[d] = clear
            self._traverse(self._to_machine(prog), line)
        if self.ref and wrap:
            self._emit(C.SetTermCond(
                {610: "exact_path", 611: "exact_stop"}.get(
                    self.modal.control, "blend"),
                self.blend[0], self.blend[1], line))

    def _reference_cycle_body(self, motion: int, prog: list[float], d: int,
                              bottom: float, clear: float, line: int) -> None:
        """G84, G86, G88 and G89 as the reference's rs274 runs them: they
        end at the clear plane themselves (G88: where the operator
        withdrew the tool), without the final rapid of the others."""
        def feed(z: float) -> None:
            prog[d] = z
            end = self._to_machine(prog)
            self._emit(C.StraightFeed(_pose(end), self.feed, line))
            self.pos = end

        dwell = self.cycle.get("p", 0.0)
        direction = 1 if self.modal.spindle == 30 else -1
        if motion == 870:
            self._back_bore(prog, d, bottom, clear, direction, line)
            return
        if motion == 840 and self.modal.spindle != 30:
            block = self.line_block
            assert block is not None
            raise block.error("Spindle not turning in G84"
                              if self.modal.spindle == 50 else
                              "Spindle turning counterclockwise in G84",
                              code_key("g", 84))
        if motion == 840:
            self._trace("DISABLE_FEED_OVERRIDE()")
            self._trace("DISABLE_SPEED_OVERRIDE(0)")
        feed(bottom)
        if motion == 840:
            self._emit(C.SpindleOff(line))
            self._emit(C.SpindleOn(-1, self.speed, line))
            self._emit(C.Dwell(dwell, line))
            feed(clear)
            self._emit(C.SpindleOff(line))
            self._emit(C.SpindleOn(1, self.speed, line))
            self._trace("ENABLE_FEED_OVERRIDE()")
            self._trace("ENABLE_SPEED_OVERRIDE(0)")
            return
        if dwell > 0:
            self._emit(C.Dwell(dwell, line))
        if motion == 890:
            feed(clear)
        elif motion == 860:
            self._emit(C.SpindleOff(line))
            prog[d] = clear
            self._traverse(self._to_machine(prog), line)
            self._emit(C.SpindleOn(direction, self.speed, line))
        else:
            self._emit(C.SpindleOff(line))
            self._emit(C.ProgramPause(line))
            self._emit(C.SpindleOn(direction, self.speed, line))

    def _back_bore(self, prog: list[float], d: int, bottom: float,
                   clear: float, direction: int, line: int) -> None:
        """G87 as the reference's rs274 runs it: off to the side by I/J,
        spindle stopped and oriented, down below the part, back to the
        centre, bore up to K and down again, then out the same way."""
        block = self.line_block
        assert block is not None
        a1, a2, _, _ = PLANES[self.modal.plane]
        words = self.cycle
        k = self._k()
        x, y = prog[a1], prog[a2]
        off_x, off_y = x + words["i"] * k, y + words["j"] * k
        top = words["k"] * k

        def go(px: float, py: float, z: float, feed: bool = False) -> None:
            prog[a1], prog[a2], prog[d] = px, py, z
            end = self._to_machine(prog)
            if feed:
                self._emit(C.StraightFeed(_pose(end), self.feed, line))
                self.pos = end
            else:
                self._traverse(end, line)

        go(off_x, off_y, prog[d])
        orient = f"ORIENT_SPINDLE(0, 0.0000, {2 if direction > 0 else 3})"
        self._emit(C.SpindleOff(line))
        self._trace(orient)
        go(off_x, off_y, bottom)
        go(x, y, bottom)
        self._emit(C.SpindleOn(direction, self.speed, line))
        go(x, y, top, feed=True)
        go(x, y, bottom, feed=True)
        self._emit(C.SpindleOff(line))
        self._trace(orient)
        go(off_x, off_y, bottom)
        go(off_x, off_y, clear)
        go(x, y, clear)
        self._emit(C.SpindleOn(direction, self.speed, line))

    def _cycle_body(self, motion: int, prog: list[float], d: int, r: float,
                    bottom: float, line: int) -> None:
        def rapid(z: float) -> None:
            prog[d] = z
            self._traverse(self._to_machine(prog), line)

        def feed(z: float) -> None:
            prog[d] = z
            end = self._to_machine(prog)
            self._emit(C.StraightFeed(_pose(end), self.feed, line))
            self.pos = end

        if motion in (730, 830):
            q = self.cycle["q"] * self._k()
            delta = 0.254 if self.machine_metric else 0.01
            depth = r
            while depth > bottom:
                target = max(depth - q, bottom)
                feed(target)
                depth = target
                if depth <= bottom:
                    break
                if motion == 830:
                    rapid(r)
                    rapid(depth + delta)
                else:
                    rapid(depth + delta)
            return
        feed(bottom)
        if motion == 840:
            self._emit(C.SpindleOff(line))
            self._emit(C.SpindleOn(-1, self.speed, line))
        if motion in (820, 840, 880, 890) and self.cycle.get("p", 0) > 0:
            self._emit(C.Dwell(self.cycle["p"], line))
        if motion in (850, 890):
            feed(r)
        elif motion == 840:
            feed(r)
            self._emit(C.SpindleOff(line))
            self._emit(C.SpindleOn(1, self.speed, line))
        elif motion == 880:
            self._emit(C.SpindleOff(line))
            self._emit(C.ProgramPause(line))
            self._emit(C.SpindleOn(1 if self.modal.spindle == 30 else -1,
                                   self.speed, line))
        elif motion == 860:
            self._emit(C.SpindleOff(line))
            rapid(r)
            if self.modal.spindle != 50:
                self._emit(C.SpindleOn(1 if self.modal.spindle == 30 else -1,
                                       self.speed, line))

    # -- user M-codes M100-M199 ------------------------------------------
    def _user_m_path(self, block: Block, code: int) -> str:
        """The executable of a user M-code, checked when the block is
        read, as the reference does: unknown without one."""
        number = code // 10
        path = self.user_m(number) if self.user_m is not None else None
        if path is None:
            # (the reference's words; the M-code search path has no
            # executable file M<number>)
            raise block.error(f"Unknown m code used: M{number}",
                              f"m{number}")
        return path

    def _user_m_code(self, block: Block, code: int) -> None:
        """Run the program of M100-M199 with P and Q (the machine waits
        for it, at rest, before the program goes on)."""
        path = self._user_m_path(block, code)
        self._emit(C.UserMCode(code // 10, path, block.words.get("p", -1.0),
                               block.words.get("q", -1.0), block.line))

    # -- predefined named parameters -------------------------------------
    def _ini_value(self, name: str) -> Optional[float]:
        """``#<_ini[section]key>``: section and key upper case, as the
        reference looks them up; None (not defined) unless numeric."""
        if self.ini is None:
            return None
        section, _, key = name[len("_ini["):].partition("]")
        text = self.ini(section.upper(), key.upper())
        if text is None:
            return None
        try:
            return float(text)
        except ValueError:
            return None

    def _predefined(self, name: str) -> Optional[float]:
        if name in _NOT_PREDEFINED and self.remap is None:
            return None         # a global name of the program's own
        asked = name
        name = name.strip("<>").lower()
        if name.startswith("_ini[") and "]" in name:
            return self._ini_value(name)
        if self.remap is not None:      # REMAP=, the [PYTHON] namedparams
            found = self.remap.named_param(self, name)
            if found is not None:
                return found
        if name == "_remap_level":
            return float(self.remap.level if self.remap is not None else 0)
        if name.startswith("_hal[") and name.endswith("]"):
            # read when the block is evaluated (a machine reads ahead of
            # motion: M66 E0 L0 before it waits for the moves)
            if self.hal_value is None:
                return None
            return self.hal_value(name[len("_hal["):-1])
        if name.isdigit():              # #5420..#5428
            i = int(name) - 5420
            return self.program_position()[i] / self._k(i)
        if len(name) == 2 and name[1] in AXES:
            i = AXES.index(name[1])
            return self.program_position()[i] / self._k(i)
        if name.startswith("_abs_") and len(name) == 6 and name[5] in "xyzabc":
            i = AXES.index(name[5])     # machine coordinates, program units
            return self.pos[i] / self._k(i)
        value = _PREDEFINED.get(name)
        if value is None:
            if self.remap is None and len(_NOT_PREDEFINED) < 10_000:
                _NOT_PREDEFINED.add(asked)
            return None
        return value(self, self.modal)


#: Names that :meth:`Interpreter._predefined` found no value for, without
#: a remap (an answer that depends on the name only): answered at once.
_NOT_PREDEFINED: set[str] = set()


#: The read-only predefined named parameters: name -> its value, from the
#: interpreter and its modal state (computed when the name is read).
_PREDEFINED: dict[str, Callable[[Interpreter, ModalState], float]] = {
    "_feed": lambda i, m: i.feed / i._k(),
    "_rpm": lambda i, m: i.speed,
    "_metric": lambda i, m: float(i.program_metric),
    "_imperial": lambda i, m: float(not i.program_metric),
    "_absolute": lambda i, m: float(m.distance == 900),
    "_incremental": lambda i, m: float(m.distance == 910),
    "_inverse_time": lambda i, m: float(m.feed_mode == 930),
    "_units_per_minute": lambda i, m: float(m.feed_mode == 940),
    "_coord_system": lambda i, m: float(m.coord_system),
    "_motion_mode": lambda i, m: float(m.motion),
    "_plane": lambda i, m: float(m.plane),
    "_ccomp": lambda i, m: float(m.cutter_comp),
    "_tool_offset": lambda i, m: float(m.tool_length != 490),
    "_retract_r_plane": lambda i, m: float(m.retract == 990),
    "_retract_old_z": lambda i, m: float(m.retract == 980),
    "_spindle_on": lambda i, m: float(m.spindle != 50),
    "_spindle_cw": lambda i, m: float(m.spindle == 30),
    "_mist": lambda i, m: float(m.mist),
    "_flood": lambda i, m: float(m.flood),
    "_current_tool": lambda i, m: float(i.current_tool),
    "_selected_tool": lambda i, m: float(i.selected_tool),
    "_selected_pocket": lambda i, m: float(i.selected_pocket),
    "_line": lambda i, m: float(i.line),
    # the LinuxCNC version whose language this is (2.9.0)
    "_vmajor": lambda i, m: 2.9,
    "_vminor": lambda i, m: 0.0,
    "_task": lambda i, m: float(i.task),
    "_call_level": lambda i, m: float(
        i.program.call_level if i.program is not None else 0),
    "_units_per_rev": lambda i, m: float(m.feed_mode == 950),
    "_spindle_rpm_mode": lambda i, m: float(m.spindle_mode == 970),
    "_spindle_css_mode": lambda i, m: float(m.spindle_mode == 960),
    "_ijk_absolute_mode": lambda i, m: float(m.arc_distance == 901),
    "_lathe_diameter_mode": lambda i, m: float(i.diameter_mode),
    "_lathe_radius_mode": lambda i, m: float(not i.diameter_mode),
    "_feed_override": lambda i, m: float(i.override_enables["feed"]),
    "_speed_override": lambda i, m: float(i.override_enables["speed"]),
    "_adaptive_feed": lambda i, m: float(i.override_enables["adaptive"]),
    "_feed_hold": lambda i, m: float(i.override_enables["hold"]),
    "_current_pocket": lambda i, m: float(i.current_pocket()),
}
