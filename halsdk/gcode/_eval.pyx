# cython: language_level=3, boundscheck=False, wraparound=False
"""The expressions of G-code values, compiled.

:func:`evaluate` computes what ``expr.evaluate(params, Where(file,
line))`` of :mod:`.expr` computes, faster: the tree of a value is
compiled once into typed nodes (kept on the tree, so the lines of loops
and subroutines, which are kept parsed, compile once) that evaluate
with C doubles and read the parameters straight from the storage of
:class:`~halsdk.gcode.params.Parameters`.

The Python tree stays the reference of behaviour: on anything out of
the ordinary (an error of any kind, a value that is not finite, a power
of a number that is not positive, an unknown parameter) the compiled
nodes give up and the Python tree evaluates the whole value again, so
the values and the errors (message, column) are the Python ones.  The
arithmetic is the one Python does (the same libm functions, the same
constants for degrees; no fused multiply-add), which property tests
check.

:func:`make_block` and :func:`assign_planned` (the blocks of general lines) work
from a :class:`Plan` of the line; the control flow (``_flow.pyx``) keeps
the plans of the lines that run again.
"""

cimport cython
from libc.math cimport (acos, asin, atan2, ceil, cos, exp, fabs, floor,
                        fmod, isfinite, log, pow, round as c_round, sin,
                        sqrt, tan)

cdef extern from "Python.h":
    int _set "PyObject_GenericSetAttr" (object o, object name,
                                        object value) except -1

from .expr import (Atan, Binary, Exists, Function, Negate, Number, ParamRef,
                   Where)
from .params import MAX_PARAMETER, normalize_name

# math.radians and math.degrees multiply by these (CPython's mathmodule.c)
cdef double PI = 3.141592653589793238462643383279502884197
cdef double DEG_TO_RAD = PI / 180.0
cdef double RAD_TO_DEG = 180.0 / PI
cdef double TOLERANCE_EQUAL = 0.0001
cdef long MAX_PARAM = MAX_PARAMETER


class _GiveUp(Exception):
    """Raised by a compiled node: the Python tree must evaluate."""


cdef object GIVE_UP = _GiveUp()
#: the attribute of an expression tree holding its compiled form
cdef str COMPILED = "_compiled"

# operator and function codes
cdef enum:
    OP_POW, OP_MUL, OP_DIV, OP_MOD, OP_ADD, OP_SUB, OP_EQ, OP_NE, OP_GT,
    OP_GE, OP_LT, OP_LE, OP_AND, OP_OR, OP_XOR
cdef dict OPS = {"**": OP_POW, "*": OP_MUL, "/": OP_DIV, "mod": OP_MOD,
                 "+": OP_ADD, "-": OP_SUB, "eq": OP_EQ, "ne": OP_NE,
                 "gt": OP_GT, "ge": OP_GE, "lt": OP_LT, "le": OP_LE,
                 "and": OP_AND, "or": OP_OR, "xor": OP_XOR}
cdef enum:
    F_ABS, F_ACOS, F_ASIN, F_COS, F_SIN, F_TAN, F_EXP, F_FIX, F_FUP, F_ROUND,
    F_LN, F_SQRT
cdef dict FUNCS = {"abs": F_ABS, "acos": F_ACOS, "asin": F_ASIN,
                   "cos": F_COS, "sin": F_SIN, "tan": F_TAN, "exp": F_EXP,
                   "fix": F_FIX, "fup": F_FUP, "round": F_ROUND, "ln": F_LN,
                   "sqrt": F_SQRT}


def _give_up_node():
    return GIVE_UP_NODE


@cython.no_gc
cdef class Node:
    """A compiled node; this one always gives up.  Nodes do not change
    once made: a copy is the node itself, a pickle gives up (the Python
    tree evaluates).  A tree of nodes holds no cycle (nodes, names):
    the cyclic garbage collector need not look at them."""

    cdef double ev(self, object p) except? -1.0:
        raise GIVE_UP

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return self

    def __reduce__(self):
        return (_give_up_node, ())


@cython.no_gc
cdef class Const(Node):
    cdef double value

    def __cinit__(self, double value):
        self.value = value

    cdef double ev(self, object p) except? -1.0:
        return self.value


