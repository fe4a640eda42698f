# cython: language_level=3, boundscheck=False, wraparound=False
"""The G-code lexer, compiled.

:func:`parse_line` reads an ASCII line into the same :class:`Line`,
words, assignments, o-word and expression trees as the Python lexer of
:mod:`.lexer` (which calls it first), in one pass over the characters.
It does not report errors: on anything the Python lexer would refuse
it returns None, and the Python lexer reads the line again and raises
its error (message and column).  Property tests check that both agree.
"""

from cpython.mem cimport PyMem_Free, PyMem_Malloc
from cpython.unicode cimport PyUnicode_AsUTF8AndSize

from .expr import (BINARY, FUNCTIONS, Atan, Binary, Exists, Function, Negate,
                   Number, ParamRef)
from .lexer import (O_KEYWORDS, Assignment, Comment, Line, OWord, Word,
                    _comment)

cdef extern from "Python.h":
    double PyOS_string_to_double(const char *s, char **endptr,
                                 object overflow_exception) except? -1.0
    # what the dataclass __init__'s "self.name = value" does, without a
    # call: the values stay in the instance (no __dict__ is made)
    int _set "PyObject_GenericSetAttr" (object o, object name,
                                        object value) except -1


class _Fail(Exception):
    """The line is not one the compiled lexer reads."""


cdef object FAIL = _Fail()
#: the keywords, by their text: the strings of O_KEYWORDS, so that the
#: control flow compares them by identity first
cdef dict _KEYWORDS = {k: k for k in O_KEYWORDS}
cdef frozenset _WITH_ARGS = frozenset(("if", "elseif", "while", "repeat",
                                       "return", "endsub", "call"))
cdef frozenset _FUNCTIONS = frozenset(FUNCTIONS)
#: the one-letter strings, by character
cdef list _LETTERS = [chr(i) for i in range(128)]
#: binary operators: (text, precedence) by the first character
cdef dict _PRECEDENCE = {op: BINARY[op][0] for op in BINARY}
cdef object _new = object.__new__


cdef inline bint _is_space(char c):
    # what str.isspace() is true for, in ASCII
    return c == 32 or 9 <= c <= 13 or 28 <= c <= 31


cdef inline bint _is_digit(char c):
    return 48 <= c <= 57


cdef inline bint _is_alpha(char c):
    return 97 <= c <= 122       # the reader's characters are lower case


