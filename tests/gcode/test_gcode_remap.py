"""REMAP= codes and the [PYTHON] plugin (halsdk.gcode.remap, .pyplugin).

What the reference's rs274 does the same way is checked byte for byte by
the golden programs of tests/gcode/programs/remap/; these tests cover
what they cannot: our error messages (INI file and line, G-code line and
the Python frame), the interpreter with its own canon (not rs274's text),
the plugin's isolation in sys.modules and sys.path, and what we accept
beyond the reference (an int returned by a Python subroutine).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from halsdk.gcode import GCodeError, Parameters, Program
from halsdk.gcode import canon as C
from halsdk.gcode.interp import Interpreter
from halsdk.gcode.pyplugin import PluginError
from halsdk.gcode.remap import (
    MAX_REMAP_LEVEL,
    RemapError,
    configure,
    parse_remap,
)
from halsdk.ini import IniFile
from halsdk.machine.tooltable import ToolTable


def setup(tmp_path: Path, remaps: str, files: dict[str, str],
          python: bool = False) -> tuple[Interpreter, C.RecordingCanon]:
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    ini = tmp_path / "m.ini"
    text = f"[RS274NGC]\nSUBROUTINE_PATH = .\n{remaps}\n"
    if python:
        text += "[PYTHON]\nTOPLEVEL = top.py\nPATH_APPEND = .\n"
    ini.write_text(text)
    rec = C.RecordingCanon()
    interp = Interpreter(Parameters(), ToolTable.parse("T1 P1 Z1 D1\n"),
                         rec)
    configure(interp, IniFile(str(ini)), (str(tmp_path),))
    return interp, rec


def run(interp: Interpreter, text: str, file: str = "p.ngc") -> None:
    interp.ended = False            # (after the M2 of an earlier run)
    interp.run(Program(text, file, interp.params))


def traverses(rec: C.RecordingCanon) -> list[tuple[float, ...]]:
    return [tuple(round(v, 6) for v in c.end[:3])
            for c in rec.of_type(C.StraightTraverse)]


# -- REMAP= lines -------------------------------------------------------------

def test_a_remap_line_is_read() -> None:
    r = parse_remap("M400 modalgroup=7 argspec=@Pq^ ngc=proc", "m.ini", 4)
    assert (r.code, r.name, r.modal_group, r.ngc, r.python) == \
        ("m400", "M400", 7, "proc", None)
    assert (r.required, r.words, r.file, r.line) == ("p", "pq", "m.ini", 4)
    g = parse_remap("g88.6 python=f")
    assert (g.code, g.modal_group, g.step) == ("g88.6", 1, 24)
    assert parse_remap("M500 ngc=x").modal_group == 10
    assert parse_remap("T prolog=a ngc=b epilog=c").code == "t"
    assert parse_remap("M6 ngc=change").code == "m6"


@pytest.mark.parametrize("line, why", [
    ("", "no code given"),
    ("X5 ngc=a", "X5 is not a G, M, T, S or F code"),
    ("M4.5 ngc=a", "is not a G, M, T, S or F code"),
    ("M400 ngc=a bogus=1", "unrecognized option 'bogus=1' in  7:REMAP = "
                           "M400 ngc=a bogus=1"),
    ("M400 ngc", "unrecognized option 'ngc' in  7:REMAP = M400 ngc"),
    ("M400 ngc=a ngc=b", "ngc= given twice"),
    ("M400 ngc=a python=b", "ngc= and python= exclude each other"),
    ("M400 argspec=p", "code 'M400' - no remap function given, use either "
                       "'python=<function>' or 'ngc=<basename>' : "
                       "7:REMAP = M400 argspec=p"),
    ("M400 modalgroup=4 ngc=a", "modalgroup=4: a remapped M code may have "
                                "modal group 5, 6, 7, 8, 9, 10"),
    ("M400 modalgroup=x ngc=a", "modalgroup=x is not a number"),
    ("G88.6 modalgroup=2 ngc=a", "may have modal group 1"),
    ("G1 ngc=a", "G1 is a built-in code that cannot be remapped"),
    ("M3 ngc=a", "M3 is a built-in code"),
    ("M400 argspec=Pg ngc=a", "argspec: illegal word 'g' - 7:REMAP = "
                              "M400 argspec=Pg ngc=a"),
    ("M400 argspec=@P@ ngc=a", "'@' given twice"),
    ("M400 python=a prolog=b", "prolog= and epilog= go with ngc="),
])
def test_a_bad_remap_line_names_the_ini_file_and_line(line: str, why: str
                                                      ) -> None:
    with pytest.raises(RemapError) as e:
        parse_remap(line, "/cfg/m.ini", 7)
    assert str(e.value).startswith("/cfg/m.ini:7:0: ")
    assert why in str(e.value)
    # our own words quote the line; the reference's quote it as
    # LINE:REMAP = VALUE
    assert f"REMAP={line.strip()}:" in str(e.value) or \
        f"7:REMAP = {line.strip()}" in str(e.value)


def test_a_code_with_no_modal_group_is_a_warning() -> None:
    """The reference's warning, through ``warn``, for G and M codes only."""
    warnings: list[GCodeError] = []
    assert parse_remap("M400 ngc=a", "/cfg/m.ini", 3,
                       warnings.append).modal_group == 10
    assert parse_remap("G88.6 ngc=a", "/cfg/m.ini", 4,
                       warnings.append).modal_group == 1
    parse_remap("M401 modalgroup=5 ngc=a", "/cfg/m.ini", 5, warnings.append)
    parse_remap("T ngc=a", "/cfg/m.ini", 6, warnings.append)
    assert [str(w) for w in warnings] == [
        "/cfg/m.ini:3:0: warning: code 'M400' : no modalgroup=<int> given, "
        "using default group 10 : 3:REMAP = M400 ngc=a",
        "/cfg/m.ini:4:0: warning: code 'G88.6' : no modalgroup=<int> given, "
        "using default group 1 : 4:REMAP = G88.6 ngc=a"]


