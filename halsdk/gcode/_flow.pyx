# cython: language_level=3
"""The control flow of a G-code program, compiled.

:func:`run` is ``Program._run``: it walks the lines of a program's units
(the main file and the subroutine files) in execution order, runs the
o-word lines (subroutine calls and returns, ``if``, the loops), applies
the lines of assignments only, and yields the :class:`Block` of every
other line.  Each o-word line and each line that runs again (the lines
of loops and subroutines) is turned once into a :class:`_Code`: its
kind as a number, its jump targets as line indexes, its expressions, so
that running it again looks nothing up by name.

With an interpreter (``Program.blocks(interp)``), the plain moves run as
they are read (``_fast.run_plain``), and a line of plain comments only,
which the interpreter would do nothing with but name as the current
line (``Interpreter.inert_comments``), is not handed out.
"""

from ._eval import assign_planned, evaluate, make_planned, plan
from ._fast import EMPTY, read_line, run_plain
from .block import Block
from .errors import GCodeError
from .lexer import Line


cdef enum:
    # lines that are not o-words
    K_LINE          # words or comments: a block
    K_ASSIGN        # assignments only
    K_NOTHING       # nothing to run (a line number, an empty '/')
    K_PERCENT
    # o-words
    K_CALL
    K_RETURN        # return and endsub
    K_SUB
    K_IF
    K_ELSE          # else: on to the line after the endif
    K_ELSEIF        # (the same, reached after its branch)
    K_ENDIF
    K_WHILE
    K_DO_WHILE      # the closing "while" of a do loop
    K_DO
    K_REPEAT
    K_ENDREPEAT
    K_ENDWHILE
    K_BREAK
    K_CONTINUE


cdef dict _KINDS = {
    "call": K_CALL, "return": K_RETURN, "endsub": K_RETURN, "sub": K_SUB,
    "if": K_IF, "elseif": K_ELSEIF, "else": K_ELSE, "endif": K_ENDIF,
    "while": K_WHILE, "do": K_DO, "repeat": K_REPEAT,
    "endrepeat": K_ENDREPEAT, "endwhile": K_ENDWHILE, "break": K_BREAK,
    "continue": K_CONTINUE}


cdef class _Code:
    """One line, ready to run again."""
    cdef int kind
    cdef object line            # its Line
    cdef object oword           # its OWord, or None
    cdef list args              # its OWord's values
    cdef str file
    cdef long number
    cdef Py_ssize_t jump        # where the o-word goes on (see _compile)
    cdef Py_ssize_t opener      # a closer's, break's or continue's loop
    cdef list branches          # an if's: (index, _Code) of its others
    cdef bint comments          # a K_LINE of comments only
    cdef bint inert             # ... that an interpreter does nothing with
    cdef bint block_delete
    cdef object plan            # a K_LINE's or K_ASSIGN's (_eval.plan)
    cdef object target          # a K_CALL's own unit, when it has the sub


cdef _Code _compile(object unit, Py_ssize_t index, object line,
                    object inert_comments):
    """The code of ``line``, line ``index`` of ``unit``."""
    cdef _Code code = _Code.__new__(_Code)
    cdef object oword = line.oword
    cdef object structure
    cdef str keyword
    code.line = line
    code.oword = oword
    code.file = line.file
    code.number = line.number
    code.block_delete = line.block_delete
    if line.percent:
        code.kind = K_PERCENT
        return code
    if oword is None:
        if line.words:
            code.kind = K_LINE
        elif line.comments:
            code.kind = K_LINE
            code.comments = True
            code.inert = (inert_comments is not None
                          and not line.assignments
                          and all([c.kind == "" for c in line.comments])
                          and inert_comments(line.text))
        elif line.assignments:
            code.kind = K_ASSIGN
        else:
            code.kind = K_NOTHING
        if code.kind != K_NOTHING:
            code.plan = plan(line)
        return code
    structure = unit.structure
    keyword = oword.keyword
    code.kind = _KINDS[keyword]
    code.args = oword.args
    if code.kind == K_SUB:
        code.jump = structure.subs[oword.name if isinstance(oword.name, str)
                                   else "?"][1] + 1
    elif code.kind == K_IF:
        code.branches = [(b, _code_of(unit, b))
                         for b in structure.branches[index]]
    elif code.kind == K_ELSE or code.kind == K_ELSEIF:
        code.jump = structure.endif_of[index] + 1
    elif code.kind == K_WHILE:
        if index in structure.loop_start:
            code.kind = K_DO_WHILE
            code.opener = structure.loop_start[index]
        else:
            code.jump = structure.loop_end[index] + 1
    elif code.kind == K_REPEAT:
        code.jump = structure.loop_end[index] + 1
    elif code.kind == K_ENDREPEAT or code.kind == K_ENDWHILE:
        code.opener = structure.loop_start[index]
    elif code.kind == K_BREAK:
        code.opener = structure.loop_of[index]
        code.jump = structure.loop_end[code.opener] + 1
    elif code.kind == K_CONTINUE:
        code.opener = structure.loop_of[index]
        code.jump = code.opener if unit.keyword(code.opener) == "while" \
            else structure.loop_end[code.opener]
    return code