cdef class _Reader:
    cdef char *s            # the significant characters, lower case
    cdef int *cols          # their 1-based columns
    cdef Py_ssize_t n
    cdef Py_ssize_t pos
    cdef int end_column

    def __dealloc__(self):
        PyMem_Free(self.s)
        PyMem_Free(self.cols)

    cdef inline char peek(self):
        return self.s[self.pos] if self.pos < self.n else 0

    cdef inline char peek1(self):
        return self.s[self.pos + 1] if self.pos + 1 < self.n else 0

    cdef inline int column(self):
        return self.cols[self.pos] if self.pos < self.n else self.end_column

    cdef inline bint at_end(self):
        return self.pos >= self.n

    cdef str text(self, Py_ssize_t start, Py_ssize_t end):
        return self.s[start:end].decode("ascii")

    cdef double unsigned_number(self) except? -1.0:
        cdef Py_ssize_t start = self.pos
        cdef int dots = 0, digits = 0
        cdef char c
        while self.pos < self.n:
            c = self.s[self.pos]
            if c == 46:
                dots += 1
            elif _is_digit(c):
                digits += 1
            else:
                break
            self.pos += 1
        if dots > 1 or not digits:
            raise FAIL
        return self.to_double(start, self.pos)

    cdef double to_double(self, Py_ssize_t start, Py_ssize_t end) \
            except? -1.0:
        """float() of the number text s[start:end]."""
        cdef char buf[64]
        cdef Py_ssize_t size = end - start, i
        if size >= 64:
            return float(self.text(start, end))
        for i in range(size):
            buf[i] = self.s[start + i]
        buf[size] = 0
        return PyOS_string_to_double(buf, NULL, None)

    cdef object number(self):
        cdef int start = self.column()
        cdef Py_ssize_t first = self.pos
        cdef int dots = 0, digits = 0
        cdef char c = self.peek()
        if c == 43 or c == 45:          # + -
            self.pos += 1
        while self.pos < self.n:
            c = self.s[self.pos]
            if c == 46:
                dots += 1
            elif _is_digit(c):
                digits += 1
            else:
                break
            self.pos += 1
        if dots > 1 or not digits:
            raise FAIL
        return _number(self.to_double(first, self.pos), start)

    cdef object real_value(self):
        cdef char c = self.peek()
        cdef char d
        cdef int column = self.column()
        cdef object operand
        if c == 91:                     # [
            return self.bracketed()
        if c == 35:                     # #
            return self.parameter()
        if c == 43 or c == 45:
            d = self.peek1()
            if d == 91 or d == 35 or _is_alpha(d):
                self.pos += 1
                operand = self.real_value()
                if c == 45:
                    return _negate(operand, column)
                return operand
        if _is_alpha(c):
            return self.function()
        return self.number()

    cdef object bracketed(self):
        cdef object value
        self.pos += 1
        value = self.expression(1)
        if self.peek() != 93:           # ]
            raise FAIL
        self.pos += 1
        return value

    cdef str operator(self):
        cdef char c = self.peek()
        cdef char d
        if c == 0:
            return None
        d = self.peek1()
        if c == 42:
            return "**" if d == 42 else "*"
        if c == 47:
            return "/"
        if c == 43:
            return "+"
        if c == 45:
            return "-"
        if c == 109 and d == 111 and self.startswith(b"mod"):
            return "mod"
        if c == 101 and d == 113:
            return "eq"
        if c == 110 and d == 101:
            return "ne"
        if c == 103:
            if d == 116:
                return "gt"
            if d == 101:
                return "ge"
        if c == 108:
            if d == 116:
                return "lt"
            if d == 101:
                return "le"
        if c == 97 and d == 110 and self.startswith(b"and"):
            return "and"
        if c == 111 and d == 114:
            return "or"
        if c == 120 and d == 111 and self.startswith(b"xor"):
            return "xor"
        return None

    cdef bint startswith(self, bytes word):
        cdef Py_ssize_t size = len(word), i
        cdef const char *w = word
        if self.pos + size > self.n:
            return False
        for i in range(size):
            if self.s[self.pos + i] != w[i]:
                return False
        return True

    cdef object expression(self, int min_precedence):
        cdef object left = self.real_value()
        cdef str op
        cdef int precedence, column
        while True:
            op = self.operator()
            if op is None:
                return left
            precedence = _PRECEDENCE[op]
            if precedence < min_precedence:
                return left
            column = self.column()
            self.pos += len(op)
            left = _binary(op, left, self.expression(precedence + 1), column)

    cdef str word(self):
        cdef Py_ssize_t start = self.pos
        while self.pos < self.n and _is_alpha(self.s[self.pos]):
            self.pos += 1
        return self.text(start, self.pos)

    cdef object function(self):
        cdef int column = self.column()
        cdef str name = self.word()
        cdef object y, target
        if name == "atan":
            if self.peek() != 91:
                raise FAIL
            y = self.bracketed()
            if self.peek() != 47:
                raise FAIL
            self.pos += 1
            if self.peek() != 91:
                raise FAIL
            return _atan(y, self.bracketed(), column)
        if name == "exists":
            if self.peek() != 91:
                raise FAIL
            self.pos += 1
            if not (self.peek() == 35 and self.peek1() == 60):
                raise FAIL
            self.pos += 1
            target = self.name()
            if self.peek() != 93:
                raise FAIL
            self.pos += 1
            e = _new(Exists)
            _set(e, "name", target)
            _set(e, "column", column)
            return e
        if name not in _FUNCTIONS:
            raise FAIL
        if self.peek() != 91:
            raise FAIL
        return _function(name, self.bracketed(), column)

    cdef str name(self):
        cdef Py_ssize_t start, end
        self.pos += 1                   # <
        start = self.pos
        end = start
        while end < self.n and self.s[end] != 62:
            end += 1
        self.pos = end
        if end >= self.n or end == start:
            raise FAIL
        self.pos += 1
        return self.text(start, end)

    cdef object parameter(self):
        cdef int column = self.column()
        cdef char c
        self.pos += 1
        c = self.peek()
        if c == 60:                     # <
            return _param(self.name(), column)
        if c == 35:
            return _param(self.parameter(), column)
        if c == 91:
            return _param(self.bracketed(), column)
        if _is_digit(c):
            return _param(self.number(), column)
        raise FAIL

    cdef object oword(self):
        cdef int column = self.column()
        cdef char c
        cdef object name
        cdef str keyword
        cdef list args = []
        self.pos += 1
        c = self.peek()
        if c == 60:
            name = self.name()
        elif c == 91 or c == 35:
            name = self.real_value()
        elif _is_digit(c):
            name = format(self.unsigned_number(), "g")
        else:
            raise FAIL
        keyword = _KEYWORDS.get(self.word())
        if keyword is None:
            raise FAIL
        if keyword in _WITH_ARGS:
            while self.peek() == 91:
                args.append(self.bracketed())
        if keyword in ("if", "elseif", "while", "repeat"):
            if len(args) != 1:
                raise FAIL
        elif keyword in ("return", "endsub") and len(args) > 1:
            raise FAIL
        o = _new(OWord)
        _set(o, "name", name)
        _set(o, "keyword", keyword)
        _set(o, "args", args)
        _set(o, "column", column)
        return o