@settings(max_examples=80, deadline=None)
@given(st.lists(st.sampled_from(sorted(set("abcdefhijklmpqrsuvwxyz"))),
                unique=True, max_size=8), st.data())
def test_upper_case_argspec_letters_are_the_required_words(letters, data
                                                           ) -> None:
    upper = [data.draw(st.booleans()) for _ in letters]
    spec = "".join(c.upper() if u else c for c, u in zip(letters, upper))
    r = parse_remap(f"M400 argspec={spec} ngc=a")
    assert r.required == "".join(c for c, u in zip(letters, upper) if u)
    assert r.words == "".join(letters)


def test_a_remap_file_names_its_line(tmp_path: Path) -> None:
    (tmp_path / "a.ngc").write_text("o<a> sub\no<a> endsub\n")
    ini = tmp_path / "m.ini"
    ini.write_text("[RS274NGC]\nREMAP=M400 ngc=a\nREMAP=M400 ngc=a\n")
    interp = Interpreter(Parameters(), None, C.RecordingCanon())
    with pytest.raises(RemapError, match=r"m.ini:3:0: code 'M400' already "
                                         r"remapped : 3:REMAP = M400 ngc=a"):
        configure(interp, IniFile(str(ini)), (str(tmp_path),))
    ini.write_text("[RS274NGC]\n\nREMAP=M400 ngc=nosuch\n")
    with pytest.raises(RemapError, match=r"m.ini:3:0: INTERP_REMAP: NGC "
                                         r"file not found: ngc=nosuch\n"
                                         r"REMAP INI Line:3 = M400 "
                                         r"ngc=nosuch"):
        configure(interp, IniFile(str(ini)), (str(tmp_path),))
    ini.write_text("[RS274NGC]\nREMAP=M400 python=f\n")
    with pytest.raises(RemapError, match=r"m.ini:2:0: .*no \[PYTHON\]"):
        configure(interp, IniFile(str(ini)), ())


