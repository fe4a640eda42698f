"""Cython generator: a ``.comp`` whose code section is Cython.

With ``option cython yes`` the code after ``;;`` is Cython, and the
component becomes one ``.pyx`` module (built with
:func:`halsdk.build.build_component`).  The code section holds:

``FUNCTION(name):`` blocks
    at the start of a line, followed by the indented body of function
    ``name``; the body is compiled as a ``noexcept nogil`` C function.
    When the file declares one function and the section has no
    ``FUNCTION(``, the whole section (less the blocks below) is its body.
``EXTRA_SETUP():`` / ``EXTRA_CLEANUP():`` blocks
    the bodies of the ``extra_setup`` (returns an int; ``prefix`` is a
    ``const char *``, ``extra_arg`` a ``long``; pins do not exist yet) and
    ``extra_cleanup`` functions of those options.
anything else at the left margin
    module-level Cython: ``cimport``s, ``cdef`` helpers (they must be
    ``noexcept nogil`` to be called from a body), constants, and
    ``cdef int get_count() noexcept`` for ``option count_function``.

In a body, every pin, param and variable of the instance is a plain
local variable of its type (arrays are C arrays; ``bit`` is ``bint``),
as are ``period``, ``fperiod`` and ``personality``.  They are read when
the function starts and written back when it ends (also after
``return``), so assigning to an ``out``/``io`` pin, a param or a variable
changes it; an ``in`` pin is read-only in effect.  ``cdef`` declarations
at the top level of a body are moved before the body (Cython wants them
there).  Conditions of ``if`` pins and ``[max : size]`` array sizes are
Cython expressions (they see ``personality``).  Divisions use C
semantics (``cdivision``); there are no bounds checks.

Not supported with Cython: ``option data``, ``option rtapi_app no``,
``variable`` arrays of pointers.
"""

from __future__ import annotations

import keyword
import re
import textwrap
from dataclasses import dataclass, field
from typing import Optional

from halcompile.model import Component, Pin, hal_format

_TYPES = {"bit": "hal.hal_bit_t", "float": "hal.hal_float_t",
          "s32": "hal.hal_s32_t", "u32": "hal.hal_u32_t",
          "s64": "hal.hal_s64_t", "u64": "hal.hal_u64_t"}
_DIRS = {"in": "hal.HAL_IN", "out": "hal.HAL_OUT", "io": "hal.HAL_IO",
         "r": "hal.HAL_RO", "rw": "hal.HAL_RW"}
_HEADER = re.compile(r"^(FUNCTION\((\w+)\)|EXTRA_SETUP\(\)|EXTRA_CLEANUP\(\))"
                     r"\s*:\s*(#.*)?$")
_CDEF = re.compile(r"^cdef\s")
#: names a Cython body cannot use for a variable
CYTHON_WORDS = frozenset(keyword.kwlist) | {
    "cdef", "cpdef", "cimport", "ctypedef", "include", "nogil", "gil",
    "struct", "union", "enum", "extern", "public", "api", "inline",
    "readonly", "noexcept", "DEF", "IF", "ELIF", "ELSE", "NULL", "sizeof",
    "memset", "memcpy", "hal", "comp_id"}


def cython_type(ctype: str) -> str:
    """The Cython spelling of the C type of a ``variable``."""
    words = ctype.split()
    out = []
    for w in words:
        if w.startswith("hal_") and w.endswith("_t"):
            out.append("hal." + w)
        elif w == "bool":
            out.append("bint")
        else:
            out.append(w)
    text = " ".join(out)
    return "unsigned int" if text == "unsigned" else text


@dataclass
class _Block:
    kind: str                   # "function", "setup", "cleanup"
    name: str
    header_line: int            # line in the .comp
    lines: list[tuple[int, str]] = field(default_factory=list)


class CythonSourceError(Exception):
    """A structural problem of a Cython code section (line in the comp)."""

    def __init__(self, line: int, message: str) -> None:
        super().__init__(message)
        self.line = line
        self.message = message


