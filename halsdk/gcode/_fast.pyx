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
    bint PyUnicode_IS_ASCII(object o)
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


#: the powers of ten that a double holds exactly
cdef double _POW10[23]
for _i in range(23):
    _POW10[_i] = 10.0 ** _i


cdef double _value(const char *s, Py_ssize_t start,
                   Py_ssize_t end) except? -1.0:
    """The value of the number ``s[start:end]`` that :func:`_number`
    found: what ``float()`` gives for it, the nearest double."""
    cdef char buf[72]
    cdef Py_ssize_t size = end - start, i = start
    cdef unsigned long long mantissa = 0
    cdef int significant = 0, fraction = 0
    cdef bint negative = False, point = False
    cdef char c
    cdef double value
    # up to 15 significant digits and 22 decimals: the digits as an
    # integer and the power of ten are both exact doubles, so their
    # quotient, one rounding, is the nearest double to the number (the
    # exact case of decimal conversion); else Python's conversion
    if s[i] == 43 or s[i] == 45:
        negative = s[i] == 45
        i += 1
    while i < end:
        c = s[i]
        i += 1
        if c == 46:
            point = True
            continue
        if mantissa or c != 48:
            significant += 1
        mantissa = mantissa * 10 + <unsigned long long>(c - 48)
        if point:
            fraction += 1
    if significant <= 15 and fraction <= 22:
        value = <double>mantissa
        if fraction:
            value = value / _POW10[fraction]
        return -value if negative else value
    memcpy(buf, s + start, size)
    buf[size] = 0
    return PyOS_string_to_double(buf, NULL, None)


def simple_words(str text):
    """``(N number or None, [(letter, value, column), ...])`` of a line of
    plain numbered words (letters lower case, columns 1-based), or None
    when the line needs the full lexer.  ``text`` has no line end."""
    return _simple_words(text)


cdef enum:
    # most words a line read by _scan may have (more: the full lexer)
    MAX_WORDS = 48


cdef struct Words:
    # a line of plain numbered words, read by _scan
    int count                   # words, in source order:
    char letter[MAX_WORDS]      # 0..25 (a..z)
    double value[MAX_WORDS]
    Py_ssize_t column[MAX_WORDS]  # 1-based
    bint has_n                  # an N word, with its number
    double n
    unsigned int seen           # a bit per letter, G and M excluded
    double by_letter[26]        # the value of each letter of ``seen``
    int g, m                    # how many G and M words
    double g0                   # the first G number


cdef bint _scan(const char *s, Py_ssize_t n, Words *w) except -1:
    """Read the plain numbered words of ``s[:n]`` into ``w``: False when
    the line needs the full lexer (anything else, or a non-ASCII byte)."""
    cdef Py_ssize_t pos = 0, end, column
    cdef char c
    cdef unsigned int bit
    cdef int letter
    cdef double value
    w.count = 0
    w.has_n = False
    w.seen = 0
    w.g = 0
    w.m = 0
    while pos < n and _space(s[pos]):
        pos += 1
    if pos < n and (s[pos] == 110 or s[pos] == 78):       # n N
        pos += 1
        while pos < n and _space(s[pos]):
            pos += 1
        if pos >= n or not _digit(s[pos]):
            return False
        end = _number(s, pos, n, False)
        if end - pos > 64:
            return False
        w.has_n = True
        w.n = _value(s, pos, end)
        pos = end
        while pos < n and _space(s[pos]):
            pos += 1
    while pos < n:
        c = s[pos]
        if 65 <= c <= 90:
            c = c + 32
        if not (97 <= c <= 122) or c == 110 or c == 111:   # not n, o
            return False
        letter = c - 97
        column = pos + 1
        pos += 1
        while pos < n and _space(s[pos]):
            pos += 1
        end = _number(s, pos, n, True)
        if end < 0 or end - pos > 64 or w.count == MAX_WORDS:
            return False
        value = _value(s, pos, end)
        if c == 103:                                       # g
            if w.g == 0:
                w.g0 = value
            w.g += 1
        elif c == 109:                                     # m
            w.m += 1
        else:
            bit = 1u << letter
            if w.seen & bit:
                return False        # two X words: parse_line says where
            w.seen |= bit
            w.by_letter[letter] = value
        w.letter[w.count] = letter
        w.value[w.count] = value
        w.column[w.count] = column
        w.count += 1
        pos = end
        while pos < n and _space(s[pos]):
            pos += 1
    return True


