# cython: language_level=3, boundscheck=False, wraparound=False
"""The hot path of the G-code reader, compiled.

Most lines of a CAM program are plain numbered words (``G1 X1.2345
Y-0.5 Z0.1``).  :func:`simple_words` reads such a line in one pass over
its characters, with Python's own string-to-float conversion (so the
values are those ``float()`` gives), and :func:`simple_block` turns its
words into a :class:`~halsdk.gcode.block.Block`.  Any other line (a
comment, a parameter, an expression, an o-word, an error ...) is refused
(None) and read by :func:`halsdk.gcode.lexer.parse_line`.
"""

from cpython.unicode cimport PyUnicode_AsUTF8AndSize
from libc.string cimport memcpy

import bisect
import builtins
import dataclasses

from .block import Block, code_key
from .errors import GCodeError
from .lexer import parse_line

cdef extern from "Python.h":
    double PyOS_string_to_double(const char *s, char **endptr,
                                 object overflow_exception) except? -1.0

cdef object _round = builtins.round
#: code_key of G and M numbers, by number (0 is not kept: -0.0 == 0.0)
cdef dict _G_KEYS = {}
cdef dict _M_KEYS = {}
#: round(number, 4) of G and M numbers (0 is not kept: -0.0 == 0.0)
cdef dict _ROUNDED = {}
cdef tuple _LETTERS = tuple(chr(c) for c in range(ord("a"), ord("z") + 1))
cdef object _new_block = Block.__new__
#: Block is a dataclass of these fields that its __init__ only stores
cdef bint _DIRECT_BLOCK = (
    tuple(f.name for f in dataclasses.fields(Block)) == (
        "file", "line", "text", "g", "m", "words", "columns", "comments",
        "message", "block_delete", "line_number")
    and not hasattr(Block, "__post_init__")
    and "__slots__" not in Block.__dict__)


cdef inline bint _space(char c) noexcept nogil:
    return c == 32 or c == 9


cdef inline bint _digit(char c) noexcept nogil:
    return 48 <= c <= 57


cdef inline Py_ssize_t _number(const char *s, Py_ssize_t pos,
                               Py_ssize_t n, bint sign) noexcept nogil:
    """The end of the number at ``pos`` (``[+-]``, digits with an optional
    point, or a point and digits), or -1 when there is none."""
    cdef Py_ssize_t digits = 0
    if sign and pos < n and (s[pos] == 43 or s[pos] == 45):
        pos += 1
    while pos < n and _digit(s[pos]):
        pos += 1
        digits += 1
    if pos < n and s[pos] == 46:
        pos += 1
        while pos < n and _digit(s[pos]):
            pos += 1
            digits += 1
    if digits == 0:
        return -1
    return pos


cdef double _value(const char *s, Py_ssize_t start,
                   Py_ssize_t end) except? -1.0:
    cdef char buf[72]
    cdef Py_ssize_t size = end - start
    memcpy(buf, s + start, size)
    buf[size] = 0
    return PyOS_string_to_double(buf, NULL, None)


def simple_words(str text):
    """``(N number or None, [(letter, value, column), ...])`` of a line of
    plain numbered words (letters lower case, columns 1-based), or None
    when the line needs the full lexer.  ``text`` has no line end."""
    return _simple_words(text)


cdef object _simple_words(str text):
    cdef Py_ssize_t n
    cdef const char *s
    cdef Py_ssize_t pos = 0, end, column
    cdef char c
    cdef unsigned int seen = 0, bit
    cdef int letter
    cdef object line_number = None
    cdef list words = []
    if not text.isascii():
        return None
    s = PyUnicode_AsUTF8AndSize(text, &n)
    while pos < n and _space(s[pos]):
        pos += 1
    if pos < n and (s[pos] == 110 or s[pos] == 78):       # n N
        pos += 1
        while pos < n and _space(s[pos]):
            pos += 1
        if pos >= n or not _digit(s[pos]):
            return None
        end = _number(s, pos, n, False)
        if end - pos > 64:
            return None
        line_number = _value(s, pos, end)
        pos = end
        while pos < n and _space(s[pos]):
            pos += 1
    while pos < n:
        c = s[pos]
        if 65 <= c <= 90:
            c = c + 32
        if not (97 <= c <= 122) or c == 110 or c == 111:   # not n, o
            return None
        letter = c - 97
        column = pos + 1
        pos += 1
        while pos < n and _space(s[pos]):
            pos += 1
        end = _number(s, pos, n, True)
        if end < 0 or end - pos > 64:
            return None
        if c != 103 and c != 109:                          # not g, m
            bit = 1u << letter
            if seen & bit:
                return None         # two X words: parse_line says where
            seen |= bit
        words.append((_LETTERS[letter], _value(s, pos, end), column))
        pos = end
        while pos < n and _space(s[pos]):
            pos += 1
    return line_number, words