# -- NGC procedures with the interpreter's own canon ---------------------------

PROC = ("o<goto> sub\n"
        "o1 if [EXISTS[#<q>]]\n  G0 Y#<q>\no1 endif\n"
        "G0 X#<p>\no<goto> endsub\nM2\n")


def test_ngc_remap_with_the_recording_canon(tmp_path: Path) -> None:
    interp, rec = setup(tmp_path, "REMAP=M400 argspec=Pq ngc=goto",
                        {"goto.ngc": PROC})
    run(interp, "G21 G90\nM400 P3\nM400 P4 Q5\nM400 P1 X9\nM2\n")
    # the X word of the last line is not the M400's: the (modal G0)
    # motion after the procedure
    assert traverses(rec) == [(3, 0, 0), (3, 5, 0), (4, 5, 0), (1, 5, 0),
                              (9, 5, 0)]


def test_missing_word_is_an_error_at_the_code(tmp_path: Path) -> None:
    interp, _ = setup(tmp_path, "REMAP=M400 argspec=Pq ngc=goto",
                      {"goto.ngc": PROC})
    with pytest.raises(GCodeError) as e:
        run(interp, "G0 X1\nG0   M400 Q2\nM2\n")
    assert str(e.value) == "p.ngc:2:6: user-defined M400: missing: P"


def test_remaps_nest_to_the_limit(tmp_path: Path) -> None:
    files = {f"m{i}.ngc": f"o<m{i}> sub\nM{i + 1}\no<m{i}> endsub\n"
             for i in range(500, 512)}
    lines = "\n".join(f"REMAP=M{i} ngc=m{i}" for i in range(500, 512))
    files["m512.ngc"] = "o<m512> sub\nG0 X1\no<m512> endsub\n"
    interp, rec = setup(tmp_path, lines + "\nREMAP=M512 ngc=m512", files)
    run(interp, f"M{512 - MAX_REMAP_LEVEL + 1}\nM2\n")
    assert traverses(rec) == [(1, 0, 0)]
    with pytest.raises(GCodeError, match="m511.ngc:2:1: maximum nesting of "
                                         "remapped blocks exceeded"):
        run(interp, f"M{512 - MAX_REMAP_LEVEL}\nM2\n")


def test_no_ini_no_remap() -> None:
    interp = Interpreter(Parameters(), None, C.RecordingCanon())
    assert interp.remap is None
    with pytest.raises(GCodeError, match="M400"):
        run(interp, "M400\nM2\n")


# -- Python -------------------------------------------------------------------

TOP = "import remap\nimport oword\nimport namedparams\n"
NAMED = """\
def _twice_feed(self):
    return 2 * self.feed_rate


def _broken(self):
    return {}["x"]
"""
REMAP = """\
from interpreter import INTERP_OK, InterpreterException


def lift(self, **words):
    self.execute("G0 Z%f" % words["z"])
    return INTERP_OK


def deep(self, **words):
    helper(words)


def helper(words):
    raise ValueError("no good %s" % sorted(words))


def catches(self, **words):
    try:
        self.execute("G0 X1 G1 Y2")
    except InterpreterException as e:
        return "caught: " + e.error_message
"""
OWORD = """\
def whole(self, *args):
    return len(args)


def alist(self, *args):
    return [1]
"""


@pytest.fixture
def py(tmp_path: Path) -> tuple[Interpreter, C.RecordingCanon]:
    return setup(tmp_path, "REMAP=M401 argspec=Z python=lift\n"
                           "REMAP=M402 argspec=pq python=deep\n"
                           "REMAP=M403 python=catches",
                 {"top.py": TOP, "remap.py": REMAP, "oword.py": OWORD,
                  "namedparams.py": NAMED},
                 python=True)