def split_code(comp: Component) -> tuple[list[tuple[int, str]],
                                         dict[str, _Block]]:
    """The module-level lines and the blocks of the code section (lines
    carry their line number in the .comp)."""
    module: list[tuple[int, str]] = []
    blocks: dict[str, _Block] = {}
    current: Optional[_Block] = None
    for i, line in enumerate(comp.code.split("\n")):
        lineno = comp.code_line + i
        m = _HEADER.match(line)
        if m:
            if m.group(2):
                block = _Block("function", m.group(2), lineno)
            elif m.group(1).startswith("EXTRA_SETUP"):
                block = _Block("setup", "extra_setup", lineno)
            else:
                block = _Block("cleanup", "extra_cleanup", lineno)
            key = block.name
            if key in blocks:
                raise CythonSourceError(lineno, f"{m.group(1)} is defined "
                                        "twice")
            blocks[key] = block
            current = block
            continue
        if current is not None and (not line.strip() or line[:1] in " \t"):
            current.lines.append((lineno, line))
            continue
        current = None
        module.append((lineno, line))
    implicit = [b for b in blocks.values() if b.kind == "function"]
    if not implicit and len(comp.functions) == 1:
        fn = comp.functions[0]
        body = _Block("function", fn.c_name, comp.code_line, module)
        blocks[fn.c_name] = body
        module = []
    return module, blocks