cdef _Code _code_of(object unit, Py_ssize_t index):
    """The code of the o-word line ``index`` of ``unit``, compiled once
    (an if's branches are run from the if and reached on their own)."""
    cdef dict codes = unit._codes
    cdef _Code code = codes.get(index)
    if code is None:
        code = _compile(unit, index, unit.owords[index], None)
        codes[index] = code
    return code


cdef class _Call:
    """A subroutine call in progress: where it returns to, and the
    counts of its repeat loops."""
    cdef object unit
    cdef Py_ssize_t back
    cdef str name
    cdef dict repeats


cdef class _Limits:
    """The runaway limits of one run (``Program``'s ``max_iterations``
    and ``max_idle_time``) and where the run stands against them."""
    cdef object program
    cdef object clock
    cdef long iterations, max_iterations
    cdef double idle_since, max_idle_time

    cdef int count(self, object unit, Py_ssize_t index,
                   str what) except -1:
        """Count one more loop iteration or subroutine call (line
        ``index`` of ``unit``); past a limit it is an error."""
        cdef double idle
        if self.iterations >= self.max_iterations:
            raise self.program._runaway(unit, index, what, None)
        self.iterations += 1
        self.program.iterations = self.iterations
        idle = self.clock() - self.idle_since
        if idle > self.max_idle_time:
            raise self.program._runaway(unit, index, what, idle)
        return 0

    cdef inline void working(self):
        """A block that does something: the idle time starts again."""
        self.idle_since = self.clock()


cdef inline bint _ends(object block):
    """True if the block holds M2 or M30."""
    cdef object m
    for m in block.m:
        if abs(m - 2) < 1e-6 or abs(m - 30) < 1e-6:
            return True
    return False


cdef inline double _value(object expr, object params, _Code code):
    """The value of ``expr``, of the line of ``code``."""
    return evaluate(expr, params, code.file, code.number)