def simple_block(str file, int number, str text, object line_number,
                 list words):
    """The :class:`Block` of the words :func:`simple_words` read: what
    ``Program`` makes of the same words through the full lexer."""
    return _simple_block(file, number, text, line_number, words)


cdef object _simple_block(str file, int number, str text,
                          object line_number, list words):
    cdef list g = []
    cdef list m = []
    cdef dict values = {}
    cdef dict columns = {}
    cdef str letter
    cdef object value, column, key, rounded
    cdef dict keys
    for letter, value, column in words:
        if letter == "g" or letter == "m":
            # round(value, 4), slow (it converts to decimal), kept
            rounded = _ROUNDED.get(value)
            if rounded is None:
                rounded = _round(value, 4)
                if value and len(_ROUNDED) < 1024:
                    _ROUNDED[value] = rounded
            value = rounded
            keys = _G_KEYS if letter == "g" else _M_KEYS
            key = keys.get(value)
            if key is None:
                key = code_key(letter, value)
                if value and len(keys) < 1024:
                    keys[value] = key
            if letter == "g":
                g.append(value)
            else:
                m.append(value)
            columns.setdefault(key, column)
            columns.setdefault(letter, column)
        else:
            values[letter] = value
            columns[letter] = column
    if not _DIRECT_BLOCK:
        return Block(file, number, text, g, m, values, columns, [], None,
                     False, line_number)
    # what Block(...) stores, without running its __init__
    block = _new_block(Block)
    block.__dict__ = {"file": file, "line": number, "text": text, "g": g,
                      "m": m, "words": values, "columns": columns,
                      "comments": [], "message": None,
                      "block_delete": False, "line_number": line_number}
    return block


#: what :func:`read_line` gives for a plain line without words
EMPTY = ("empty line",)
#: the class of streamed program files (program._FileLines, set by it)
cdef object _FileLines = None


def set_file_lines(cls):
    """Tell :func:`read_line` the class of streamed files."""
    global _FileLines
    _FileLines = cls


def read_line(object unit, Py_ssize_t index):
    """Line ``index`` of a program's ``_Unit``, ready to run: a new
    :class:`Block` for a plain line (:data:`EMPTY` when it has no words),
    the ``Line`` of another line, the ``GCodeError`` of a line that
    cannot be read, None past the end.

    The lines of loops and subroutine definitions (the unit's keep
    ranges) are kept once read, as they run again.
    """
    cdef dict kept = unit._kept
    cdef object entry = kept.get(index) if kept else None
    cdef object text, simple, source, raw
    cdef list starts
    cdef Py_ssize_t at
    if entry is None:
        entry = unit.owords.get(index)
        if entry is not None:
            return entry
        source = unit.source
        if source.__class__ is _FileLines and source._file is not None \
                and index == source._next and index < source.count:
            # _FileLines.line, sequential
            raw = source._file.readline()
            source._next = index + 1
            text = raw.decode("utf-8").rstrip("\r\n")
        else:
            text = source.line(index)
            if text is None:
                return None
        simple = _simple_words(text)
        if simple is not None:
            entry = (text, simple[0], simple[1])
        else:
            try:
                entry = parse_line(text, unit.file, index + 1)
            except GCodeError as exc:
                entry = exc
        starts = unit._keep_starts
        if starts:
            at = bisect.bisect_right(starts, index) - 1
            if at >= 0 and index <= unit._keep_ends[at]:
                kept[index] = entry
    if type(entry) is tuple:
        if not entry[2]:
            return EMPTY
        return _simple_block(unit.file, index + 1, entry[0], entry[1],
                             entry[2])
    return entry


# -- the interpreter's plain moves ------------------------------------------

import math

from . import canon as C

cdef object _dist = math.dist
cdef tuple _AXES = ("x", "y", "z", "a", "b", "c", "u", "v", "w")
cdef dict _FAST_MOTION = {0.0: 0, 1.0: 10, 2.0: 20, 3.0: 30}
#: interp.COORD_CODES (G54 .. G59.3 in tenths)
COORD_CODES = (540, 550, 560, 570, 580, 590, 591, 592, 593)
cdef tuple _COORD_CODES = COORD_CODES
cdef object _SetFeedRate = C.SetFeedRate
cdef object _StraightFeed = C.StraightFeed
cdef object _StraightTraverse = C.StraightTraverse
cdef object _ArcFeed = C.ArcFeed