class _Out:
    """Lines of the .pyx, each with the .comp line it comes from (0:
    generated)."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.origin: list[int] = []
        self.shift: list[int] = []      # columns added to the .comp text

    def add(self, *lines: str, origin: int = 0, shift: int = 0) -> None:
        for text in lines:
            for part in text.split("\n"):
                self.lines.append(part)
                self.origin.append(origin)
                self.shift.append(shift)


def generate(comp: Component) -> tuple[str, list[tuple[int, int]]]:
    """The ``.pyx`` source of ``comp`` and, for each of its lines, the
    line of the .comp it comes from (0 for generated lines) and the
    columns the generator added before its text."""
    module, blocks = split_code(comp)
    names = [(p.c_name, p.loc.line, p.kind) for p in comp.pins + comp.params]
    names += [(v.name, v.loc.line, "variable") for v in comp.variables]
    names += [(f.c_name, f.loc.line, "function") for f in comp.functions]
    names += [(m.name, m.loc.line, "modparam") for m in comp.modparams]
    for cname, line, kind in names:
        if cname in CYTHON_WORDS:
            raise CythonSourceError(line, f"{kind} name '{cname}' is a "
                                    f"Python or Cython word (write "
                                    f"'{cname}_': the HAL name drops the "
                                    "'_')")
    for fn in comp.functions:
        if fn.c_name not in blocks:
            raise CythonSourceError(fn.loc.line, f"function '{fn.name}' "
                                    f"has no FUNCTION({fn.c_name}): block in "
                                    "the code section")
    declared = {fn.c_name for fn in comp.functions}
    for b in blocks.values():
        if b.kind == "function" and b.name not in declared:
            raise CythonSourceError(b.header_line, f"FUNCTION({b.name}): "
                                    "no such function is declared")
    for opt in ("extra_setup", "extra_cleanup"):
        has = opt in blocks
        if bool(comp.option(opt)) != has:
            line = comp.option_locs[opt].line if opt in comp.option_locs \
                else blocks[opt].header_line
            raise CythonSourceError(
                line, f"option {opt} and an {opt.upper()}(): block go "
                "together")
    o = _Out()
    personality = comp.has_personality
    o.add("# cython: language_level=3, boundscheck=False, "
          "wraparound=False, cdivision=True, initializedcheck=False",
          f"# {comp.name}.pyx: generated by halsdk's halcompile from "
          f"{comp.file}; edit the .comp file instead",
          "from libc.string cimport memset, memcpy",
          "from halsdk cimport hal", "", "hal.import_halsdk()", "",
          "cdef enum:", "    TRUE = 1", "    FALSE = 0", "",
          "cdef struct __comp_state:", "    __comp_state *_next",
          "    int _personality")
    for p in comp.pins:
        size = f"[{p.array.size}]" if p.array else ""
        o.add(f"    {_TYPES[p.type]} *{p.c_name}{size}")
    for p in comp.params:
        size = f"[{p.array.size}]" if p.array else ""
        o.add(f"    {_TYPES[p.type]} {p.c_name}{size}")
    for v in comp.variables:
        size = f"[{v.size}]" if v.size is not None else ""
        o.add(f"    {cython_type(v.ctype)} {v.stars}{v.name}{size}")
    o.add("", "cdef int comp_id = -1",
          "cdef __comp_state *__comp_first_inst = NULL",
          "cdef __comp_state *__comp_last_inst = NULL")
    for mp in comp.modparams:
        if mp.type in ("int", "long"):
            o.add(f"cdef {mp.type} {mp.name} = {mp.default or '0'}",
                  origin=mp.loc.line)
        elif mp.type == "string":
            o.add(f"cdef bytes __mp_{mp.name} = "
                  f"{(mp.default or '').encode()!r}",
                  f"cdef const char *{mp.name} = __mp_{mp.name}")
    o.add("")
    # module-level code of the section
    for lineno, text in module:
        o.add(text, origin=lineno)
    o.add("")
    for b in blocks.values():
        _emit_block(o, comp, b, personality)
    _emit_setup(o, comp, personality, "extra_setup" in blocks,
                "extra_cleanup" in blocks)
    return "\n".join(o.lines) + "\n", list(zip(o.origin, o.shift))


def _locals(o: _Out, comp: Component, pins: bool, personality: bool
            ) -> list[str]:
    """Declare and read the locals of a body; returns the write-back
    lines."""
    back: list[str] = []
    ind = "    "
    inst = "__comp_inst"
    items: list[Pin] = (comp.pins if pins else []) + comp.params
    for p in items:
        n, t = p.c_name, _TYPES[p.type]
        is_pin = p.kind == "pin"
        guard = is_pin and (p.condition is not None or p.array is not None)
        writes = not (is_pin and p.direction == "in")
        if p.array:
            k = p.array.size
            o.add(f"{ind}cdef {t} {n}[{k}]")
            if is_pin:
                o.add(f"{ind}for __j in range({k}):",
                      f"{ind}    {n}[__j] = {inst}.{n}[__j][0] if "
                      f"{inst}.{n}[__j] != NULL else 0")
                if writes:
                    back += [f"for __j in range({k}):",
                             f"    if {inst}.{n}[__j] != NULL:",
                             f"        {inst}.{n}[__j][0] = {n}[__j]"]
            else:
                o.add(f"{ind}memcpy({n}, {inst}.{n}, sizeof({n}))")
                back.append(f"memcpy({inst}.{n}, {n}, sizeof({n}))")
        elif is_pin:
            read = f"{inst}.{n}[0]"
            if guard:
                read += f" if {inst}.{n} != NULL else 0"
            o.add(f"{ind}cdef {t} {n} = {read}")
            if writes:
                back += ([f"if {inst}.{n} != NULL:",
                          f"    {inst}.{n}[0] = {n}"] if guard
                         else [f"{inst}.{n}[0] = {n}"])
        else:
            o.add(f"{ind}cdef {t} {n} = {inst}.{n}")
            back.append(f"{inst}.{n} = {n}")
    for v in comp.variables:
        t = cython_type(v.ctype)
        if v.size is not None:
            o.add(f"{ind}cdef {t} {v.stars}{v.name}[{v.size}]",
                  f"{ind}memcpy({v.name}, {inst}.{v.name}, "
                  f"sizeof({v.name}))")
            back.append(f"memcpy({inst}.{v.name}, {v.name}, "
                        f"sizeof({v.name}))")
        else:
            o.add(f"{ind}cdef {t} {v.stars}{v.name} = {inst}.{v.name}")
            back.append(f"{inst}.{v.name} = {v.name}")
    if personality:
        o.add(f"{ind}cdef int personality = {inst}._personality")
    return back


def _body(o: _Out, b: _Block, back: list[str]) -> None:
    """The user's body inside try/finally (its top-level cdef lines
    before it), then the write-back."""
    text = textwrap.dedent("\n".join(t for _, t in b.lines))
    lines = list(zip([n for n, _ in b.lines], text.split("\n")))
    # columns the dedent took away from each line
    cut = {n: len(t) - len(d) for (n, t), (_, d) in zip(b.lines, lines)}
    while lines and not lines[-1][1].strip():
        lines.pop()
    cdefs = [(n, t) for n, t in lines if _CDEF.match(t)]
    rest = [(n, t) for n, t in lines if not _CDEF.match(t)]
    for n, t in cdefs:
        o.add("    " + t, origin=n, shift=4 - cut[n])
    if not back:
        if not any(t.strip() for _, t in rest):
            o.add("    pass")
        for n, t in rest:
            o.add(("    " + t) if t.strip() else "", origin=n,
                  shift=4 - cut[n])
        o.add("")
        return
    o.add("    try:")
    if not any(t.strip() for _, t in rest):
        o.add("        pass")
    for n, t in rest:
        o.add(("        " + t) if t.strip() else "", origin=n,
              shift=8 - cut[n])
    o.add("    finally:")
    for t in back:
        o.add("        " + t)
    o.add("")


def _emit_block(o: _Out, comp: Component, b: _Block,
                personality: bool) -> None:
    if b.kind == "cleanup":
        o.add("cdef void extra_cleanup() noexcept nogil:",
              origin=b.header_line)
        _body(o, b, [])
        return
    if b.kind == "setup":
        o.add("cdef int extra_setup(__comp_state *__comp_inst, "
              "const char *prefix, long extra_arg) noexcept nogil:",
              origin=b.header_line)
        o.add("    cdef int __j")
        back = _locals(o, comp, False, personality)
        _body(o, b, back)
        return
    o.add(f"cdef void {b.name}(void *__arg, long period) noexcept nogil:",
          origin=b.header_line)
    o.add("    cdef __comp_state *__comp_inst = <__comp_state *>__arg",
          "    cdef double fperiod = period * 1e-9", "    cdef int __j")
    back = _locals(o, comp, True, personality)
    _body(o, b, back)


def _emit_setup(o: _Out, comp: Component, personality: bool,
                extra_setup: bool, extra_cleanup: bool) -> None:
    name, prefix = comp.name, comp.prefix
    singleton = bool(comp.option("singleton"))
    count_function = bool(comp.option("count_function"))
    default_count = int(comp.option("default_count", 1))
    default_pers = int(comp.option("default_personality", 0))
    # ---- one instance
    o.add("cdef int __export(char *prefix, long extra_arg, int pers) "
          "except -1:",
          "    global __comp_first_inst, __comp_last_inst",
          "    cdef int r = 0", "    cdef int j = 0", "    cdef int n = 0",
          "    cdef __comp_state *inst = <__comp_state *>hal.hal_malloc("
          "sizeof(__comp_state))",
          "    if inst == NULL:",
          "        raise MemoryError('hal_malloc failed')",
          "    memset(inst, 0, sizeof(__comp_state))",
          "    inst._personality = pers")
    if personality:
        o.add("    cdef int personality = pers")
    if extra_setup:
        o.add("    r = extra_setup(inst, prefix, extra_arg)",
              "    if r != 0:",
              "        raise RuntimeError(f'extra_setup of {prefix.decode()} "
              "returned {r}')")
    for p in comp.pins + comp.params:
        _export_item(o, p)
    for v in comp.variables:
        if v.default is None:
            continue
        if v.size is not None:
            o.add(f"    for j in range({v.size}):")
            o.add(f"        inst.{v.name}[j] = {v.default}",
                  origin=v.loc.line)
        else:
            o.add(f"    inst.{v.name} = {v.default}", origin=v.loc.line)
    for fn in comp.functions:
        fmt = "%s" + ("." + fn.hal_name if fn.hal_name else "")
        o.add(f"    r = hal.hal_export_functf({fn.c_name}, inst, "
              f"{int(fn.fp)}, 0, comp_id, {fmt.encode()!r}, prefix)",
              "    if r != 0:",
              f"        raise RuntimeError(f'{{prefix.decode()}}: cannot "
              f"export function {fn.hal_name or '(main)'}: "
              "{hal.halsdk_last_error().decode()}')")
    o.add("    if __comp_last_inst != NULL:",
          "        __comp_last_inst._next = inst",
          "    __comp_last_inst = inst",
          "    if __comp_first_inst == NULL:",
          "        __comp_first_inst = inst",
          "    return 0", "")
    # ---- modparams and setup()
    specs = []
    if not singleton and not count_function:
        specs += [f"    'count': (int, 0, 'number of {name}'),",
                  f"    'names': (str, '', 'names of {name}'),"]
    if personality:
        specs.append(f"    'personality': ([int], [], 'personality of "
                     f"each {name}'),")
    user_mps = []
    for mp in comp.modparams:
        if mp.type == "dummy":
            continue
        kind = "str" if mp.type == "string" else "int"
        default = repr(mp.default or "") if mp.type == "string" else \
            str(int(mp.default or "0", 0))
        specs.append(f"    {mp.name!r}: ({kind}, {default}, "
                     f"{(mp.doc or '')!r}),")
        user_mps.append(mp)
    o.add("modparams = {", *specs, "}", "",
          "def setup(**params):",
          "    global comp_id, __comp_first_inst, __comp_last_inst")
    for mp in user_mps:
        if mp.type == "string":
            o.add(f"    global __mp_{mp.name}, {mp.name}",
                  f"    __mp_{mp.name} = str(params.get({mp.name!r}, "
                  f"{(mp.default or '')!r})).encode()",
                  f"    {mp.name} = __mp_{mp.name}")
        else:
            o.add(f"    global {mp.name}",
                  f"    {mp.name} = int(params.get({mp.name!r}, "
                  f"{int(mp.default or '0', 0)}))")
    o.add("    __comp_first_inst = __comp_last_inst = NULL",
          f"    comp_id = hal.hal_init({name.encode()!r})",
          "    if comp_id < 0:",
          f"        raise RuntimeError('hal_init({name}) failed: ' + "
          "hal.halsdk_last_error().decode())",
          "    pers = list(params.get('personality') or [])")
    o.add("    def personality_of(idx):",
          f"        return pers[idx % len(pers)] if pers else {default_pers}")
    if singleton:
        o.add(f"    insts = [{prefix!r}]")
    elif count_function:
        o.add(f"    insts = [f'{prefix}.{{i}}' for i in range(get_count())]")
    else:
        o.add("    count = int(params.get('count') or 0)",
              "    names = str(params.get('names') or '')",
              "    if count and names:",
              "        hal.hal_exit(comp_id)",
              "        comp_id = -1",
              "        raise ValueError('count= and names= are mutually "
              "exclusive')",
              "    if names:",
              "        insts = names.split(',')",
              "    else:",
              f"        insts = [f'{prefix}.{{i}}' for i in "
              f"range(count or {default_count})]")
    o.add("    try:",
          "        for idx, inst in enumerate(insts):",
          "            __export(inst.encode(), idx, personality_of(idx))",
          "    except BaseException:")
    if extra_cleanup:
        o.add("        extra_cleanup()")
    o.add("        hal.hal_exit(comp_id)", "        comp_id = -1",
          "        raise", "    hal.hal_ready(comp_id)", "",
          "def cleanup():", "    global comp_id",
          "    if comp_id < 0:", "        return")
    if extra_cleanup:
        o.add("    extra_cleanup()")
    o.add("    hal.hal_exit(comp_id)", "    comp_id = -1", "")


def _export_item(o: _Out, p: Pin) -> None:
    n = p.c_name
    what = "pin" if p.kind == "pin" else "param"
    fmt = ("%s." + hal_format(p.name)).encode()
    runs = len(re.findall("#+", p.name))
    ind = "    "
    if p.condition:
        o.add(f"{ind}if {p.condition.strip()}:",
              origin=p.condition_loc.line if p.condition_loc else 0)
        ind += "    "
    ref = f"inst.{n}" + ("[j]" if p.array else "")
    ptr = f"&{ref}"
    value = f"{ref}[0]" if p.kind == "pin" else ref
    call = (f"r = hal.hal_{what}_{p.type}_newf({_DIRS[p.direction]}, {ptr}, "
            f"comp_id, {fmt!r}, prefix" + ", j" * runs + ")")
    if p.array:
        if p.array.condsize:
            o.add(f"{ind}n = <int>({p.array.condsize.strip()})",
                  origin=p.array.condsize_loc.line
                  if p.array.condsize_loc else 0)
            o.add(f"{ind}if n > {p.array.size}:",
                  f"{ind}    raise ValueError(f'{what.capitalize()} {p.name}: "
                  f"Requested size {{n}} exceeds max size {p.array.size}')")
        else:
            o.add(f"{ind}n = {p.array.size}")
        o.add(f"{ind}for j in range(n):")
        ind += "    "
    o.add(f"{ind}{call}", f"{ind}if r != 0:",
          f"{ind}    raise RuntimeError(f'{{prefix.decode()}}: cannot make "
          f"{what} {p.name}: {{hal.halsdk_last_error().decode()}}')")
    if p.default is not None:
        o.add(f"{ind}{value} = {p.default.strip()}",
              origin=p.default_loc.line if p.default_loc else 0)