cdef object _words_of(Words *w):
    """What :func:`simple_words` gives for the words of ``w``."""
    cdef list words = []
    cdef int i
    for i in range(w.count):
        words.append((_LETTERS[<int>w.letter[i]], w.value[i], w.column[i]))
    return (w.n if w.has_n else None), words


cdef object _simple_words(str text):
    cdef Py_ssize_t n
    cdef const char *s
    cdef Words w
    if not PyUnicode_IS_ASCII(text):
        return None
    s = PyUnicode_AsUTF8AndSize(text, &n)
    if not _scan(s, n, &w):
        return None
    return _words_of(&w)


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


def candidate_lines(bytes chunk, Py_ssize_t end):
    """The lines of ``chunk[:end]`` that may be o-word or '%' lines (they
    hold an 'o', 'O' or '%'), for the first pass over a program file:
    ``(count, found)``, the number of lines of ``chunk[:end]`` (a last
    one without its line end counted) and a list of ``(line, start,
    stop)``: the line's number in the chunk (from 0) and where its text
    is, without its '\\n'."""
    cdef const char *s = chunk
    cdef Py_ssize_t i, start = 0, line = 0
    cdef bint hit = False
    cdef char c
    cdef list found = []
    if end > len(chunk):
        raise ValueError("end past the chunk")
    for i in range(end):
        c = s[i]
        if c == 10:
            if hit:
                found.append((line, start, i))
                hit = False
            line += 1
            start = i + 1
        elif c == 111 or c == 79 or c == 37:        # o O %
            hit = True
    if start < end:
        if hit:
            found.append((line, start, end))
        line += 1
    return line, found


#: what :func:`read_line` gives for a plain line without words
EMPTY = ("empty line",)
#: the class of streamed program files (program._FileLines, set by it)
cdef object _FileLines = None


#: the class of programs held in memory (program._TextLines, set by it)
cdef object _TextLines = None


def set_file_lines(cls, text_cls=None):
    """Tell :func:`read_line` the class of streamed files (and
    :func:`run_plain` the class of programs in memory)."""
    global _FileLines, _TextLines
    _FileLines = cls
    if text_cls is not None:
        _TextLines = text_cls


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
    cdef object text, source, raw
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
        entry = _entry(unit, index, text)
    return _ready(unit, index, entry)


cdef object _entry(object unit, Py_ssize_t index, str text):
    """The entry of line ``index`` read from ``text``: the fast path's
    (text, N number, words), a ``Line``, or the ``GCodeError`` of a line
    that cannot be read; kept when the line is in a keep range."""
    cdef object entry, simple
    cdef list starts
    cdef Py_ssize_t at
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
            unit._kept[index] = entry
    return entry


cdef inline object _ready(object unit, Py_ssize_t index, object entry):
    """What read_line gives for ``entry``."""
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


cdef inline long _coord_base(object modal) except -1:
    """20 times the number of the active coordinate system (G54: 1): the
    offset of its parameters from #5201 (its X) and #5210 (its R)."""
    return 20 * (_COORD_CODES.index(modal.coord_system) + 1)


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
    base = 5201 + _coord_base(modal)
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


cdef bint _block_ready(object interp, object block) except -1:
    """Whether the state lets the short path take ``block``: it knows
    neither G7 diameters, nor a rotated coordinate system, nor the M73
    restore, nor an arc's turns (a P word, checked before the line
    runs), nor the reference's extra calls of ``rs274`` (its feed calls
    among them), nor the comments of a line (maybe a LOG, PROBEOPEN or
    py comment)."""
    cdef dict words = block.words
    cdef bint ref = interp.ref
    cdef object modal
    cdef str axis
    if interp.diameter_mode or interp._autosaved or "p" in words \
            or ("f" in words and ref) or block.comments:
        return False
    modal = interp.modal
    if ref:
        if modal.feed_mode == 930:
            return False
        for axis in _AXES:
            if axis in words:
                break
        else:
            return False
    return not interp.params.get(5210 + _coord_base(modal))  # G10 L2 R