def test_python_remap_runs_gcode(py) -> None:
    interp, rec = py
    run(interp, "G21\nM401 Z4\nM2\n")
    assert traverses(rec) == [(0, 0, 4)]


def test_a_python_exception_names_the_line_and_the_frame(py, tmp_path
                                                         ) -> None:
    interp, _ = py
    with pytest.raises(PluginError) as e:
        run(interp, "G0 X1\nM402 P2\nM2\n", "job.ngc")
    text = str(e.value)
    assert text.startswith("job.ngc:2:1: M402 remap: deep() raised "
                           "ValueError: no good ['p'] (at ")
    assert text.endswith(f"{tmp_path / 'remap.py'}:14 in helper)")


def test_a_gcode_error_from_python_is_an_exception_there(py) -> None:
    interp, _ = py
    with pytest.raises(GCodeError) as e:
        run(interp, "M403\nM2\n")
    assert e.value.message.startswith("caught: ")
    # the G-code error of self.execute() inside, in the reference's words
    assert e.value.message.endswith("Two g codes used from same modal "
                                    "group")


def test_a_python_subroutine_may_return_an_int_not_a_list(py) -> None:
    interp, _ = py
    run(interp, "o<whole> call [1] [2]\n#<n> = #<_value>\nM2\n")
    assert interp.params.get("_value") == 2.0
    with pytest.raises(GCodeError, match=r"p.ngc:1:1: o<alist> call: "
                                         r"Python oword.alist\(\) returned "
                                         r"list"):
        run(interp, "o<alist> call\nM2\n")


def test_only_the_functions_of_the_module_are_subroutines(py) -> None:
    interp, _ = py
    for name in ("__class__", "__loader__", "nosuch"):
        # (the reference's words for a subroutine it cannot find)
        with pytest.raises(GCodeError, match=f"seeking o-word: "
                                             f"o<{name}> from line"):
            run(interp, f"o<{name}> call\nM2\n")


def test_the_plugin_stays_out_of_sys_modules_and_path(tmp_path: Path
                                                      ) -> None:
    """Two machines, each with its own remap.py: each calls its own; the
    plugin's modules and folders are not left in sys.modules/sys.path."""
    path = list(sys.path)
    found = []
    for n in (1, 2):
        folder = tmp_path / f"m{n}"
        folder.mkdir()
        code = f"def f(self, **w):\n    self.execute('G0 X{n}')\n"
        interp, rec = setup(folder, "REMAP=M401 python=f",
                            {"top.py": "import remap\n", "remap.py": code},
                            python=True)
        found.append((interp, rec))
        assert "remap" not in sys.modules
    for n, (interp, rec) in enumerate(found, start=1):
        run(interp, "M401\nM2\n")
        assert traverses(rec) == [(n, 0, 0)]
    assert "remap" not in sys.modules and "interpreter" not in sys.modules
    assert sys.path == path


@pytest.mark.parametrize("top, why", [
    (None, r"m.ini:5:0: \[PYTHON\]TOPLEVEL: cannot read .*top.py"),
    ("import nosuchmodule_x\n", r"m.ini:5:0: \[PYTHON\]TOPLEVEL .*top.py "
                                r"raised ModuleNotFoundError: .*nosuchmodule_x"
                                r".* \(at .*top.py:1 in <module>\)"),
    ("def (:\n", r"m.ini:5:0: .*raised SyntaxError: invalid syntax \(at "
                 r".*top.py:1\)$"),
    ("import remap\n", r"m.ini:3:0: REMAP M401: the plugin has no function "
                       r"remap.lift"),
])
def test_a_bad_plugin_names_the_ini_line(tmp_path: Path, top, why) -> None:
    files = {"remap.py": "def other(self):\n    pass\n"}
    if top is not None:
        files["top.py"] = top
    with pytest.raises(GCodeError, match=why):
        setup(tmp_path, "REMAP=M401 python=lift", files, python=True)