# -- the nodes, made as their dataclass __init__ makes them ---------------

cdef inline object _number(double value, int column):
    cdef object o = _new(Number)
    _set(o, "value", value)
    _set(o, "column", column)
    return o


cdef inline object _param(object index, int column):
    cdef object o = _new(ParamRef)
    _set(o, "index", index)
    _set(o, "column", column)
    return o


cdef inline object _negate(object operand, int column):
    cdef object o = _new(Negate)
    _set(o, "operand", operand)
    _set(o, "column", column)
    return o


cdef inline object _function(str name, object operand, int column):
    cdef object o = _new(Function)
    _set(o, "name", name)
    _set(o, "operand", operand)
    _set(o, "column", column)
    return o


cdef inline object _atan(object y, object x, int column):
    cdef object o = _new(Atan)
    _set(o, "y", y)
    _set(o, "x", x)
    _set(o, "column", column)
    return o


cdef inline object _binary(str op, object left, object right, int column):
    cdef object o = _new(Binary)
    _set(o, "op", op)
    _set(o, "left", left)
    _set(o, "right", right)
    _set(o, "column", column)
    return o


cdef bint _plain_dataclass(object cls, tuple names):
    """True if instances of ``cls`` may be made by filling their
    attributes (what the dataclass __init__ does): the fields are just
    ``names`` and __init__ does nothing else."""
    import dataclasses
    return (tuple(f.name for f in dataclasses.fields(cls)) == names
            and not hasattr(cls, "__post_init__")
            and "__slots__" not in cls.__dict__)


cdef bint _DIRECT = all([
    _plain_dataclass(Number, ("value", "column")),
    _plain_dataclass(ParamRef, ("index", "column")),
    _plain_dataclass(Negate, ("operand", "column")),
    _plain_dataclass(Function, ("name", "operand", "column")),
    _plain_dataclass(Atan, ("y", "x", "column")),
    _plain_dataclass(Binary, ("op", "left", "right", "column")),
    _plain_dataclass(Exists, ("name", "column")),
    _plain_dataclass(OWord, ("name", "keyword", "args", "column")),
    _plain_dataclass(Word, ("letter", "value", "column")),
    _plain_dataclass(Assignment, ("target", "value", "column")),
    _plain_dataclass(Line, ("file", "number", "text", "block_delete",
                            "line_number", "words", "assignments",
                            "comments", "oword", "percent")),
])


