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
"""

from libc.math cimport (acos, asin, atan2, ceil, cos, exp, fabs, floor,
                        fmod, isfinite, log, pow, round as c_round, sin,
                        sqrt, tan)

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


cdef class Node:
    """A compiled node; this one always gives up.  Nodes do not change
    once made: a copy is the node itself, a pickle gives up (the Python
    tree evaluates)."""

    cdef double ev(self, object p) except? -1.0:
        raise GIVE_UP

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return self

    def __reduce__(self):
        return (_give_up_node, ())


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


cdef class Indirect(Node):
    """``#[expr]``, ``##n``."""
    cdef Node index

    def __cinit__(self, Node index):
        self.index = index

    cdef double ev(self, object p) except? -1.0:
        return _numbered(p, _index(self.index.ev(p)))


cdef class Neg(Node):
    cdef Node operand

    def __cinit__(self, Node operand):
        self.operand = operand

    cdef double ev(self, object p) except? -1.0:
        return -self.operand.ev(p)


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


cdef class Exist(Node):
    cdef str name

    def __cinit__(self, str name):
        self.name = name

    cdef double ev(self, object p) except? -1.0:
        return 1.0 if p.exists(self.name) else 0.0


cdef inline bint _eq(double a, double b):
    return fabs(a - b) < TOLERANCE_EQUAL


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
    cdef object node
    try:
        node = expr.__dict__.get(COMPILED)
    except AttributeError:          # a tree without __dict__
        return _compile(expr)
    if node is None:
        node = _compile(expr)
        expr.__dict__[COMPILED] = node
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


def assign(object program, object line):
    """What ``make_block(program, line)`` does to a line of assignments
    only (no words, no comments): apply them."""
    cdef object params = program.params
    cdef str file = line.file
    cdef long number = line.number
    cdef list values = []
    cdef object key, a, value
    for a in line.assignments:
        key = a.target.index
        if type(key) is not str:
            key = program._parameter_key(a.target, line)
        values.append((key, evaluate(a.value, params, file, number),
                       a.column))
    for key, value, column in values:
        if not _assign(params, key, value):
            program._set(key, value, line, column)


def make_block(object program, object line):
    """``Program._block(line)``: the words of ``line`` evaluated into a
    :class:`Block`, its assignments applied."""
    cdef object params = program.params
    cdef str file = line.file
    cdef long number = line.number
    cdef list g = [], m = [], values = []
    cdef dict words = {}, columns = {}
    cdef list comments = []
    cdef object message = None
    cdef object word, value, key, a, comment, block
    cdef str letter, kind
    cdef double v
    if _DIRECT_BLOCK:
        block = _new(Block)
    else:
        block = Block(file, number, line.text)
    for word in line.words:
        letter = word.letter
        v = evaluate(word.value, params, file, number)
        if letter == "g" or letter == "m":
            value = _round(v, 4)
            key = code_key(letter, value)
            if letter == "g":
                g.append(value)
            else:
                m.append(value)
            columns.setdefault(key, word.column)
            columns.setdefault(letter, word.column)
        else:
            words[letter] = v
            columns[letter] = word.column
    for a in line.assignments:
        key = a.target.index        # ParamRef.key of a name: the name
        if type(key) is not str:
            key = program._parameter_key(a.target, line)
        values.append((key,
                       evaluate(a.value, params, file, number), a.column))
    for key, value, column in values:
        if not _assign(params, key, value):
            program._set(key, value, line, column)
    for comment in line.comments:
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
    d["text"] = line.text
    d["g"] = g
    d["m"] = m
    d["words"] = words
    d["columns"] = columns
    d["comments"] = comments
    d["message"] = message
    d["block_delete"] = line.block_delete
    d["line_number"] = line.line_number
    return block
