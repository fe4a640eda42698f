"""The machine control API (halsdk.machine.Machine) on a simulated,
stepped machine: motmod + trivkins + homemod + tpmod with looped feedback,
an IoControl whose toolchanger answers at once (tool-prepare and
tool-change looped to their answers), and a probe that trips below a
machine Z."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers import repo_path
from helpers.motion_trace import looped_machine

from halsdk.machine import (
    InterpState,
    Machine,
    MachineError,
    TaskMode,
    TaskState,
    ToolTable,
)

P = "iocontrol.0."
PROBE_Z = 12.0          # machine Z below which the probe is tripped

TABLE = "T1 P1 Z10 D6\nT2 P2 Z20 D3\n"

PROGRAM = """(two tools, an arc and a probe)
G21 G90 G17 G94
T1 M6
G43
G0 X0 Y0 Z5
S1000 M3
G1 Z-1 F600
G2 X10 Y0 I5 J0
T2 M6
G43
G0 Z5
G38.2 Z-20 F300
G0 Z5
M5
M2
"""


def build(hal, tmp_path: Path, random: bool = False) -> Machine:
    motion = looped_machine(hal, vmax=100.0, amax=1000.0, travel=200.0)
    motion.disable()
    for j in range(3):                  # home where it stands, together
        motion.set_joint_homing(j, HOME_SEQUENCE=0, HOME_SEARCH_VEL=0,
                                HOME_LATCH_VEL=0)
    path = tmp_path / "tool.tbl"
    path.write_text(("T0 P0\n" if random else "") + TABLE)
    table = ToolTable.load(str(path), random=random)
    m = Machine(hal, motion, tool_table=table)
    hal.net("prep-loop", P + "tool-prepare", P + "tool-prepared")
    hal.net("change-loop", P + "tool-change", P + "tool-changed")

    def probe(period: int) -> None:
        z = hal.getp("joint.2.motor-pos-cmd")
        hal.setp("motion.probe-input", z < PROBE_Z)
    hal.add_python_function("probe-sim", probe, thread="servo-thread")
    hal.setp(P + "emc-enable-in", True)       # the outside chain is closed
    return m


def turn_on(m: Machine) -> None:
    m.state(TaskState.ESTOP_RESET)
    m.state(TaskState.ON)
    m.home()


@pytest.fixture
def machine(hal, tmp_path):
    return build(hal, tmp_path)


def test_states_and_refusals(machine):
    m = machine
    assert m.status().task_state is TaskState.ESTOP
    with pytest.raises(MachineError, match="E-stop"):
        m.state(TaskState.ON)
    with pytest.raises(MachineError, match="not on"):
        m.home()
    m.state(TaskState.ESTOP_RESET)
    assert m.status().task_state is TaskState.ESTOP_RESET
    assert not m.status().enabled
    m.state(TaskState.ON)
    st = m.status()
    assert st.task_state is TaskState.ON and st.enabled
    m.home()
    assert all(m.status().homed)
    with pytest.raises(MachineError, match="MDI mode"):
        m.mdi("G0 X1")
    m.mode(TaskMode.AUTO)
    with pytest.raises(MachineError, match="MANUAL"):
        m.jog(0, 10.0, 1.0)
    with pytest.raises(MachineError, match="no program open"):
        m.program_run()
    with pytest.raises(MachineError, match="MDI mode"):
        m.mdi("G0 X1")
    m.state(TaskState.OFF)
    st = m.status()
    assert st.task_state is TaskState.ESTOP_RESET and not st.enabled
    m.state(TaskState.ON)
    m.state(TaskState.ESTOP)
    assert m.status().task_state is TaskState.ESTOP
    assert not m.status().enabled


def test_external_estop_disables_motion(machine, hal):
    m = machine
    turn_on(m)
    hal.setp(P + "emc-enable-in", False)
    m.update()
    m.update()
    st = m.status()
    assert st.task_state is TaskState.ESTOP and not st.enabled
    assert any("external E-stop" in t for _, t in m.errors())


def test_jog_in_manual_and_mdi(machine):
    m = machine
    turn_on(m)
    m.jog(0, 20.0, 2.5)
    assert m.status().position[0] == pytest.approx(2.5, abs=1e-6)
    m.mode(TaskMode.MDI)
    m.mdi("G21 G90 G0 X10 Y-5 Z3")
    assert m.status().position[:3] == pytest.approx((10, -5, 3), abs=1e-6)
    m.mdi("G91 G1 X-4 F1200")
    assert m.status().position[0] == pytest.approx(6, abs=1e-6)
    m.mdi("G90 M8")
    assert m.status().flood
    m.mdi("M9 (MSG, hello)")
    assert not m.status().flood
    assert ("display", "hello") in m.errors()


def run_program(m: Machine, tmp_path: Path, text: str) -> Path:
    path = tmp_path / "part.ngc"
    path.write_text(text)
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    assert m.status().interp_state is InterpState.READING
    m.wait_program(timeout=60)
    return path


@pytest.mark.parametrize("random", [False, True])
def test_program_with_two_tool_changes_arc_and_probe(hal, tmp_path, random):
    m = build(hal, tmp_path, random)
    turn_on(m)
    run_program(m, tmp_path, PROGRAM)
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    assert st.tool_in_spindle == 2 and st.tool_changes == 2
    # G43 with tool 2 (Z20): program Z5 is machine Z25
    assert st.position[:3] == pytest.approx((10, 0, 25), abs=1e-6)
    assert st.tool_offset[2] == pytest.approx(20)
    # the probe tripped near machine Z12, program Z-8
    assert m.params.get(5070) == 1
    assert m.params.get(5063) == pytest.approx(PROBE_Z - 20, abs=0.05)
    assert m.executor.probes == 1
    assert not st.motion.spindles[0].on
    text = (tmp_path / "tool.tbl").read_text()
    if random:
        # the changer swapped: T2 in the spindle (P0), T1 went to P2
        assert "T2 P0" in text and "T1 P2" in text
    else:
        assert "T1 P1" in text and "T2 P2" in text
    assert [e for e in m.errors() if e[0] == "error"] == []


def test_arc_goes_through_the_far_side(machine, hal, tmp_path):
    m = machine
    turn_on(m)
    ys: list[float] = []
    hal.add_python_function(
        "y-trace", lambda period: ys.append(hal.getp("joint.1.motor-pos-cmd")),
        thread="servo-thread")
    path = tmp_path / "arc.ngc"
    path.write_text("G21 G90 G0 X0 Y0 Z0\nG2 X10 Y0 I5 J0 F3000\nM2\n")
    run_program(m, tmp_path, path.read_text())
    # clockwise from (0,0) to (10,0) around (5,0) passes over Y=+5
    assert max(ys) == pytest.approx(5.0, abs=1e-3)
    assert min(ys) > -1e-6
    assert m.status().position[:2] == pytest.approx((10, 0), abs=1e-6)


def test_errors_name_file_and_line(machine, tmp_path):
    m = machine
    turn_on(m)
    path = tmp_path / "bad.ngc"
    path.write_text("G21 G90 G0 X1\nG1 X2 F100\nG1 X3 Q#<nope>\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError) as e:
        m.wait_program(timeout=10)
    assert f"{path}:3:" in str(e.value)
    errors = m.errors()
    assert any(k == "error" and f"{path}:3:" in t for k, t in errors)
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    # bad input leaves the machine safe: off, motion disabled
    assert st.task_state is TaskState.ESTOP_RESET and not st.enabled
    # a probe without contact is reported with its line too
    m.state(TaskState.ON)
    path.write_text("G21 G90 G0 Z50\nG38.2 Z40 F600\nM2\n")
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError, match=f"{path}:2: .*without contact"):
        m.wait_program(timeout=10)


@pytest.mark.parametrize("pin,text", [
    ("joint.1.amp-fault-in", "joint 1 amplifier fault"),
    ("joint.2.neg-lim-sw-in", "joint 2 on its negative hard limit"),
])
def test_machine_on_with_a_fault_stays_off_and_says_why(hal, machine, pin,
                                                        text):
    m = machine
    hal.setp(pin, True)
    m.state(TaskState.ESTOP_RESET)
    with pytest.raises(MachineError, match=f"machine on failed: {text}"):
        m.state(TaskState.ON)
    st = m.status()
    assert st.task_state is TaskState.ESTOP_RESET and not st.enabled
    hal.setp(pin, False)
    m.state(TaskState.ON)
    assert m.status().task_state is TaskState.ON and m.status().enabled


def test_a_runaway_loop_is_reported_like_other_gcode_errors(machine,
                                                             tmp_path):
    from halsdk.ini import IniFile
    m = machine
    ini = tmp_path / "limits.ini"
    ini.write_text("[RS274NGC]\nHALSDK_MAX_ITERATIONS = 500\n"
                   "HALSDK_MAX_IDLE_TIME = 2.5\n")
    m.configure_from_ini(IniFile(str(ini)))
    assert (m.max_iterations, m.max_idle_time) == (500, 2.5)
    turn_on(m)
    path = tmp_path / "spin.ngc"
    path.write_text("G21 G90 G0 X1\no1 repeat [99999]\n  o2 repeat [99999]"
                    "\n  o2 endrepeat\no1 endrepeat\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError) as e:
        m.wait_program(timeout=10)
    assert str(e.value).startswith(f"{path}:3:3: loop exceeds the limit "
                                   "of 500 loop iterations")
    assert any(k == "error" and t == str(e.value) for k, t in m.errors())
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    assert st.task_state is TaskState.ESTOP_RESET and not st.enabled


@pytest.mark.parametrize("entry, why", [
    ("HALSDK_MAX_ITERATIONS = 0", "is not a whole number above 0"),
    ("HALSDK_MAX_ITERATIONS = 2.5", "is not a whole number above 0"),
    ("HALSDK_MAX_IDLE_TIME = -1", "is not a number of seconds above 0"),
    ("HALSDK_MAX_IDLE_TIME = soon", "is not a number of seconds above 0"),
])
def test_bad_control_flow_limits_in_the_ini_name_the_line(machine, tmp_path,
                                                          entry, why):
    from halsdk.ini import IniFile
    ini = tmp_path / "bad.ini"
    ini.write_text(f"[RS274NGC]\n{entry}\n")
    with pytest.raises(MachineError, match=f"bad.ini:2: .* {why}"):
        machine.configure_from_ini(IniFile(str(ini)))


def test_m0_pauses_and_resume_continues(machine, tmp_path):
    m = machine
    turn_on(m)
    path = tmp_path / "p.ngc"
    path.write_text("G21 G90 G0 X5\nM0\nG0 X7\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError, match="M0"):
        m.wait_program(timeout=10)
    assert m.status().interp_state is InterpState.PAUSED
    assert m.status().position[0] == pytest.approx(5)
    with pytest.raises(MachineError, match="interpreter"):
        m.mode(TaskMode.MDI)
    m.resume()
    m.wait_program(timeout=10)
    assert m.status().position[0] == pytest.approx(7)


def test_abort_mid_program_leaves_the_machine_safe(machine, tmp_path):
    m = machine
    turn_on(m)
    path = tmp_path / "long.ngc"
    path.write_text("G21 G90 G0 X0 Y0 Z0\nS500 M3 M8\nG1 X100 F600\n"
                    "G1 Y100\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    m.run_for(1.0)
    st = m.status()
    assert st.current_line == 3 and st.motion.spindles[0].on and st.flood
    m.abort()
    m.run_for(0.5)
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    assert st.task_state is TaskState.ON
    assert st.motion.queue_depth == 0 and st.motion.in_position
    assert 0 < st.position[0] < 100 and st.position[1] == 0
    assert not st.motion.spindles[0].on and not st.flood
    # the machine accepts new work
    m.mode(TaskMode.MDI)
    m.mdi("G0 X0")
    assert m.status().position[0] == pytest.approx(0, abs=1e-6)


def test_tool_table_edits(machine, tmp_path):
    m = machine
    m.set_tool_offsets(2, offset=(0, 0, 33, 0, 0, 0, 0, 0, 0), diameter=4)
    assert "T2 P2 Z33 D4" in (tmp_path / "tool.tbl").read_text()
    assert m.interp.tools.entry(m.interp.tools.pocket_of(2)).offset[2] == 33
    (tmp_path / "tool.tbl").write_text("T7 P3 Z1\n")
    m.load_tool_table()
    assert m.io.table.tools() == [7]
    other = tmp_path / "copy.tbl"
    m.save_tool_table(str(other))
    assert other.read_text() == "T7 P3 Z1\n"


def test_mdi_tool_commands_input_wait_and_dwell(machine, hal, tmp_path):
    m = machine
    turn_on(m)
    m.mode(TaskMode.MDI)
    m.mdi("M61 Q1")
    m.mdi("G43")
    assert m.status().tool_in_spindle == 1
    assert m.status().tool_offset[2] == pytest.approx(10)
    m.mdi("G10 L1 P1 Z12.5")
    assert "T1 P1 Z12.5" in (tmp_path / "tool.tbl").read_text()
    m.mdi("G43")
    assert m.status().tool_offset[2] == pytest.approx(12.5)
    hal.setp("motion.digital-in-00", True)
    m.update()                          # motion reads its inputs
    m.mdi("M66 P0 L0")
    assert m.params.get(5399) == 1
    m.mdi("M66 P0 L4 Q0.05")           # wait for LOW: times out
    assert m.params.get(5399) == -1
    before = m.status().motion.heartbeat
    m.mdi("G4 P0.25")
    assert m.status().motion.heartbeat - before >= 250


def test_feed_override_slows_the_program(machine, tmp_path):
    m = machine
    turn_on(m)
    m.feed_override(0.5)
    m.rapid_override(0.5)
    st = m.status()
    assert st.feedrate == 0.5 and st.rapidrate == 0.5
    path = tmp_path / "f.ngc"
    path.write_text("G21 G90 G1 X10 F600\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    m.run_for(1.0)          # 10 mm at 5 mm/s takes 2 s
    assert 3 < m.status().position[0] < 6
    m.wait_program(timeout=10)
    assert m.status().position[0] == pytest.approx(10)


def test_step_and_start_line(machine, tmp_path):
    m = machine
    turn_on(m)
    path = tmp_path / "s.ngc"
    path.write_text("G21 G90 G0 X1\nM0\nG0 X2\nG0 X3\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    with pytest.raises(MachineError, match="M0"):
        m.wait_program(timeout=10)
    m.step()
    m.run_for(0.5)
    st = m.status()
    assert st.interp_state is InterpState.PAUSED
    assert st.position[0] == pytest.approx(2)
    m.resume()
    m.wait_program(timeout=10)
    assert m.status().position[0] == pytest.approx(3)
    # from line 4 on: only X3 after a move elsewhere
    m.mode(TaskMode.MDI)
    m.mdi("G0 X-5")
    m.mode(TaskMode.AUTO)
    m.program_run(start_line=4, wait=True)
    assert m.status().position[0] == pytest.approx(3)
    with pytest.raises(MachineError, match="pause first"):
        m.step()


def test_from_launcher_reads_the_emcio_section(tmp_path, monkeypatch):
    from halsdk.machine.launcher import Launcher
    from halsdk.testing import private_instance_name
    monkeypatch.setenv("HALSDK_INSTANCE", private_instance_name())
    mill = repo_path("examples", "motion")
    text = (mill / "mill3.ini").read_text().replace(
        "HALFILE = mill3.hal", f"HALFILE = {mill / 'mill3.hal'}")
    text += "\n[EMCIO]\nTOOL_TABLE = tool.tbl\nRANDOM_TOOLCHANGER = 1\n"
    text += ("\n[RS274NGC]\nPARAMETER_FILE = mill.var\n"
             "SUBROUTINE_PATH = subs\n")
    (tmp_path / "mill.ini").write_text(text)
    (tmp_path / "tool.tbl").write_text("T0 P0\nT4 P3 Z7\n")
    (tmp_path / "mill.var").write_text("5221 12.5\n")
    (tmp_path / "subs").mkdir()
    (tmp_path / "subs" / "seven.ngc").write_text(
        "o<seven> sub\n#<_value> = 7\no<seven> endsub [7]\n")
    launcher = Launcher(str(tmp_path / "mill.ini"))
    launcher.start(realtime=False)
    m = None
    try:
        m = Machine.from_launcher(launcher)
        assert m.io.table.random and m.io.table.tools() == [0, 4]
        assert m.io.table.path == str(tmp_path / "tool.tbl")
        # [RS274NGC]: the var file is read, subroutines are found
        assert m.params.get(5221) == 12.5
        assert m.subroutine_path == [str(tmp_path / "subs")]
        m.params.set(5222, 3.0)
        m.save_parameters()
        assert "5222" in (tmp_path / "mill.var").read_text()
        launcher.hal.setp(P + "emc-enable-in", True)
        m.state(TaskState.ESTOP_RESET)
        m.state(TaskState.ON)
        assert m.status().enabled
        m.home()
        prog = tmp_path / "p.ngc"
        prog.write_text("G21 G90\no<seven> call\nG0 X#<_value>\nM2\n")
        m.mode(TaskMode.AUTO)
        m.program_open(str(prog))
        m.program_run()
        m.wait_program(timeout=30)
        # X7 from the subroutine, in G54 whose X offset #5221 = 12.5 came
        # from the var file
        assert m.status().position[0] == pytest.approx(7 + 12.5)
        m.state(TaskState.ESTOP)
        assert not m.status().enabled
    finally:
        if m is not None:
            m.io.close()
        launcher.shutdown()


def test_m66_waits_for_an_edge_while_the_machine_runs(machine, hal,
                                                      tmp_path):
    m = machine
    turn_on(m)
    path = tmp_path / "w.ngc"
    path.write_text("G21 G90 G0 X1\nM66 P1 L1 Q5\nG0 X[#5399 * 7]\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    m.run_for(0.3)
    st = m.status()
    assert st.interp_state is InterpState.READING
    assert st.position[0] == pytest.approx(1)
    hal.setp("motion.digital-in-01", True)          # the rising edge
    m.wait_program(timeout=10)
    assert m.params.get(5399) == 1
    assert m.status().position[0] == pytest.approx(7)
    # the abort while waiting drops the wait
    hal.setp("motion.digital-in-01", False)
    m.program_run()
    m.run_for(0.3)
    m.abort()
    assert m.status().interp_state is InterpState.IDLE
    assert list(m.executor.pending) == []


def test_remapped_codes_of_the_ini_run_on_the_machine(machine, tmp_path):
    """REMAP= lines and the [PYTHON] plugin of the machine's INI file:
    an M code done by an NGC procedure (from MDI and in a program), one
    done by Python, and o<name> call of a Python subroutine."""
    from halsdk.ini import IniFile
    m = machine
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "goto.ngc").write_text(
        "o<goto> sub\nG0 X#<p> Y[#<p> / 2]\no<goto> endsub\nM2\n")
    (tmp_path / "top.py").write_text("import remap\nimport oword\n")
    (tmp_path / "remap.py").write_text(
        "def lift(self, **words):\n"
        "    self.execute('G0 Z%f' % words['z'])\n")
    (tmp_path / "oword.py").write_text(
        "def half(self, a):\n    return a / 2\n")
    ini = tmp_path / "machine.ini"
    ini.write_text("[RS274NGC]\nSUBROUTINE_PATH = sub\n"
                   "REMAP=M400 modalgroup=10 argspec=P ngc=goto\n"
                   "REMAP=M401 argspec=Z python=lift\n"
                   "[PYTHON]\nTOPLEVEL = top.py\nPATH_APPEND = .\n")
    m.configure_from_ini(IniFile(str(ini)))
    turn_on(m)
    m.mode(TaskMode.MDI)
    m.mdi("G21 G90")
    m.mdi("M400 P8")
    assert m.status().position[:2] == pytest.approx((8, 4))
    m.mdi("M401 Z3")
    assert m.status().position[2] == pytest.approx(3)
    path = tmp_path / "p.ngc"
    path.write_text("G21 G90\no<half> call [10]\nM400 P#<_value>\n"
                    "M401 Z1\nM2\n")
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()
    m.wait_program(timeout=10)
    assert m.status().position[:3] == pytest.approx((5, 2.5, 1))
    m.mode(TaskMode.MDI)
    with pytest.raises(MachineError, match="<mdi>:1:1: user-defined M401: "
                                           "missing: Z"):
        m.mdi("M401")                   # Z is required


def test_a_remap_warning_is_an_operator_text_message(machine, tmp_path):
    """A REMAP code with no modalgroup=: the reference's warning, posted
    to the operator as a text message (the code still works)."""
    from halsdk.ini import IniFile
    (tmp_path / "m400.ngc").write_text("o<m400> sub\no<m400> endsub\n")
    ini = tmp_path / "warn.ini"
    ini.write_text("[RS274NGC]\nSUBROUTINE_PATH = .\n"
                   "REMAP=M400 ngc=m400\n")
    machine.errors()
    machine.configure_from_ini(IniFile(str(ini)))
    assert ("text", f"{ini}:3:0: warning: code 'M400' : no "
                    "modalgroup=<int> given, using default group 10 : "
                    "3:REMAP = M400 ngc=m400") in machine.errors()


def test_a_bad_remap_line_names_the_ini_line(machine, tmp_path):
    from halsdk.ini import IniFile
    ini = tmp_path / "bad.ini"
    ini.write_text("[RS274NGC]\n\nREMAP=M400 ngc=x python=y\n")
    with pytest.raises(MachineError,
                       match=r"bad.ini:3:0: REMAP=M400 ngc=x python=y: "
                             "ngc= and python= exclude each other"):
        machine.configure_from_ini(IniFile(str(ini)))


def test_task_and_call_level_on_a_machine(machine):
    """#<_task> is 1 in the machine's interpreter (0 in rs274 and in a
    preview); G97 is the machine's only spindle mode, G96 is refused."""
    m = machine
    turn_on(m)
    m.mode(TaskMode.MDI)
    m.mdi("#1 = #<_task>")
    m.mdi("#2 = [#<_vmajor> + #<_call_level>]")
    m.mdi("G97 S100")
    assert (m.params.get(1), m.params.get(2)) == (1.0, 2.9)
    with pytest.raises(MachineError, match="G96"):
        m.mdi("G96 S100")
