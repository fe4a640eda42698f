"""halsdk/demo/mill: the simulated three-axis servo mill (pid loops, simulated
motors and encoders, home switches with index) is started from its INI file,
enabled, homed, jogged and moved along a line and an arc, deterministically;
the tuned loops keep the following error far below the limits."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from helpers import repo_path

from halsdk.ini import IniFile
from halsdk.machine.launcher import Launcher
from halsdk.testing import private_instance_name

MILL = repo_path("halsdk", "demo", "mill")
INI = MILL / "mill.ini"
JOINTS = range(3)


def ini_float(section: str, key: str) -> float:
    return float(IniFile(str(INI)).get(section, key))


def ferror_pins(hal) -> list[float]:
    return [abs(hal.getp(f"joint.{n}.f-error")) for n in JOINTS]


def run_recording(machine: Launcher, done, limit: int = 60000) -> list[float]:
    """Step the servo thread until ``done(status)``, recording the largest
    |joint.N.f-error| seen in any period."""
    worst = [0.0, 0.0, 0.0]
    for _ in range(limit):
        machine.hal.step(1)
        worst = [max(w, f) for w, f in zip(worst, ferror_pins(machine.hal))]
        if done(machine.motion.status()):
            return worst
    raise AssertionError("the machine did not finish the move")


def at_rest(st) -> bool:
    return st.in_position and st.queue_depth == 0 and not st.homing


@pytest.fixture
def machine(monkeypatch):
    monkeypatch.setenv("HALSDK_INSTANCE", private_instance_name())
    m = Launcher(str(INI))
    m.start(realtime=False)
    try:
        yield m
    finally:
        m.shutdown()


def enable_and_home(machine: Launcher) -> list[float]:
    motion = machine.motion
    motion.enable()
    motion.home()
    return run_recording(machine, lambda st: st.all_homed and at_rest(st))


def test_the_loops_get_their_gains_from_the_ini_file(machine):
    hal = machine.hal
    for n, letter in enumerate("xyz"):
        section = f"JOINT_{n}"
        assert hal.getp(f"pid-{letter}.Pgain") == ini_float(section, "P")
        assert hal.getp(f"pid-{letter}.FF1") == ini_float(section, "FF1")
        assert hal.getp(f"pid-{letter}.FF2") == ini_float(section, "FF2")
        assert hal.getp(f"pid-{letter}.maxoutput") == \
            ini_float(section, "MAX_OUTPUT")
        assert hal.getp(f"enc-{letter}.in1") == \
            ini_float(section, "INPUT_SCALE")
    # amplifiers off until motion is enabled
    assert not any(hal.getp(f"pid-{letter}.enable") for letter in "xyz")


def test_homing_enables_the_amps_and_ends_exactly_at_home(machine):
    worst = enable_and_home(machine)
    hal = machine.hal
    st = machine.motion.status()
    assert st.all_homed and st.enabled
    for n in JOINTS:
        assert hal.getp(f"joint.{n}.amp-enable-out")
        assert st.joints[n].pos_cmd == ini_float(f"JOINT_{n}", "HOME")
    machine.hal.step(200)                       # let the loops settle
    count = 1 / ini_float("JOINT_0", "INPUT_SCALE")
    for n, j in enumerate(machine.motion.status().joints[:3]):
        # the encoder quantizes: a few counts at most
        assert abs(j.pos_fb - j.pos_cmd) <= 3 * count, n
    for n in JOINTS:
        # homing moves ran (the switches are far away) well within MIN_FERROR
        assert 0 < worst[n] < ini_float(f"JOINT_{n}", "MIN_FERROR") / 5
    assert machine.motion.errors() == []


def test_jogs_and_a_line_and_an_arc_stay_far_below_ferror(machine):
    enable_and_home(machine)
    motion = machine.motion
    motion.jog_incr(0, 40, 50)                  # X +50
    motion.jog_abs(1, 40, 30)                   # Y to 30
    motion.jog_incr(2, 25, -20)                 # Z -20
    worst_jog = run_recording(machine, at_rest)
    st = motion.status()
    assert [j.pos_cmd for j in st.joints[:3]] == \
        pytest.approx([50, 30, -20], abs=1e-9)

    motion.coord()
    motion.queue_line({"x": 100, "y": 80, "z": -10}, 40)
    # half a circle around (120, 80), counterclockwise seen from +Z: it
    # passes through its lowest point (120, 60)
    motion.queue_circle({"x": 140, "y": 80, "z": -10}, (120, 80, -10),
                        (0, 0, 1), 30)
    seen_arc = []

    def done(s) -> bool:
        if s.joints[0].pos_cmd > 100.5:         # on the arc
            seen_arc.append(s.joints[1].pos_cmd)
        return at_rest(s)
    worst_coord = run_recording(machine, done)
    assert seen_arc and min(seen_arc) == pytest.approx(60, abs=0.05)
    machine.hal.step(200)
    st = motion.status()
    count = 1 / ini_float("JOINT_0", "INPUT_SCALE")
    for n, want in enumerate([140, 80, -10]):
        assert st.joints[n].pos_cmd == pytest.approx(want, abs=1e-9)
        assert st.joints[n].pos_fb == pytest.approx(want, abs=3 * count)
    for n in JOINTS:
        min_ferror = ini_float(f"JOINT_{n}", "MIN_FERROR")
        assert 0 < worst_jog[n] < min_ferror / 5, (n, worst_jog)
        assert worst_coord[n] < min_ferror / 5, (n, worst_coord)
        assert st.joints[n].ferror_high_mark < min_ferror / 5
        assert not st.joints[n].ferror_exceeded
    assert motion.errors() == []


def test_without_the_loop_the_error_trips_the_ferror_check(machine):
    """The limits do bite: with the loop's gains zeroed the table never
    moves and motion reports the following error and disables itself."""
    hal = machine.hal
    for letter in "xyz":
        for pin in ("Pgain", "FF1", "FF2"):
            hal.setp(f"pid-{letter}.{pin}", 0.0)
    machine.motion.enable()
    machine.motion.jog_incr(0, 40, 20)
    for _ in range(2000):
        hal.step(1)
        if not machine.motion.status().enabled:
            break
    assert not machine.motion.status().enabled
    assert any("following error" in e for e in machine.motion.errors())


def test_the_toolchanger_stand_in_acknowledges_prepare_and_change(
        machine, tmp_path):
    # halsdk run made iocontrol.0 from [EMCIO] before mill.hal and
    # toolchange.hal ran, so the stand-in's nets are in place
    io = machine.io
    io.table.path = str(tmp_path / "tool.tbl")     # never the example's
    io.estop_reset()
    io.poll()                       # user-enable-out reached emc-enable-in
    io.poll()
    io.machine_on()
    io.prepare(2)
    io.poll()                       # tool-prepared came back through the net
    io.change()
    io.poll()
    assert io.table.tool_in_spindle == 2
    assert machine.hal.getp("iocontrol.0.tool-number") == 2
    assert io.changes == 1


def test_halsdk_run_starts_and_stops_the_mill(tmp_path):
    env = dict(os.environ, HALSDK_INSTANCE=private_instance_name())
    proc = subprocess.run([sys.executable, "-m", "halsdk.machine.cli", "run",
                           str(INI), "--seconds", "1"], cwd=str(tmp_path),
                          env=env, text=True, capture_output=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "machine running" in proc.stdout and "stopped" in proc.stdout