cdef object _line(str file, long number, str text, list comments):
    """``Line(file, number, text, comments=comments)``."""
    cdef object line = _new(Line)
    _set(line, "file", file)
    _set(line, "number", number)
    _set(line, "text", text)
    _set(line, "block_delete", False)
    _set(line, "line_number", None)
    _set(line, "words", [])
    _set(line, "assignments", [])
    _set(line, "comments", comments)
    _set(line, "oword", None)
    _set(line, "percent", False)
    return line


cdef object _read(_Reader r, object line):
    cdef int seen[128]
    cdef int column, i
    cdef char c
    cdef object target, w
    cdef list words, assignments
    if r.peek() == 37:                  # %
        r.pos += 1
        if not r.at_end():
            raise FAIL
        line.percent = True
        return line
    if r.peek() == 47:                  # /
        r.pos += 1
        line.block_delete = True
    if r.peek() == 110:                 # n
        r.pos += 1
        line.line_number = r.unsigned_number()
    if r.peek() == 111:                 # o
        line.oword = r.oword()
        if not r.at_end():
            raise FAIL
        return line
    for i in range(128):
        seen[i] = 0
    words = line.words
    assignments = line.assignments
    while not r.at_end():
        column = r.column()
        c = r.peek()
        if c == 35:                     # #
            target = r.parameter()
            if r.peek() != 61:          # =
                raise FAIL
            r.pos += 1
            w = _new(Assignment)
            _set(w, "target", target)
            _set(w, "value", r.real_value())
            _set(w, "column", column)
            assignments.append(w)
            continue
        if not _is_alpha(c) or c == 111 or c == 110:   # o, n
            raise FAIL
        r.pos += 1
        if c != 103 and c != 109:       # g, m
            if seen[c]:
                raise FAIL
            seen[c] = 1
        w = _new(Word)
        _set(w, "letter", _LETTERS[c])
        _set(w, "value", r.real_value())
        _set(w, "column", column)
        words.append(w)
    return line


def parse_line(str text, str file="<string>", long lineno=1):
    """The :class:`Line` of an ASCII line the Python lexer reads without
    error, the same; None for any other line."""
    cdef Py_ssize_t size, i, n = 0
    cdef const char *raw
    cdef char c
    cdef Py_ssize_t end
    cdef _Reader r
    cdef list comments = []
    if not _DIRECT:
        return None
    text = text.rstrip("\r\n")
    if not text.isascii():
        return None
    raw = PyUnicode_AsUTF8AndSize(text, &size)
    r = _Reader.__new__(_Reader)
    r.s = <char *>PyMem_Malloc(size + 1)
    r.cols = <int *>PyMem_Malloc((size + 1) * sizeof(int))
    if r.s == NULL or r.cols == NULL:
        raise MemoryError()
    i = 0
    while i < size:
        c = raw[i]
        if c == 40:                     # (
            end = i + 1
            while end < size and raw[end] != 41:
                if raw[end] == 40:
                    return None         # nested comment
                end += 1
            if end >= size:
                return None             # unclosed comment
            comments.append(_comment(text[i + 1:end], i + 1))
            i = end + 1
            continue
        if c == 59:                     # ;
            comments.append(_comment_rest(text, i))
            break
        if not _is_space(c):
            if 65 <= c <= 90:
                c += 32
            r.s[n] = c
            r.cols[n] = i + 1
            n += 1
        i += 1
    r.n = n
    r.pos = 0
    r.end_column = size + 1
    line = _line(file, lineno, text, comments)
    try:
        return _read(r, line)
    except _Fail:
        return None


cdef object _comment_rest(str text, Py_ssize_t i):
    return Comment(text[i + 1:].strip(), "", i + 1)