cdef inline double _as_double(object value) except? -1.0:
    if type(value) is float:
        return <double>value
    return float(value)


@cython.no_gc
cdef class Named(Node):
    """``#<name>``: a local name, or a global (``_``) one that the
    predefined-name callback answers first."""
    cdef str name
    cdef bint underscore

    def __cinit__(self, str name):
        self.name = name
        self.underscore = name.startswith("_")

    cdef double ev(self, object p) except? -1.0:
        cdef object value, fn
        cdef dict table
        if self.underscore:
            fn = p._predefined
            if fn is not None:
                value = fn(self.name)
                if value is not None:
                    return _as_double(value)
            table = p._globals
        else:
            table = p._top.named
        value = table.get(self.name)
        if value is None:
            raise GIVE_UP
        return _as_double(value)


cdef inline double _numbered(object p, long number) except? -1.0:
    """``Parameters.get`` of a valid parameter number."""
    cdef object value, fn
    if 1 <= number <= 30 and len(<list>p._frames) > 1:
        value = (<dict>p._top.numbered).get(number)
        return 0.0 if value is None else _as_double(value)
    if 5420 <= number <= 5428:
        fn = p._predefined
        if fn is not None:
            value = fn(str(number))
            if value is not None:
                return _as_double(value)
    value = (<dict>p._numbered).get(number)
    return 0.0 if value is None else _as_double(value)


@cython.no_gc
cdef class Numbered(Node):
    """``#n`` of a constant number n."""
    cdef long number

    def __cinit__(self, long number):
        self.number = number

    cdef double ev(self, object p) except? -1.0:
        return _numbered(p, self.number)


cdef inline long _index(double value) except -1:
    """The parameter number ``value`` names (what ParamRef.key and
    Parameters._number accept); -1 gives up."""
    cdef double number
    if not isfinite(value):
        raise GIVE_UP
    number = c_round(value)
    if fabs(number - value) > 1e-4 or not 1 <= number <= MAX_PARAM:
        raise GIVE_UP
    return <long>number


@cython.no_gc
cdef class Indirect(Node):
    """``#[expr]``, ``##n``."""
    cdef Node index

    def __cinit__(self, Node index):
        self.index = index

    cdef double ev(self, object p) except? -1.0:
        return _numbered(p, _index(self.index.ev(p)))


@cython.no_gc
cdef class Neg(Node):
    cdef Node operand

    def __cinit__(self, Node operand):
        self.operand = operand

    cdef double ev(self, object p) except? -1.0:
        return -self.operand.ev(p)


@cython.no_gc
cdef class Func(Node):
    cdef Node operand
    cdef int code

    def __cinit__(self, int code, Node operand):
        self.code = code
        self.operand = operand

    cdef double ev(self, object p) except? -1.0:
        cdef double x = self.operand.ev(p)
        cdef double r
        cdef int code = self.code
        if not isfinite(x):
            raise GIVE_UP
        if code == F_ABS:
            r = fabs(x)
        elif code == F_ACOS:
            if not -1 <= x <= 1:
                raise GIVE_UP
            r = acos(x) * RAD_TO_DEG
        elif code == F_ASIN:
            if not -1 <= x <= 1:
                raise GIVE_UP
            r = asin(x) * RAD_TO_DEG
        elif code == F_COS:
            r = cos(x * DEG_TO_RAD)
        elif code == F_SIN:
            r = sin(x * DEG_TO_RAD)
        elif code == F_TAN:
            r = tan(x * DEG_TO_RAD)
        elif code == F_EXP:
            if not x < 709:
                raise GIVE_UP
            r = exp(x)
        elif code == F_FIX:
            r = floor(x) + 0.0      # math.floor gives an int: no -0.0
        elif code == F_FUP:
            r = ceil(x) + 0.0
        elif code == F_ROUND:
            r = floor(fabs(x) + 0.5)
            if not x >= 0:
                r = -r
        elif code == F_LN:
            if not x > 0:
                raise GIVE_UP
            r = log(x)
        elif code == F_SQRT:
            if not x >= 0:
                raise GIVE_UP
            r = sqrt(x)
        else:
            raise GIVE_UP
        if not isfinite(r):
            raise GIVE_UP
        return r