def test_named_parameters_from_python(py, tmp_path: Path) -> None:
    interp, rec = py
    run(interp, "F7\nG0 X#<_twice_feed>\nM2\n")
    assert traverses(rec) == [(14, 0, 0)]
    with pytest.raises(GCodeError, match="p.ngc:1:.*read-only"):
        run(interp, "#<_twice_feed> = 1\nM2\n")
    with pytest.raises(GCodeError) as e:
        run(interp, "G0 X1\nG0 X#<_broken>\nM2\n")
    assert str(e.value).startswith("p.ngc:2:")
    assert "namedparams._broken() raised KeyError: 'x' (at " \
        f"{tmp_path / 'namedparams.py'}:6 in _broken)" in str(e.value)


def test_after_an_error_in_a_procedure_the_next_line_runs(tmp_path: Path
                                                         ) -> None:
    """rs274 -n 0 goes on after an error: the scopes the failed procedure
    opened are closed and no remap stays in progress."""
    import io

    from halsdk.gcode.rs274 import run as rs274
    (tmp_path / "bad.ngc").write_text(
        "o<bad> sub\n#<local> = 1\no<inner> call\no<bad> endsub\n")
    (tmp_path / "inner.ngc").write_text(
        "o<inner> sub\nG1 X1 F-1\no<inner> endsub\n")
    (tmp_path / "m.ini").write_text("[RS274NGC]\nREMAP=M400 ngc=bad\n")
    out, err = io.StringIO(), io.StringIO()
    status = rs274("#<top> = 5\nM400\nM400\n(debug, top=#<top>)\nM2\n",
                   "p.ngc", out.write, err.write,
                   ini=IniFile(str(tmp_path / "m.ini")),
                   search_path=(str(tmp_path),), keep_going=True)
    assert status == 0
    assert err.getvalue().count("inner.ngc:2:") == 2
    assert 'MESSAGE(" top=5.000000")' in out.getvalue()


def test_rs274_command_reports_without_a_traceback(tmp_path: Path) -> None:
    """``rs274 -i``: Python that raises and a bad REMAP line are messages
    and exit status 1, never a traceback."""
    import subprocess
    (tmp_path / "top.py").write_text("import remap\n")
    (tmp_path / "remap.py").write_text(
        "def boom(self, **words):\n    return 1 / 0\n")
    ini = tmp_path / "m.ini"
    ini.write_text("[RS274NGC]\nREMAP=M401 python=boom\n"
                   "[PYTHON]\nTOPLEVEL = top.py\n")
    prog = tmp_path / "p.ngc"
    prog.write_text("G0 X1\nM401\nM2\n")
    command = [sys.executable, "-m", "halsdk.gcode.rs274", "-g", "-i",
               str(ini), str(prog)]
    done = subprocess.run(command, capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)
    assert done.returncode == 1
    # the reference's warning first, then the error and the line the
    # reference shows for it, the procedure's call
    assert done.stderr == (
        f"{ini}:2:0: warning: code 'M401' : no modalgroup=<int> given, "
        "using default group 10 : 2:REMAP = M401 python=boom\n"
        f"{prog}:2:1: M401 remap: boom() raised ZeroDivisionError: "
        f"division by zero (at {tmp_path / 'remap.py'}:2 in boom)\n"
        "O <boom> call \n")
    assert "Traceback" not in done.stderr
    assert "STRAIGHT_TRAVERSE(1.0000" in done.stdout
    ini.write_text("[RS274NGC]\nREMAP=M401 python=boom argspec=O\n")
    done = subprocess.run(command, capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)
    assert (done.returncode, done.stdout) == (1, "")
    # (the reference checks the argspec before it warns)
    assert done.stderr == (f"{ini}:2:0: argspec: illegal word 'O' - "
                           "2:REMAP = M401 python=boom argspec=O\n")
    assert "Traceback" not in done.stderr