def run(object program, object interp=None):
    """``Program._run``: the blocks of ``program`` in execution order."""
    cdef object unit = program._main
    cdef Py_ssize_t index = 0
    cdef list frames = []
    cdef dict main_repeats = {}, repeats = main_repeats
    cdef bint seen_code = False
    cdef object clock = program.clock
    cdef object params = program.params
    cdef object structure = unit.structure
    cdef dict codes = unit._codes
    cdef dict kept = unit._kept
    cdef object inert_comments = None
    cdef object entry, line, oword, block, target, returned, python, name
    cdef _Code code
    cdef _Call call
    cdef Py_ssize_t first_sub = -1, last_sub = -1, end, opener, b
    cdef bint ran
    cdef double handed
    cdef _Limits limits = _Limits.__new__(_Limits)
    cdef object count
    cdef list args
    limits.program = program
    limits.clock = clock
    limits.iterations = 0
    limits.max_iterations = min(program.max_iterations, 1 << 62)
    limits.idle_since = clock()
    limits.max_idle_time = program.max_idle_time
    if interp is not None:
        inert_comments = interp.inert_comments
    program._frames = frames
    if structure.sub_starts:
        first_sub = structure.sub_starts[0]
        last_sub = structure.sub_ends[-1]
    while True:
        code = codes.get(index)
        entry = None
        if code is None:
            if interp is None:
                entry = read_line(unit, index)
            else:
                # plain moves run at once; the line it stops at is ours
                index, entry, ran = run_plain(unit, index, interp,
                                              not frames)
                if ran:
                    seen_code = True
                    limits.working()
                code = codes.get(index)
            if code is None and entry is None:
                if frames:  # pragma: no cover - the scan rules it out
                    raise GCodeError(
                        f"end of file inside "
                        f"{_label((<_Call>frames[len(frames) - 1]).name)}",
                        unit.file, unit.count, 1)
                return
        if not frames and first_sub >= 0 and first_sub <= index <= last_sub:
            end = structure.sub_end(index)
            if end >= 0:
                # a subroutine definition met in the main flow: skip it
                index = end + 1
                continue
        if code is None:
            if entry.__class__ is Block:
                # the fast path: a line of plain numbered words
                index += 1
                seen_code = True
                clock()
                yield entry
                limits.working()
                if entry.m and _ends(entry):
                    return
                continue
            if entry is EMPTY:
                index += 1
                continue
            if isinstance(entry, GCodeError):
                raise entry
            assert isinstance(entry, Line)
            code = _compile(unit, index, entry, inert_comments)
            if code.oword is not None or kept.get(index) is entry:
                codes[index] = code         # it runs again
        line = code.line
        if code.kind == K_PERCENT:
            if seen_code and unit.percents[0] == index:
                # only a program opened with '%' may close with one
                raise GCodeError("Bad character '%' used", line.file,
                                 line.number, line.text.find("%") + 1)
            if seen_code or unit.percents and unit.percents[0] < index:
                return
            index += 1
            continue
        if code.block_delete and program.block_delete:
            index += 1
            continue
        if code.kind < K_CALL:
            index += 1
            if code.kind == K_ASSIGN:
                assign_planned(program, code.plan)     # no block to hand out
                continue
            if code.kind == K_NOTHING:
                continue
            if code.comments:
                if code.inert and interp is not None and \
                        interp.quiet_comments():
                    # what the interpreter would do with its block
                    interp.line = line.number
                    interp.line_block = None
                    continue
                block = make_planned(program, code.plan)
                handed = clock()
                yield block
                if block.message is not None:
                    limits.working()
                else:   # the time the consumer held it is not idle
                    limits.idle_since += clock() - handed
                continue
            seen_code = True
            block = make_planned(program, code.plan)
            clock()
            yield block
            limits.working()
            if block.m and _ends(block):
                return
            continue

        seen_code = True
        oword = code.oword
        if code.kind == K_CALL:
            name = oword.name if isinstance(oword.name, str) else \
                f"{_value(oword.name, params, code):g}"
            python = program.python_subs(name) if program.python_subs \
                else None
            if python is not None:
                program._python_call(python, oword, line)
                index += 1
                continue
            target = code.target
            if target is None:
                target = program._find_sub(name, unit)
                if target is unit and type(oword.name) is str:
                    # found first in any program that runs this unit
                    code.target = target
            if target is None:
                # (the reference reads on to the end, looking for it)
                raise GCodeError(f"EOF in file:{unit.file} seeking "
                                 f"o-word: o<{name}> from line: "
                                 f"{line.number}", unit.file,
                                 unit.count, 1)
            if len(frames) >= program.max_call_depth:
                raise GCodeError("Too many subroutine levels", line.file,
                                 line.number, oword.column)
            limits.count(unit, index, "subroutine call")
            args = [_value(a, params, code) for a in code.args]
            if len(args) > 30:
                raise GCodeError("Too many subroutine parameters",
                                 line.file, line.number, oword.column)
            params.set_returned(None)
            params.push_scope(args)
            call = _Call.__new__(_Call)
            call.unit = unit
            call.back = index + 1
            call.name = name
            call.repeats = repeats = {}
            frames.append(call)
            unit = target
            structure = unit.structure
            codes = unit._codes
            kept = unit._kept
            index = structure.subs[name][0] + 1
        elif code.kind == K_RETURN:
            if not frames:          # the endsub of a definition run into
                index += 1
                continue
            returned = _value(code.args[0], params, code) \
                if code.args else None
            call = frames.pop()
            params.pop_scope()
            params.set_returned(returned)
            repeats = (<_Call>frames[len(frames) - 1]).repeats if frames \
                else main_repeats
            unit = call.unit
            index = call.back
            structure = unit.structure
            codes = unit._codes
            kept = unit._kept
        elif code.kind == K_SUB:
            index = code.jump
        elif code.kind == K_IF:
            index = _branch(code, index, params)
        elif code.kind == K_ELSE or code.kind == K_ELSEIF:
            index = code.jump
        elif code.kind == K_ENDIF:
            index += 1
        elif code.kind == K_DO_WHILE:
            if _value(code.args[0], params, code):
                limits.count(unit, code.opener, "loop")
                index = code.opener + 1
            else:
                index += 1
        elif code.kind == K_WHILE:
            if _value(code.args[0], params, code):
                limits.count(unit, index, "loop")
                index += 1
            else:
                index = code.jump
        elif code.kind == K_DO:
            limits.count(unit, index, "loop")
            index += 1
        elif code.kind == K_REPEAT:
            count = int(_value(code.args[0], params, code))
            repeats[index] = count
            if count <= 0:
                index = code.jump
            else:
                limits.count(unit, index, "loop")
                index += 1
        elif code.kind == K_ENDREPEAT:
            count = repeats[code.opener] - 1
            if count > 0:
                repeats[code.opener] = count
                limits.count(unit, code.opener, "loop")
                index = code.opener + 1
            else:
                del repeats[code.opener]
                index += 1
        elif code.kind == K_ENDWHILE:
            index = code.opener
        elif code.kind == K_BREAK:
            repeats.pop(code.opener, None)
            index = code.jump
        elif code.kind == K_CONTINUE:
            index = code.jump


cdef Py_ssize_t _branch(_Code code, Py_ssize_t index,
                        object params) except -1:
    """The line to go on at after the ``if`` of ``code`` at ``index``."""
    cdef Py_ssize_t b
    cdef _Code branch
    if _value(code.args[0], params, code):
        return index + 1
    for b, branch in code.branches:
        # (an endif is an "else": on after it)
        if branch.kind != K_ELSEIF or _value(branch.args[0], params,
                                             branch):
            return b + 1
    raise AssertionError("if without endif")  # pragma: no cover


cdef str _label(str name):
    return f"O{name}" if name[:1].isdigit() else f"O<{name}>"
