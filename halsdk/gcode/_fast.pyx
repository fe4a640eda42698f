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

import builtins

from .block import Block, code_key

cdef extern from "Python.h":
    double PyOS_string_to_double(const char *s, char **endptr,
                                 object overflow_exception) except? -1.0

cdef object _round = builtins.round
cdef tuple _LETTERS = tuple(chr(c) for c in range(ord("a"), ord("z") + 1))
cdef object _new_block = Block.__new__


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
    cdef list g = []
    cdef list m = []
    cdef dict values = {}
    cdef dict columns = {}
    cdef str letter
    cdef object value, column, key
    for letter, value, column in words:
        if letter == "g" or letter == "m":
            value = _round(value, 4)
            key = code_key(letter, value)
            if letter == "g":
                g.append(value)
            else:
                m.append(value)
            columns.setdefault(key, column)
            columns.setdefault(letter, column)
        else:
            values[letter] = value
            columns[letter] = column
    block = _new_block(Block)
    block.file = file
    block.line = number
    block.text = text
    block.g = g
    block.m = m
    block.words = values
    block.columns = columns
    block.comments = []
    block.message = None
    block.block_delete = False
    block.line_number = line_number
    return block