cdef bint _plain(object cls, tuple names):
    """True if ``cls`` is a dataclass of just the fields ``names`` that
    its __init__ only stores (no __post_init__, no slots): then an
    instance can be made by filling its __dict__, which is what a frozen
    dataclass's __init__ does, in a third of the time."""
    return (tuple(f.name for f in dataclasses.fields(cls)) == names
            and not hasattr(cls, "__post_init__")
            and "__slots__" not in cls.__dict__)


cdef bint _DIRECT_FEED = _plain(_StraightFeed, ("end", "feed", "line"))
cdef bint _DIRECT_TRAVERSE = _plain(_StraightTraverse, ("end", "line"))
cdef bint _DIRECT_ARC = _plain(
    _ArcFeed, ("end", "center", "plane", "turn", "feed", "line"))
cdef object _new = object.__new__


cdef object _straight_feed(tuple end, object feed, object line):
    if not _DIRECT_FEED:
        return _StraightFeed(end, feed, line)
    command = _new(_StraightFeed)
    command.__dict__.update(end=end, feed=feed, line=line)
    return command


cdef object _straight_traverse(tuple end, object line):
    if not _DIRECT_TRAVERSE:
        return _StraightTraverse(end, line)
    command = _new(_StraightTraverse)
    command.__dict__.update(end=end, line=line)
    return command


cdef object _arc_feed(tuple end, tuple center, object plane, object turn,
                      object feed, object line):
    if not _DIRECT_ARC:
        return _ArcFeed(end, center, plane, turn, feed, line)
    command = _new(_ArcFeed)
    command.__dict__.update(end=end, center=center, plane=plane, turn=turn,
                            feed=feed, line=line)
    return command
cdef object _hypot = math.hypot
cdef object _atan2 = math.atan2
cdef double _PI = math.pi
#: interp.PLANES: plane -> (first axis, second axis, normal axis, centre
#: words)
PLANES = {170: (0, 1, 2, "ij"), 180: (2, 0, 1, "ki"), 190: (1, 2, 0, "jk")}
cdef dict _PLANES = PLANES
cdef dict _OTHER_CENTRE = {170: "k", 180: "j", 190: "i"}


cdef double _factor(object interp, object modal):
    """Interpreter._k(): program units to machine units (linear axes)."""
    if (modal.units == 210) == interp.machine_metric:
        return 1.0
    return 25.4 if interp.machine_metric else 1 / 25.4


cdef list _target(object interp, dict words, object modal):
    """``Interpreter._target(block)`` (not G53): the machine end point
    from the axis words, the same arithmetic in the same order."""
    cdef list g92 = interp.g92
    cdef list tlo = interp.tlo
    cdef list pos = interp.pos
    cdef double prog[9]
    cdef double g5x[9]
    cdef double k
    cdef double value
    cdef bint incremental = modal.distance == 910
    cdef int i, base
    cdef object word
    cdef dict numbered = interp.params._numbered
    # Interpreter._g5x(): the offsets of the active coordinate system
    # (numbers above the subroutine locals: read as Parameters.numbered)
    base = 5201 + 20 * (_COORD_CODES.index(modal.coord_system) + 1)
    for i in range(9):
        g5x[i] = numbered.get(base + i, 0.0)
    k = _factor(interp, modal)
    for i in range(9):
        prog[i] = <double>pos[i] - g5x[i] - <double>g92[i] - <double>tlo[i]
    for i in range(9):
        word = words.get(_AXES[i])
        if word is not None:
            value = <double>word * (1.0 if 3 <= i <= 5 else k)
            prog[i] = prog[i] + value if incremental else value
    return [prog[i] + g5x[i] + <double>g92[i] + <double>tlo[i]
            for i in range(9)]


cdef inline _emit(object interp, object command):
    """Interpreter._emit"""
    if not interp.comp.hold(command):
        interp.canon.emit(command)