@cython.no_gc
cdef class Atan2(Node):
    cdef Node y
    cdef Node x

    def __cinit__(self, Node y, Node x):
        self.y = y
        self.x = x

    cdef double ev(self, object p) except? -1.0:
        cdef double y = self.y.ev(p)
        cdef double x = self.x.ev(p)
        if not (isfinite(y) and isfinite(x)):
            raise GIVE_UP
        return atan2(y, x) * RAD_TO_DEG


@cython.no_gc
cdef class Exist(Node):
    cdef str name

    def __cinit__(self, str name):
        self.name = name

    cdef double ev(self, object p) except? -1.0:
        return 1.0 if p.exists(self.name) else 0.0


cdef inline bint _eq(double a, double b):
    return fabs(a - b) < TOLERANCE_EQUAL


@cython.no_gc
cdef class Bin(Node):
    cdef Node left
    cdef Node right
    cdef int op

    def __cinit__(self, int op, Node left, Node right):
        self.op = op
        self.left = left
        self.right = right

    cdef double ev(self, object p) except? -1.0:
        cdef double a = self.left.ev(p)
        cdef double b = self.right.ev(p)
        cdef double r
        cdef int op = self.op
        if op == OP_ADD:
            r = a + b
        elif op == OP_SUB:
            r = a - b
        elif op == OP_MUL:
            r = a * b
        elif op == OP_DIV:
            if b == 0:
                raise GIVE_UP
            r = a / b
        elif op == OP_MOD:
            if b == 0 or not (isfinite(a) and isfinite(b)):
                raise GIVE_UP
            if (a >= 0) == (b >= 0):
                r = fmod(a, b)
            else:
                r = a - b * (floor(a / b) + 0.0)
        elif op == OP_POW:
            # Python's float power, for a positive finite base
            if not (a > 0 and isfinite(a) and isfinite(b)):
                raise GIVE_UP
            if b == 0 or a == 1:
                r = 1.0
            else:
                r = pow(a, b)
        elif op == OP_EQ:
            r = 1.0 if _eq(a, b) else 0.0
        elif op == OP_NE:
            r = 0.0 if _eq(a, b) else 1.0
        elif op == OP_GT:
            r = 1.0 if a > b and not _eq(a, b) else 0.0
        elif op == OP_GE:
            r = 1.0 if a > b or _eq(a, b) else 0.0
        elif op == OP_LT:
            r = 1.0 if a < b and not _eq(a, b) else 0.0
        elif op == OP_LE:
            r = 1.0 if a < b or _eq(a, b) else 0.0
        elif op == OP_AND:
            r = 1.0 if a != 0 and b != 0 else 0.0
        elif op == OP_OR:
            r = 1.0 if a != 0 or b != 0 else 0.0
        elif op == OP_XOR:
            r = 1.0 if (a != 0) != (b != 0) else 0.0
        else:
            raise GIVE_UP
        if not isfinite(r):
            raise GIVE_UP
        return r


cdef Node GIVE_UP_NODE = Node()


cdef Node _compile(object expr):
    """The compiled form of the Python tree ``expr``."""
    cdef object cls = type(expr)
    cdef object index, code
    cdef double value, number
    if cls is Number:
        return Const(expr.value)
    if cls is ParamRef:
        index = expr.index
        if isinstance(index, str):
            return Named(normalize_name(index))
        if type(index) is Number:
            value = index.value
            if not isfinite(value):
                return GIVE_UP_NODE
            number = c_round(value)
            if fabs(number - value) > 1e-4 or not 1 <= number <= MAX_PARAM:
                return GIVE_UP_NODE
            return Numbered(<long>number)
        return Indirect(_compile(index))
    if cls is Binary:
        code = OPS.get(expr.op)
        if code is None:
            return GIVE_UP_NODE
        return Bin(code, _compile(expr.left), _compile(expr.right))
    if cls is Negate:
        return Neg(_compile(expr.operand))
    if cls is Function:
        code = FUNCS.get(expr.name)
        if code is None:
            return GIVE_UP_NODE
        return Func(code, _compile(expr.operand))
    if cls is Atan:
        return Atan2(_compile(expr.y), _compile(expr.x))
    if cls is Exists:
        return Exist(expr.name)
    return GIVE_UP_NODE


