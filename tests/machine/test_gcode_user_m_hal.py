"""User M-codes (M100-M199), #<_hal[name]> and G5.2 NURBS on a
simulated machine: the programs are run through halsdk.machine.Machine,
the M-code is a script on the INI's USER_M_PATH, the HAL items are set
while it runs."""

from __future__ import annotations

import os
import signal
import stat
import time
from pathlib import Path
from typing import Callable

import pytest
from helpers.motion_trace import looped_machine

from halsdk.ini import IniFile
from halsdk.machine import (
    InterpState,
    Machine,
    MachineError,
    TaskMode,
    TaskState,
    ToolTable,
)
from halsdk.machine.usermcode import UserMError, UserMRun, find_user_m, search_path

P = "iocontrol.0."

#: M101 writes its arguments and the moment it ran to the file "out"
M101 = """#!/bin/sh
echo "$1 $2" >> out
"""


def executable(path: Path, text: str) -> Path:
    path.write_text(text)
    path.chmod(path.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP
               | stat.S_IXOTH)
    return path


def build(hal, tmp_path: Path, ini_text: str) -> Machine:
    motion = looped_machine(hal, vmax=100.0, amax=1000.0, travel=200.0)
    motion.disable()
    for j in range(3):
        motion.set_joint_homing(j, HOME_SEQUENCE=0, HOME_SEARCH_VEL=0,
                                HOME_LATCH_VEL=0)
    m = Machine(hal, motion, tool_table=ToolTable())
    hal.net("prep-loop", P + "tool-prepare", P + "tool-prepared")
    hal.net("change-loop", P + "tool-change", P + "tool-changed")
    hal.setp(P + "emc-enable-in", True)
    ini = tmp_path / "machine.ini"
    ini.write_text(ini_text)
    m.configure_from_ini(IniFile(str(ini)))
    m.state(TaskState.ESTOP_RESET)
    m.state(TaskState.ON)
    m.home()
    return m


def start(m: Machine, tmp_path: Path, text: str) -> None:
    path = tmp_path / "part.ngc"
    path.write_text(text)
    m.mode(TaskMode.AUTO)
    m.program_open(str(path))
    m.program_run()