def fast_move(object interp, object block):
    """``Interpreter._fast``: execute a plain move (G0-G3 or the modal
    motion; axis words, F and arc words only; no cutter compensation)
    as ``Interpreter.execute`` does, in fewer steps; False, having
    changed nothing, for any other block, or in a state it does not
    know (:func:`_block_ready`).

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
    if block.m or len(g) > 1 or block.message is not None \
            or not _block_ready(interp, block):
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
    f = words.get("f")
    if f is not None:
        # Interpreter._execute's F word (not the reference's calls)
        if f < 0:
            raise block.error("Negative f word used", "f")
        interp.feed_value = f
        if modal.feed_mode == 940:
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


# -- the read-execute loop of plain moves ------------------------------------

from cpython.object cimport PyObject_GenericSetAttr
from cpython.bytes cimport PyBytes_AS_STRING, PyBytes_GET_SIZE

from .cutter_radius import CutterComp

cdef object _CutterComp = CutterComp
cdef str _DICT = "__dict__"
#: the letters a plain move may have: axes, centre words, R, P (a bit per
#: letter); F is for fast_move (the feed's bookkeeping)
cdef unsigned int _AXIS_BITS = 0
cdef unsigned int _ARC_BITS = 0
for _c in "xyzabcuvw":
    _AXIS_BITS |= 1u << (ord(_c) - 97)
for _c in "ijkrp":
    _ARC_BITS |= 1u << (ord(_c) - 97)
cdef int _I = ord("i") - 97
cdef int _R = ord("r") - 97
cdef int _P = ord("p") - 97
#: the motion codes as the modal state holds them (G0 .. G3)
cdef tuple _MOTIONS = (0, 10, 20, 30)
#: _AXES as letter numbers
cdef int _AXIS_LETTER[9]
for _i, _c in enumerate(_AXES):
    _AXIS_LETTER[_i] = ord(_c) - 97


cdef struct Machine:
    # what run_plain reads of the interpreter once per call (plain moves
    # change none of it but the position and the motion mode)
    double g5x[9]
    double g92[9]
    double tlo[9]
    double k                # program units -> machine units
    double tol              # Interpreter._arc's radius tolerance
    double feed
    bint incremental        # G91
    bint relative_centres   # G91.1
    int a1, a2              # the plane's axes
    int w1, w2, other       # its centre words (letter numbers)


cdef inline bint _in_ranges(list starts, list ends, Py_ssize_t index):
    """True if ``index`` is in one of the sorted (start, end) ranges."""
    cdef Py_ssize_t at = bisect.bisect_right(starts, index) - 1
    return at >= 0 and index <= <Py_ssize_t>ends[at]


cdef inline object _command(object cls, dict fields):
    """An instance of the frozen dataclass ``cls`` holding ``fields``
    (what its __init__ stores; see _plain)."""
    command = _new(cls)
    PyObject_GenericSetAttr(command, _DICT, fields)
    return command


cdef bint _ready_state(object interp, object modal, Machine *m) except -1:
    """Read the state into ``m``; False when it is one that the short
    path does not know (see _block_ready and fast_move): the
    reference's calls, G7, a rotated coordinate system, the M73
    restore, inverse time, cutter compensation."""
    cdef dict numbered
    cdef list g92, tlo
    cdef int base, i
    cdef object comp = interp.comp
    cdef object plane
    if (interp.ref or interp.diameter_mode or interp._autosaved
            or modal.feed_mode == 930
            or type(comp) is not _CutterComp or comp.active
            or comp._pending is not None):
        return False
    if not (_DIRECT_FEED and _DIRECT_TRAVERSE and _DIRECT_ARC):
        return False
    base = _coord_base(modal)
    if interp.params.get(5210 + base):
        return False                        # G10 L2 R: rotated
    numbered = interp.params._numbered
    g92 = interp.g92
    tlo = interp.tlo
    for i in range(9):
        m.g5x[i] = numbered.get(5201 + base + i, 0.0)
        m.g92[i] = g92[i]
        m.tlo[i] = tlo[i]
    m.k = _factor(interp, modal)
    m.tol = 0.005 if interp.machine_metric else 0.0005
    m.feed = interp.feed
    m.incremental = modal.distance == 910
    m.relative_centres = modal.arc_distance != 901
    plane = modal.plane
    if plane not in _PLANES:
        return False
    m.a1, m.a2, _, centre = _PLANES[plane]
    m.w1 = ord(centre[0]) - 97
    m.w2 = ord(centre[1]) - 97
    m.other = ord(_OTHER_CENTRE[plane]) - 97
    return True


def run_plain(object unit, Py_ssize_t index, object interp,
              bint main_flow):
    """Execute the plain moves of ``unit`` from line ``index`` on with
    ``interp`` (what ``Interpreter.execute`` does with their blocks,
    without making the blocks) until a line that they cannot take.

    Gives ``(index, entry, ran)``: that line's index, what
    :func:`read_line` gives for it, and whether any move ran.  A plain
    move is a line :func:`simple_words` reads holding G0-G3 (or
    nothing: the modal motion), axis words, and the centre words and P
    of a centre-format arc with relative centres, in a state that
    :func:`fast_move` takes; with ``main_flow``, not a line of a
    subroutine definition.  Everything else is the caller's, and so is
    every error: a move that would fail is not run here but handed back
    as its Block.  The property tests of tests/gcode/
    test_gcode_fastpath.py hold it to the general path.
    """
    cdef dict kept = unit._kept
    cdef dict owords = unit.owords
    cdef object entry = kept.get(index) if kept else None
    # an o-word or another kept line that is not plain (most lines of a
    # loop or a subroutine): handed back before the state is looked at
    if entry is None:
        entry = owords.get(index)
        if entry is not None:
            return index, entry, False
    elif type(entry) is not tuple:
        return index, entry, False
    cdef object source = unit.source
    cdef object structure = unit.structure
    cdef list sub_starts = structure.sub_starts
    cdef list sub_ends = structure.sub_ends
    cdef list keep_starts = unit._keep_starts
    cdef list keep_ends = unit._keep_ends
    cdef list lines = None
    cdef Py_ssize_t count = source.count
    cdef bint is_file = source.__class__ is _FileLines
    cdef bint ran = False, has_axes
    cdef int ready = 0              # 1: the state is in ``m``; -1: no
    cdef Words w
    cdef Machine m
    cdef const char *s
    cdef Py_ssize_t n
    cdef object raw, text, modal = None, emit = None, line
    cdef object motion_now, explicit, plane_code = None
    cdef list pos, end
    cdef double prog[9]
    cdef double e[9]
    cdef double value, c1 = 0.0, c2 = 0.0, r1, r2, p
    cdef int i, motion, turn = 0
    cdef unsigned int letters
    cdef tuple end_tuple
    if not (main_flow and sub_starts):
        sub_starts = None
    if not keep_starts:
        keep_starts = None
    if source.__class__ is _TextLines:
        lines = source.lines
    while True:
        raw = None
        text = None
        entry = kept.get(index) if kept else None
        if entry is None:
            entry = owords.get(index)
            if entry is not None:
                return index, entry, ran
            if index >= count:
                return index, None, ran
            if lines is not None:
                text = lines[index]
            elif is_file and source._file is not None \
                    and index == source._next:
                raw = source._file.readline()
                source._next = index + 1
            else:
                text = source.line(index)
            if keep_starts is not None and \
                    _in_ranges(keep_starts, keep_ends, index):
                if raw is not None:
                    text = raw.decode("utf-8").rstrip("\r\n")
                    raw = None
                entry = _entry(unit, index, text)       # kept
                if type(entry) is not tuple:
                    return index, entry, ran
                text = entry[0]
        elif type(entry) is not tuple:
            return index, entry, ran
        else:
            text = entry[0]
        # the words, read from the bytes of the file or from the text
        if raw is not None:
            s = PyBytes_AS_STRING(raw)
            n = PyBytes_GET_SIZE(raw)
            while n > 0 and (s[n - 1] == 10 or s[n - 1] == 13):
                n -= 1
            if not _scan(s, n, &w):
                text = raw.decode("utf-8").rstrip("\r\n")
                return index, _ready(unit, index, _entry(unit, index, text)), \
                    ran
        elif not PyUnicode_IS_ASCII(text) or not _scan(
                PyUnicode_AsUTF8AndSize(text, &n), n, &w):
            if entry is None:
                entry = _entry(unit, index, text)
            return index, _ready(unit, index, entry), ran
        if sub_starts is not None and \
                _in_ranges(sub_starts, sub_ends, index):
            break                   # the caller skips the definition
        if w.count == 0:
            index += 1              # EMPTY
            continue
        # what fast_move refuses without looking at the state: M codes,
        # G codes other than one G0-G3, words other than axes and arcs'
        letters = w.seen
        if (w.m or w.g > 1 or letters & ~(_AXIS_BITS | _ARC_BITS)
                or (w.g == 1 and not (w.g0 == 0.0 or w.g0 == 1.0
                                      or w.g0 == 2.0 or w.g0 == 3.0))):
            break
        if ready == 0:
            modal = interp.modal
            ready = 1 if _ready_state(interp, modal, &m) else -1
            emit = interp.canon.emit
            plane_code = modal.plane // 10
            # no Block is made: the interpreter names none as the current
            interp.line_block = None
        if ready < 0:
            break
        has_axes = (letters & _AXIS_BITS) != 0
        if w.g == 1:
            motion = <int>w.g0 * 10
            explicit = _MOTIONS[<int>w.g0]
        else:
            explicit = None
            motion_now = modal.motion
            if motion_now is None:
                break
            motion = motion_now
            if motion != 0 and motion != 10 and motion != 20 \
                    and motion != 30:
                break
        if letters & _ARC_BITS and not (
                (motion == 20 or motion == 30)
                and (has_axes or explicit is not None)):
            break
        if motion != 0 and (has_axes or motion != 10) and m.feed <= 0:
            break                   # the general path's error
        if motion == 20 or motion == 30:
            # fast_move's _arc: relative centres, no R; the rest
            # (errors included) is the general path's
            if not m.relative_centres or letters & (1u << _R):
                break
            if not (letters & (1u << m.w1) or letters & (1u << m.w2)) \
                    or letters & (1u << m.other):
                break
        line = index + 1
        # Interpreter._target (not G53, no rotation, no G7)
        if has_axes or motion == 20 or motion == 30:
            pos = interp.pos
            for i in range(9):
                prog[i] = (<double>pos[i] - m.g5x[i] - m.g92[i]
                           - m.tlo[i])
            for i in range(9):
                if letters & (1u << _AXIS_LETTER[i]):
                    value = w.by_letter[_AXIS_LETTER[i]] * (
                        1.0 if 3 <= i <= 5 else m.k)
                    prog[i] = prog[i] + value if m.incremental else value
            for i in range(9):
                e[i] = prog[i] + m.g5x[i] + m.g92[i] + m.tlo[i]
        if motion == 20 or motion == 30:
            # _arc's checks first: a failing arc is the general path's
            c1 = <double>pos[m.a1] + (
                (w.by_letter[m.w1] if letters & (1u << m.w1) else 0.0)
                * m.k)
            c2 = <double>pos[m.a2] + (
                (w.by_letter[m.w2] if letters & (1u << m.w2) else 0.0)
                * m.k)
            r1 = _hypot(<double>pos[m.a1] - c1, <double>pos[m.a2] - c2)
            r2 = _hypot(e[m.a1] - c1, e[m.a2] - c2)
            if r1 < m.tol or r2 < m.tol:
                break               # a zero-radius arc: the general error
            if abs(r1 - r2) > m.tol and abs(r1 - r2) > 0.001 * r1:
                break
            turn = 1
            if letters & (1u << _P):
                p = w.by_letter[_P]
                if p < 1 or abs(p - _round(p)) > 1e-6:
                    break
                turn = int(_round(p))
            if motion == 20:
                turn = -turn
        # run it (fast_move's order)
        interp.line = line
        if explicit is not None:
            modal.motion = explicit
        if motion == 0 or motion == 10:
            if has_axes:
                end = [e[i] for i in range(9)]
                end_tuple = tuple(end)
                if motion == 10:
                    emit(_command(_StraightFeed, {
                        "end": end_tuple, "feed": m.feed, "line": line}))
                else:
                    emit(_command(_StraightTraverse, {
                        "end": end_tuple, "line": line}))
                interp.pos = end
        else:
            end = [e[i] for i in range(9)]
            emit(_command(_ArcFeed, {
                "end": tuple(end), "center": (c1, c2),
                "plane": plane_code, "turn": turn, "feed": m.feed,
                "line": line}))
            interp.pos = end
        ran = True
        index += 1
    # line ``index`` is the caller's
    if entry is None:
        if text is None:
            text = raw.decode("utf-8").rstrip("\r\n")
        entry = _entry(unit, index, text)
    return index, _ready(unit, index, entry), ran