cdef inline Node compiled(object expr):
    """The compiled node of ``expr``, kept on it (an attribute, set as
    ``object.__setattr__`` sets it: a tree with no room for it is
    compiled again each time)."""
    cdef object node = getattr(expr, COMPILED, None)
    if node is None:
        node = _compile(expr)
        try:
            _set(expr, COMPILED, node)
        except AttributeError:
            pass
    return <Node>node


cpdef double evaluate(object expr, object params, str file,
                      long line) except? -1.0:
    """``expr.evaluate(params, Where(file, line))``, compiled."""
    cdef Node node
    if type(expr) is Number:
        return expr.value
    node = compiled(expr)
    try:
        return node.ev(params)
    except (_GiveUp, GCodeError):
        # the Python tree again: its value, or its error at its place (a
        # parameter the predefined-name callback refuses, for one)
        return expr.evaluate(params, Where(file, line))


# -- the blocks of general lines ---------------------------------------------

import builtins
import dataclasses

from .block import Block, code_key
from .errors import GCodeError
from .params import POSITION, READ_ONLY

cdef object _round = builtins.round
cdef object _new = object.__new__
cdef tuple _BLOCK_FIELDS = ("file", "line", "text", "g", "m", "words",
                            "columns", "comments", "message",
                            "block_delete", "line_number")
#: Block is a dataclass whose __init__ only stores its fields: a block
#: may be made by filling its __dict__
cdef bint _DIRECT_BLOCK = (
    tuple(f.name for f in dataclasses.fields(Block)) == _BLOCK_FIELDS
    and not hasattr(Block, "__post_init__")
    and "__slots__" not in Block.__dict__)
cdef long _READ_ONLY_FIRST = READ_ONLY[0]
cdef long _READ_ONLY_LAST = READ_ONLY[-1]
cdef long _POSITION_FIRST = POSITION[0]
cdef long _POSITION_LAST = POSITION[-1]


cdef bint _assign(object params, object key, double value) except -1:
    """``params.set(key, value)`` for a local name or a writable
    parameter number; False (nothing done) for any other key."""
    cdef long number
    cdef str name
    if type(key) is str:
        name = normalize_name(key)
        if not name or name[0] == "_":
            return False        # an error, or a global: params.set
        (<dict>params._top.named)[name] = value
        return True
    if type(key) is int:
        if not 1 <= key <= MAX_PARAMETER:   # (a Python int of any size)
            return False
        number = key
        if _READ_ONLY_FIRST <= number <= _READ_ONLY_LAST or \
                _POSITION_FIRST <= number <= _POSITION_LAST:
            return False
        if number <= 30 and len(<list>params._frames) > 1:
            (<dict>params._top.numbered)[key] = value
        else:
            (<dict>params._numbered)[key] = value
        return True
    return False


@cython.no_gc
cdef class _Word:
    """A word of a line: its letter, its value's tree and compiled node
    (no cycle through it, as through a Plan)."""
    cdef str letter
    cdef bint code              # a G or M word
    cdef object value, key      # a constant G or M word's value and key
    cdef object expr
    cdef Node node
    cdef object column


@cython.no_gc
cdef class _Assign:
    """An assignment of a line: its target, its value's tree and node."""
    cdef object target          # the ParamRef
    cdef object name            # the target's name, None for a number
    cdef object expr
    cdef Node node
    cdef object column


@cython.no_gc
cdef class Plan:
    """A line read once for :func:`make_planned` and
    :func:`assign_planned`: what they read of the line, and the compiled
    nodes of its values, so that a line that runs again (in a loop, in a
    subroutine) is not looked at again.  Made by :func:`plan`; a line
    must not change once planned.  A plan holds its line and the line's
    trees and nodes, none of which refers back to it: no cycle goes
    through a plan, and the cyclic garbage collector does not look at
    it."""
    cdef object line
    cdef str file
    cdef long number
    cdef str text
    cdef object block_delete, line_number
    cdef list words             # of _Word
    cdef list assigns           # of _Assign
    cdef list comments


