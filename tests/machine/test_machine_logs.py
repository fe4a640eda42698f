"""The file comments of a program on a machine: (LOGOPEN,name),
(LOGAPPEND,name), (LOG,text), (LOGCLOSE), (PROBEOPEN name), (PROBECLOSE),
carried out by the machine's executor (see docs/gcode.rst)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from halsdk.gcode.interp import comment_kind, probe_comment
from halsdk.machine import InterpState, MachineError, TaskMode, TaskState

# the simulated machine of test_machine_api (tests are modules by path)
_spec = importlib.util.spec_from_file_location(
    "_machine_api", Path(__file__).with_name("test_machine_api.py"))
assert _spec is not None and _spec.loader is not None
_api = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_api)
build, run_program, turn_on = _api.build, _api.run_program, _api.turn_on

# the probe of the simulated machine trips below machine Z 12; G54 has Z2,
# so the probed points are near program Z 10
PROGRAM = """(probe two points, log them)
#<depth> = -20
(LOGOPEN,{log})
(LOG,start depth=#<depth>)
G21 G90 G10 L2 P1 Z2
G0 X1 Y2 Z20 (PROBEOPEN {probe})
G38.2 Z#<depth> F600
(LOG,hit X#5061 Y#5062 Z#5063 ok #5070)
G0 Z20
G0 X3.25
G38.3 Z#<depth> F600 (LOG,before the move X#5061)
(LOG,hit X#5061 Y#5062 Z#5063 ok #5070)
G0 Z20
G38.3 Z15 F600
(LOG,miss Z#5063 ok #5070)
G0 Z20
G38.3 Z15 F600
(PROBECLOSE)
G38.3 Z#<depth> F600
G0 Z20
(LOG, end: not the last)(log,last comment wins)
(LOGCLOSE)
(LOG,not written: no log open)
M2
"""


def _hits(log: list[str]) -> list[float]:
    """The Z of the 'hit' lines of a log."""
    return [float(line.split("Z")[1].split()[0])
            for line in log if line.startswith("hit")]


def test_log_and_probe_files_of_a_program(hal, tmp_path: Path) -> None:
    m = build(hal, tmp_path)
    turn_on(m)
    log, probe = tmp_path / "run.log", tmp_path / "points.txt"
    log.write_text("old content\n")
    probe.write_text("old points\n")
    run_program(m, tmp_path, PROGRAM.format(log=log, probe=probe))
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    assert [e for e in m.errors() if e[0] == "error"] == []
    lines = log.read_text().splitlines()
    z1, z2 = _hits(lines)
    # the probe stopped where the input changed (machine Z 12, G54 Z2)
    assert z1 == pytest.approx(10, abs=0.05)
    assert z2 == pytest.approx(10, abs=0.05)
    # LOGOPEN emptied the file; LOG expands parameters as %.6f; a comment
    # runs before the move of its line; the last comment of a line counts
    assert lines == [
        "start depth=-20.000000",
        f"hit X1.000000 Y2.000000 Z{z1:f} ok 1.000000",
        "before the move X1.000000",
        f"hit X3.250000 Y2.000000 Z{z2:f} ok 1.000000",
        "miss Z15.000000 ok 0.000000",
        "last comment wins",
    ]
    # one line per probe move, nine numbers %f, program coordinates, also
    # where a G38.3 without contact stopped; not a point equal to the one
    # written last (the second miss), nor after PROBECLOSE
    zero = " 0.000000" * 6
    assert probe.read_text() == (f"1.000000 2.000000 {z1:f}{zero}\n"
                                 f"3.250000 2.000000 {z2:f}{zero}\n"
                                 f"3.250000 2.000000 15.000000{zero}\n")


def test_logappend_keeps_the_file_and_mdi_logs_too(hal, tmp_path: Path
                                                   ) -> None:
    m = build(hal, tmp_path)
    turn_on(m)
    log = tmp_path / "a.log"
    log.write_text("first\n")
    run_program(m, tmp_path, f"(LOGAPPEND,{log})\n#1=2.5\n"
                "(LOG,one #1)\nM2\n")
    # the log stays open after the program's end, until LOGCLOSE
    m.mode(TaskMode.MDI)
    m.mdi("(LOG,from mdi)")
    m.mdi("(LOGCLOSE)")
    m.mdi("(LOG,after close)")
    assert log.read_text() == "first\none 2.500000\nfrom mdi\n"
    # LOGOPEN of another file closes the first one
    m.mdi(f"(LOGOPEN,{tmp_path / 'b.log'})")
    m.mdi("(LOG,b)")
    m.mdi(f"(  logopen,{tmp_path / 'c.log'})")
    m.mdi("(LOG,c)")
    m.mdi("(LOGCLOSE)")
    assert (tmp_path / "b.log").read_text() == "b\n"
    assert (tmp_path / "c.log").read_text() == "c\n"


def test_relative_names_are_in_the_ini_folder(hal, tmp_path: Path) -> None:
    from halsdk.ini import IniFile
    m = build(hal, tmp_path)
    config = tmp_path / "config"
    config.mkdir()
    ini = config / "machine.ini"
    ini.write_text("[RS274NGC]\n")
    m.configure_from_ini(IniFile(str(ini)))
    turn_on(m)
    run_program(m, tmp_path, "(LOGOPEN,results.txt)\n(LOG,x)\n(LOGCLOSE)\n"
                "(PROBEOPEN points.txt)\n(PROBECLOSE)\nM2\n")
    assert (config / "results.txt").read_text() == "x\n"
    assert (config / "points.txt").read_text() == ""
    assert not (tmp_path / "results.txt").exists()


@pytest.mark.parametrize("comment, what", [
    ("(LOGOPEN,{bad})", "LOGOPEN"),
    ("(LOGAPPEND,{bad})", "LOGAPPEND"),
    ("(PROBEOPEN {bad})", "PROBEOPEN"),
])
def test_a_file_that_cannot_be_opened_stops_the_program(
        hal, tmp_path: Path, comment: str, what: str) -> None:
    m = build(hal, tmp_path)
    turn_on(m)
    bad = tmp_path / "no-such-folder" / "x.txt"
    path = tmp_path / "part.ngc"
    path.write_text("G21 G90 G0 X1\n" + comment.format(bad=bad) +
                    "\nG0 X2\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError) as e:
        m.wait_program(timeout=10)
    text = str(e.value)
    assert text == (f"{path}:2: {what}: cannot open '{bad}' ({bad}): "
                    "No such file or directory")
    assert ("error", text) in m.errors()
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    assert st.task_state is TaskState.ESTOP_RESET
    assert st.position[0] <= 1 + 1e-6       # stopped: X2 not run


@pytest.mark.parametrize("body, kind, text", [
    ("LOGOPEN, a b.txt ", "logopen", " a b.txt "),
    ("  logappend,x", "logappend", "x"),
    ("LOGOPEN ,x", "", "LOGOPEN ,x"),
    ("L O G,x", "", "L O G,x"),
    ("MSG ,x", "", "MSG ,x"),
    (" msg,x", "msg", "x"),
    (" LOGCLOSE", "logclose", ""),
    ("LOGCLOSE ", "", "LOGCLOSE "),
    ("LOGCLOSE,x", "", "LOGCLOSE,x"),
    ("   plain  ", "", "plain  "),
    ("py,x = 1", "py", "x = 1"),
    ("PY, x", "py", " x"),
])
def test_comment_kinds_as_the_reference_reads_them(body, kind, text):
    # checked against the reference's rs274 (tests/gcode/programs/glog)
    assert comment_kind(body) == (kind, text)


@pytest.mark.parametrize("text, found", [
    ("PROBEOPEN  p q.txt ", ("open", "p q.txt ")),
    ("PROBEOPENs.txt", ("open", "s.txt")),
    ("probeopen r.txt", None),
    ("PROBECLOSE now", ("close", "")),
    ("PROBE OPEN x", None),
])
def test_probe_comments(text, found):
    assert probe_comment(text) == found


def test_py_comments_run_in_the_plugin(hal, tmp_path: Path) -> None:
    from halsdk.ini import IniFile
    m = build(hal, tmp_path)
    (tmp_path / "toplevel.py").write_text("lines = []\n")
    ini = tmp_path / "machine.ini"
    ini.write_text("[RS274NGC]\n[PYTHON]\nTOPLEVEL = toplevel.py\n")
    m.configure_from_ini(IniFile(str(ini)))
    turn_on(m)
    out = tmp_path / "py.txt"
    run_program(m, tmp_path, f"G21 G90 G0 X1\n;py,lines.append('a')\n"
                "G0 X2 (py,lines += ['b'])\n"
                "G0 X3 ;py,lines.append('not run')\n"
                f";py,open({str(out)!r}, 'w').write(' '.join(lines))\nM2\n")
    assert out.read_text() == "a b"
    assert m.status().position[0] == pytest.approx(3, abs=1e-6)
    # a Python error stops the program with its line
    path = tmp_path / "bad.ngc"
    path.write_text("G0 X1\n;py,1 / 0\nG0 X2\nM2\n")
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError, match=f"^{path}:2:1: py comment "
                       "'1 / 0' raised ZeroDivisionError"):
        m.wait_program(timeout=10)


def test_a_py_comment_without_a_plugin_is_an_error(hal, tmp_path: Path
                                                   ) -> None:
    m = build(hal, tmp_path)
    turn_on(m)
    path = tmp_path / "part.ngc"
    path.write_text("G0 X1\n;py,print('hello')\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError) as e:
        m.wait_program(timeout=10)
    assert str(e.value) == (f"{path}:2:1: a ;py, or (py,...) comment needs "
                            "the [PYTHON] plugin of an INI file (TOPLEVEL=)")
    assert ("error", str(e.value)) in m.errors()