def fast_move(object interp, object block):
    """``Interpreter._fast``: execute a plain move (G0-G3 or the modal
    motion; axis words, F and arc words only; no cutter compensation)
    as ``Interpreter.execute`` does, in fewer steps; False, having
    changed nothing, for any other block.

    It does what ``execute``, ``_target``, ``_straight_feed`` and
    ``_traverse`` do for such a block: a change to what a plain move
    does belongs in both places (arcs go to ``Interpreter._arc``).
    """
    cdef list g = block.g
    cdef dict words = block.words
    cdef object explicit, modal, f, end, line, feed
    cdef int motion
    cdef bint has_axes = False, arc_words = False
    cdef str letter
    if block.m or len(g) > 1 or block.message is not None:
        return False
    modal = interp.modal
    if g:
        explicit = _FAST_MOTION.get(g[0])
        if explicit is None:
            return False
        motion = explicit
    else:
        explicit = None
        motion = modal.motion
        if motion != 0 and motion != 10 and motion != 20 and motion != 30:
            return False
    for letter in words:
        if len(letter) == 1 and letter in "xyzabcuvw":
            has_axes = True
        elif letter != "f":
            if len(letter) != 1 or letter not in "ijkrp":
                return False
            arc_words = True
    if arc_words and not ((motion == 20 or motion == 30)
                          and (has_axes or explicit is not None)):
        return False
    if interp.comp.active:
        return False
    line = block.line
    interp.line = line
    interp.line_block = block
    if modal.feed_mode == 940:
        f = words.get("f")
        if f is not None:
            if f < 0:
                raise block.error("Negative f word used", "f")
            interp.feed = interp._len(f)
            interp._emit(_SetFeedRate(interp.feed, line))
    if explicit is not None:
        modal.motion = explicit
    elif not has_axes:
        return True
    if motion == 10:
        if has_axes:
            end = _target(interp, words, modal)
            if modal.feed_mode == 930:
                feed = interp._feed_for(block, _dist(interp.pos, end))
            else:
                feed = interp.feed
                if feed <= 0:
                    raise block.error("Cannot do g1 with zero feed rate", "")
            _emit(interp, _straight_feed(tuple(end), feed, line))
            interp.pos = end
    elif motion == 0:
        if has_axes:
            end = _target(interp, words, modal)
            _emit(interp, _straight_traverse(tuple(end), line))
            interp.pos = end
    elif not _arc(interp, block, words, modal, motion, line):
        interp._arc(block, motion)
    return True


cdef bint _arc(object interp, object block, dict words, object modal,
               int motion, object line) except -1:
    """Interpreter._arc for a centre-format arc with relative centres
    (G91.1), the same checks and arithmetic in the same order; False,
    having done nothing, for the other arcs."""
    cdef int a1, a2, i, turns, turn
    cdef double s1, s2, e1, e2, k, tol, o1, o2, c1, c2, r1, r2
    cdef double r, t0, t1, sweep, planar
    cdef str w1, w2
    cdef list start, end
    cdef object feed, p
    if modal.arc_distance == 901 or "r" in words:
        return False
    a1, a2, _, centre = _PLANES[modal.plane]
    w1, w2 = centre[0], centre[1]
    # the errors of missing centre words, or of the third one, are
    # Interpreter._arc's
    if (w1 not in words and w2 not in words) or \
            _OTHER_CENTRE[modal.plane] in words:
        return False
    start = interp.pos
    end = _target(interp, words, modal)
    s1, s2, e1, e2 = start[a1], start[a2], end[a1], end[a2]
    k = _factor(interp, modal)
    tol = 0.005 if interp.machine_metric else 0.0005
    if w1 not in words and w2 not in words:
        return False
    o1 = <double>words.get(w1, 0.0) * k
    o2 = <double>words.get(w2, 0.0) * k
    c1 = s1 + o1
    c2 = s2 + o2
    r1 = _hypot(s1 - c1, s2 - c2)
    r2 = _hypot(e1 - c1, e2 - c2)
    # an error (P, feed, radii): Interpreter._arc raises it, in the
    # reference's order and words
    if r1 < tol or r2 < tol or (abs(r1 - r2) > tol
                                and abs(r1 - r2) > 0.001 * r1):
        return False
    turns = 1
    if "p" in words:
        p = words["p"]
        if p < 1 or abs(p - _round(p)) > 1e-6:
            return False
        turns = int(_round(p))
    if modal.feed_mode != 930 and interp.feed <= 0:
        return False
    turn = turns if motion == 30 else -turns
    # Interpreter._arc_length
    r = _hypot(s1 - c1, s2 - c2)
    t0 = _atan2(s2 - c2, s1 - c1)
    t1 = _atan2(e2 - c2, e1 - c1)
    sweep = t1 - t0
    if turn > 0:
        while sweep <= 1e-12:
            sweep += 2 * _PI
    else:
        while sweep >= -1e-12:
            sweep -= 2 * _PI
    sweep = abs(sweep) + 2 * _PI * (abs(turn) - 1)
    planar = r * sweep
    length = _hypot(planar, _hypot(*[
        <double>end[i] - <double>start[i] for i in range(9)
        if i != a1 and i != a2]))
    # Interpreter._feed_for
    if modal.feed_mode == 930:
        feed = interp._feed_for(block, length)
    else:
        feed = interp.feed
    _emit(interp, _arc_feed(tuple(end), (c1, c2), modal.plane // 10, turn,
                            feed, line))
    interp.pos = end
    return True