cdef inline Node _node_of(object expr):
    if type(expr) is Number:
        return Const(expr.value)
    return compiled(expr)


def plan(object line):
    """The :class:`Plan` of ``line``."""
    cdef Plan p = Plan.__new__(Plan)
    cdef _Word w
    cdef _Assign a
    cdef object word, assignment, index
    p.line = line
    p.file = line.file
    p.number = line.number
    p.text = line.text
    p.block_delete = line.block_delete
    p.line_number = line.line_number
    p.words = []
    p.assigns = []
    p.comments = line.comments
    for word in line.words:
        w = _Word.__new__(_Word)
        w.letter = word.letter
        w.code = w.letter == "g" or w.letter == "m"
        w.expr = word.value
        w.node = _node_of(w.expr)
        w.column = word.column
        if w.code and type(w.node) is Const:
            w.value = _round((<Const>w.node).value, 4)
            w.key = code_key(w.letter, w.value)
        p.words.append(w)
    for assignment in line.assignments:
        a = _Assign.__new__(_Assign)
        a.target = assignment.target
        index = a.target.index      # ParamRef.key of a name: the name
        a.name = index if type(index) is str else None
        a.expr = assignment.value
        a.node = _node_of(a.expr)
        a.column = assignment.column
        p.assigns.append(a)
    return p


cdef inline double _ev(Node node, object expr, object params, str file,
                       long line) except? -1.0:
    """:func:`evaluate` of a planned value."""
    try:
        return node.ev(params)
    except (_GiveUp, GCodeError):
        return expr.evaluate(params, Where(file, line))


cdef int _apply(object program, Plan p) except -1:
    """Apply the assignments of ``p``: every value first, then the
    parameters (the reference's order)."""
    cdef object params = program.params
    cdef list values = []
    cdef _Assign a
    cdef object key, value, column
    for a in p.assigns:
        key = a.name
        if key is None:
            key = program._parameter_key(a.target, p.line)
        values.append((key, _ev(a.node, a.expr, params, p.file, p.number),
                       a.column))
    for key, value, column in values:
        if not _assign(params, key, value):
            program._set(key, value, p.line, column)
    return 0


def assign_planned(object program, Plan p):
    """What :func:`make_planned` does to a line of assignments only (no
    words, no comments): apply them."""
    _apply(program, p)


def make_block(object program, object line):
    """``Program._block(line)``: the words of ``line`` evaluated into a
    :class:`Block`, its assignments applied."""
    return make_planned(program, plan(line))


def make_planned(object program, Plan p):
    """:func:`make_block` of a planned line."""
    cdef object params = program.params
    cdef str file = p.file
    cdef long number = p.number
    cdef object line = p.line
    cdef list g = [], m = []
    cdef dict words = {}, columns = {}
    cdef list comments = []
    cdef object message = None
    cdef object value, key, comment, block
    cdef str letter, kind
    cdef _Word w
    if _DIRECT_BLOCK:
        block = _new(Block)
    else:
        block = Block(file, number, p.text)
    for w in p.words:
        letter = w.letter
        if w.code:
            if w.key is not None:
                value = w.value     # a constant code, ready
                key = w.key
            else:
                value = _round(_ev(w.node, w.expr, params, file, number), 4)
                key = code_key(letter, value)
            if letter == "g":
                g.append(value)
            else:
                m.append(value)
            columns.setdefault(key, w.column)
            columns.setdefault(letter, w.column)
        else:
            words[letter] = _ev(w.node, w.expr, params, file, number)
            columns[letter] = w.column
    if p.assigns:
        _apply(program, p)
    for comment in p.comments:
        kind = comment.kind
        if kind == "msg":
            message = comment.text
        elif kind == "debug" or kind == "print":
            message = program._debug_text(comment.text).strip()
        else:
            comments.append(comment.text)
    d = block.__dict__
    d["file"] = file
    d["line"] = number
    d["text"] = p.text
    d["g"] = g
    d["m"] = m
    d["words"] = words
    d["columns"] = columns
    d["comments"] = comments
    d["message"] = message
    d["block_delete"] = p.block_delete
    d["line_number"] = p.line_number
    return block