def settle(m: Machine, seconds: float = 20,
           until: Callable[[], bool] = lambda: False) -> None:
    """Step the (simulated) machine in real time, as M-codes run in real
    time, until the program is idle or ``until()``; raise its error."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and not until():
        if m.status().interp_state is InterpState.IDLE:
            m.wait_program(timeout=0.01)        # raises the job's error
            return
        m.update()
        time.sleep(0.0005)
    if not until():
        pytest.fail(f"the program did not end within {seconds} s")


def run(m: Machine, tmp_path: Path, text: str) -> None:
    start(m, tmp_path, text)
    settle(m)


INI = """[DISPLAY]
PROGRAM_PREFIX = programs
[RS274NGC]
USER_M_PATH = mcodes:more
HALSDK_USER_M_TIMEOUT = 3
"""


@pytest.fixture
def mcodes(tmp_path):
    folder = tmp_path / "mcodes"
    folder.mkdir()
    executable(folder / "M101", M101)
    return folder


def test_m101_runs_with_p_and_q_after_the_moves_before_the_next(
        hal, tmp_path, mcodes):
    m = build(hal, tmp_path, INI)
    run(m, tmp_path, "G21 G90 G1 X5 F3000\nM101 P1.5 Q-2\nM101\n"
        "M101 P3\nG0 X7\nM2\n")
    lines = (mcodes / "out").read_text().splitlines()
    assert lines == ["1.500000 -2.000000", "-1.000000 -1.000000",
                     "3.000000 -1.000000"]
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    assert st.position[0] == pytest.approx(7)
    assert [e for e in m.errors() if e[0] == "error"] == []


def test_the_machine_waits_for_the_m_code(hal, tmp_path, mcodes):
    # the M-code holds the program until it exits: the move after it
    # starts only once the file it waits for has been written
    executable(mcodes / "M103", "#!/bin/sh\nwhile [ ! -e go ]; do "
               "sleep 0.05; done\necho done > seen\n")
    m = build(hal, tmp_path, INI)
    start(m, tmp_path, "G21 G90 G0 X1\nM103\nG0 X9\nM2\n")
    settle(m, 10, until=lambda: m.status().position[0] > 0.999)
    end = time.monotonic() + 0.3
    while time.monotonic() < end:
        m.update()
        time.sleep(0.001)
    st = m.status()
    assert st.interp_state is not InterpState.IDLE
    assert st.position[0] == pytest.approx(1)
    (mcodes / "go").write_text("")
    settle(m)
    assert (mcodes / "seen").read_text() == "done\n"
    assert m.status().position[0] == pytest.approx(9)


def test_mdi_m_code_and_the_exec_state_while_it_runs(hal, tmp_path, mcodes):
    from halsdk.channels.constants import EXEC_DONE, EXEC_WAITING_FOR_SYSTEM_CMD
    # (written whole, then renamed: the test polls for the file)
    executable(mcodes / "M105", '#!/bin/sh\necho "$1 $2" > args.tmp\n'
               'mv args.tmp args\n'
               'while [ ! -e go ]; do sleep 0.05; done\n')
    m = build(hal, tmp_path, INI)
    m.mode(TaskMode.MDI)
    m.mdi("M105 P7 Q-0.5", wait=False)
    settle(m, 10, until=lambda: (mcodes / "args").exists())
    assert (mcodes / "args").read_text() == "7.000000 -0.500000\n"
    assert m.exec_state() == EXEC_WAITING_FOR_SYSTEM_CMD
    (mcodes / "go").write_text("")
    settle(m, 10, until=lambda: m.exec_state() == EXEC_DONE
           and m.status().interp_state is InterpState.IDLE)
    assert [e for e in m.errors() if e[0] == "error"] == []


@pytest.mark.parametrize("script, why", [
    ("exit 3", "exited with status 3"),
    ("kill -TERM $$", "was killed by signal 15"),
    ("sleep 30", "still running after 3 s, killed"),
])
def test_a_failing_m_code_aborts_the_program(hal, tmp_path, mcodes,
                                             script, why):
    executable(mcodes / "M110", f"#!/bin/sh\n{script}\n")
    m = build(hal, tmp_path, INI)
    start = time.monotonic()
    with pytest.raises(MachineError, match=f"part.ngc:2: M110: .*M110 "
                       f"{why}"):
        run(m, tmp_path, "G21 G0 X1\nM110\nG0 X9\nM2\n")
    assert time.monotonic() - start < 20         # bounded, no hang
    st = m.status()
    assert st.interp_state is InterpState.IDLE
    assert st.position[0] == pytest.approx(1)
    assert any(k == "error" and "M110" in t for k, t in m.errors())


def test_unknown_m_code_names_the_line(hal, tmp_path, mcodes):
    (mcodes / "M120").write_text("#!/bin/sh\n")     # not executable
    m = build(hal, tmp_path, INI)
    with pytest.raises(MachineError, match="part.ngc:2:1: Unknown m code "
                       "used: M120"):
        run(m, tmp_path, "G21 G0 X1\nM120\nM2\n")


def test_the_ini_keys_are_known_to_the_ini_check(tmp_path):
    from halsdk.machine.inicheck import check_ini
    ini = tmp_path / "machine.ini"
    ini.write_text(INI + "HAL_PIN_VARS = 1\nHALSDK_MAX_ITERATIONS = 9\n"
                   "HALSDK_MAX_IDLE_TIME = 9\nHALSDK_USER_M_TIMEOUTS = 1\n")
    problems = [str(p) for p in check_ini(IniFile(str(ini)))]
    assert len(problems) == 1
    assert "HALSDK_USER_M_TIMEOUTS: unknown key" in problems[0]
    assert "HALSDK_USER_M_TIMEOUT" in problems[0]      # the suggestion


def test_a_bad_timeout_in_the_ini_names_the_line(hal, tmp_path):
    with pytest.raises(MachineError, match="machine.ini:5: "
                       "HALSDK_USER_M_TIMEOUT '0' is not a number of "
                       "seconds above 0"):
        build(hal, tmp_path, INI.replace("= 3", "= 0"))


def test_the_search_path_order(tmp_path):
    for name in ("programs", "mcodes", "more"):
        (tmp_path / name).mkdir()
    executable(tmp_path / "more" / "M150", "#!/bin/sh\n")
    folders = search_path(str(tmp_path), "programs", "mcodes:more")
    assert folders == [str(tmp_path / n) for n in
                       ("programs", "mcodes", "more")]
    assert find_user_m(150, folders) == str(tmp_path / "more" / "M150")
    executable(tmp_path / "programs" / "M150", "#!/bin/sh\n")
    assert find_user_m(150, folders) == str(tmp_path / "programs" / "M150")
    assert find_user_m(151, folders) is None
    assert find_user_m(99, folders) is None
    # without PROGRAM_PREFIX: nc_files beside the INI file
    assert search_path("/m", None, None) == ["/m/nc_files"]


def test_a_run_that_cannot_start_says_why(tmp_path):
    bad = executable(tmp_path / "M130", "not a script")
    with pytest.raises(UserMError, match="M130: cannot run"):
        UserMRun(130, str(bad), 0, 0)


def test_timeout_uses_the_clock_and_kills_the_group(tmp_path):
    now = [0.0]
    script = executable(tmp_path / "M140", "#!/bin/sh\nsleep 30 &\n"
                        "echo $! > c.tmp\nmv c.tmp child\nwait\n")
    run_ = UserMRun(140, str(script), 1, 2, timeout=5, clock=lambda: now[0])
    assert run_.argv[1:] == ["1.000000", "2.000000"]
    assert run_.poll() is False
    deadline = time.monotonic() + 5
    while not (tmp_path / "child").exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    child = int((tmp_path / "child").read_text())
    now[0] = 5.0
    with pytest.raises(UserMError, match="still running after 5 s"):
        run_.poll()
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        time.sleep(0.02)
    else:
        pytest.fail("the M-code's child survived the timeout")


def test_abort_kills_a_running_m_code(hal, tmp_path, mcodes):
    executable(mcodes / "M104", "#!/bin/sh\necho $$ > p.tmp\nmv p.tmp pid\n"
               "sleep 30\n")
    m = build(hal, tmp_path, INI)
    start(m, tmp_path, "G21 M104\nM2\n")
    settle(m, 10, until=lambda: (mcodes / "pid").exists())
    pid = int((mcodes / "pid").read_text())
    m.abort()
    assert m.status().interp_state is InterpState.IDLE
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)


def test_hal_items_are_read_live(hal, tmp_path, mcodes):
    hal.newsig("gauge", "float")
    hal.sets("gauge", 2.5)
    m = build(hal, tmp_path, INI)
    # the signal changes between two runs; a pin and a param too
    text = ("#1 = #<_hal[gauge]>\n#2 = #<_hal[motion.motion-enabled]>\n"
            "#3 = EXISTS[#<_hal[no.such.item]>]\n"
            "#4 = #<_hal[iocontrol.0.emc-enable-in]>\n"
            "(debug, gauge=#<_hal[gauge]>)\nM2\n")
    run(m, tmp_path, text)
    assert (m.params.get(1), m.params.get(2), m.params.get(3),
            m.params.get(4)) == (2.5, 1.0, 0.0, 1.0)
    assert ("display", "gauge=2.500000") in m.errors()
    hal.sets("gauge", -7.25)
    run(m, tmp_path, text)
    assert m.params.get(1) == -7.25


def test_hal_item_unknown_or_feature_off_is_an_error(hal, tmp_path,
                                                     mcodes):
    hal.newsig("gauge", "float")
    m = build(hal, tmp_path, INI + "HAL_PIN_VARS = 0\n")
    with pytest.raises(MachineError, match=r"part.ngc:1:6: Named "
                       r"parameter #<_hal\[gauge\]> not defined"):
        run(m, tmp_path, "#1 = #<_hal[gauge]>\nM2\n")
    m.state(TaskState.ON)
    m.hal_pin_vars = True
    with pytest.raises(MachineError, match=r"Named parameter "
                       r"#<_hal\[nope\]> not defined"):
        run(m, tmp_path, "#1 = #<_hal[nope]>\nM2\n")


def test_a_nurbs_block_moves_the_machine_along_the_curve(hal, tmp_path):
    from halsdk.gcode.nurbs import knot_vector, point
    m = build(hal, tmp_path, INI)
    xs: list[tuple[float, float]] = []
    hal.add_python_function("xy-trace", lambda period: xs.append(
        (hal.getp("joint.0.motor-pos-cmd"),
         hal.getp("joint.1.motor-pos-cmd"))), thread="servo-thread")
    start(m, tmp_path, "G21 G90 G0 X0 Y0\nF6000\nG5.2 P1 L3\nX0 Y10 P1\n"
          "X20 Y20 P1\nX20 Y0 P1\nX0 Y0 P2\nG5.3\nM2\n")
    m.wait_program(timeout=60)          # (servo time: no M-code here)
    assert m.status().position[:2] == pytest.approx((0, 0), abs=1e-6)
    ctrl = [(0, 0), (0, 10), (20, 20), (20, 0), (0, 0)]
    knots = knot_vector(5, 3)
    curve = [point(ctrl, [1, 1, 1, 1, 2], 3, knots, j / 400)
             for j in range(401)]
    # the machine went as far right and up as the curve, not further
    assert max(x for x, _ in xs) == pytest.approx(
        max(x for x, _ in curve), abs=0.01)
    assert max(y for _, y in xs) == pytest.approx(
        max(y for _, y in curve), abs=0.01)
    assert [e for e in m.errors() if e[0] == "error"] == []


def test_a_user_m_code_ends_with_the_thread_that_started_it(tmp_path):
    """A machine that dies (its task thread ends, however) leaves no
    M-code running: the kernel sends it SIGTERM."""
    import threading
    script = executable(tmp_path / "M150", "#!/bin/sh\nexec sleep 30\n")
    runs: list[UserMRun] = []
    thread = threading.Thread(
        target=lambda: runs.append(UserMRun(150, str(script), 0, 0)))
    thread.start()
    thread.join()
    process = runs[0].process
    try:
        assert process.wait(timeout=10) == -signal.SIGTERM
    finally:
        runs[0].kill()
