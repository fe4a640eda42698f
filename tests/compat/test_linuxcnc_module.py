"""Tests of the compat ``linuxcnc`` module (halsdk.compat.linuxcnc, what
``import linuxcnc`` finds on halsdk.compat.pythonpath()).

The names, constant values, attribute types and the messages of argument
errors are the reference's: ``tests/data/linuxcnc/module.json`` holds
what the LinuxCNC 2.9 module has (made by make_module_json.py beside it),
the argument errors were checked on the reference.  The tests that need a
machine, or none, run their client in a child process, so that this
process never attaches to an instance it does not own.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any, Callable

import pytest
from helpers import data_path, repo_path
from helpers.running_machine import running_machine

import halsdk
import halsdk.compat
from halsdk.compat import linuxcnc

GOLDEN = json.loads(data_path("linuxcnc", "module.json").read_text())
#: what the reference has and halsdk does not (listed in docs/compat.md)
ABSENT = {"positionlogger", "draw_lines", "draw_dwells", "line9", "vertex9",
          "gui_respect_offsets", "gui_rot_offsets"}
#: halsdk's additions: the manual's spelling of task_plan_synch
EXTRA_METHODS = {"task_plan_sync"}


def kind(value: Any) -> str:
    """What make_module_json.py writes for a value."""
    if isinstance(value, tuple):
        inner = type(value[0]).__name__ if value else ""
        return f"tuple[{len(value)}]" + (f" of {inner}" if inner else "")
    return type(value).__name__


def public(obj: Any) -> list[str]:
    return sorted(n for n in dir(obj) if not n.startswith("_"))


def client(code: str, env: dict[str, str], cwd: Path,
           timeout: float = 120) -> subprocess.CompletedProcess:
    """Run ``code`` (dedented) in a child Python with ``import linuxcnc``
    resolving to the compat module."""
    env = dict(env)
    env["PYTHONPATH"] = os.pathsep.join(
        p for p in (halsdk.compat.pythonpath(),
                    str(Path(halsdk.__file__).parents[1]),
                    env.get("PYTHONPATH")) if p)
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)],
                          env=env, cwd=str(cwd), capture_output=True,
                          text=True, timeout=timeout)


# ---------------------------------------------------------------- names

def test_import_linuxcnc_is_this_module(tmp_path: Path) -> None:
    assert os.path.isfile(os.path.join(halsdk.compat.pythonpath(),
                                       "linuxcnc.py"))
    proc = client("""
        import linuxcnc, halsdk.compat.linuxcnc as impl
        print(linuxcnc is impl, linuxcnc.error.__name__)
        """, dict(os.environ), tmp_path)
    assert proc.stdout.split() == ["True", "error"], proc.stderr


def test_constants_have_the_reference_values() -> None:
    for name, value in GOLDEN["constants"].items():
        assert getattr(linuxcnc, name) == value, name
        assert type(getattr(linuxcnc, name)) is int, name


def test_no_constant_of_our_own() -> None:
    ours = {n for n in public(linuxcnc) if n.isupper()
            and isinstance(getattr(linuxcnc, n), int)}
    assert ours == set(GOLDEN["constants"])


def test_the_module_has_the_reference_names_but_the_absent_ones() -> None:
    names = set(GOLDEN["constants"]) | set(GOLDEN["strings"]) | \
        set(GOLDEN["objects"])
    assert set(linuxcnc.__all__) == names - ABSENT
    for name in names - ABSENT:
        assert hasattr(linuxcnc, name), name
    for name in ABSENT:
        assert not hasattr(linuxcnc, name), name
    for name in GOLDEN["strings"]:
        assert isinstance(getattr(linuxcnc, name), str), name


def test_what_is_absent_is_documented() -> None:
    text = repo_path("docs", "compat.md").read_text()
    for name in ABSENT:
        assert f"`{name}`" in text, name


def test_error_is_a_runtime_error_and_a_hal_error() -> None:
    e = linuxcnc.error("boom")
    assert isinstance(e, RuntimeError) and isinstance(e, halsdk.HalError)
    assert str(e) == "boom" and e.args == ("boom",)


def test_version_and_nmlfile_are_strings() -> None:
    assert linuxcnc.version.startswith("2.9")
    assert linuxcnc.nmlfile.endswith(".nml")


# ---------------------------------------------------------------- stat

def test_stat_has_the_reference_attributes_before_a_poll() -> None:
    """Before its first poll a stat reads zeros with the reference's types
    and tuple lengths (what the reference gives with no poll)."""
    s = linuxcnc.stat()
    assert public(s) == sorted([*GOLDEN["stat"], *GOLDEN["stat_methods"]])
    for name, want in GOLDEN["stat"].items():
        assert kind(getattr(s, name)) == want, name
    assert s.task_state == 0 and s.tool_table == ()
    assert s.joint[3]["homed"] == 0 and s.spindle[0]["override"] == 0.0


def test_stat_attributes_are_read_only() -> None:
    s = linuxcnc.stat()
    with pytest.raises(AttributeError, match="readonly attribute"):
        s.task_state = 4            # type: ignore[misc]
    with pytest.raises(AttributeError):
        s.something_else = 1        # type: ignore[attr-defined]


def test_tool_result_is_the_reference_entry() -> None:
    assert sorted(linuxcnc.tool._fields) == GOLDEN["tool_result"]
    entry = linuxcnc.tool(-1, *([0.0] * 12), 0)
    assert entry.id == -1 and entry.orientation == 0
    assert repr(entry).startswith("tool_result(id=-1, xoffset=0.0")


def test_command_error_channel_ini_have_the_reference_methods() -> None:
    assert set(public(linuxcnc.command)) == \
        set(GOLDEN["command"]) | EXTRA_METHODS
    assert public(linuxcnc.error_channel) == GOLDEN["error_channel"]
    assert public(linuxcnc.ini) == GOLDEN["ini"]
    c = linuxcnc.command()
    assert c.serial == 0
    with pytest.raises(AttributeError, match="readonly attribute"):
        c.serial = 5                # type: ignore[misc]


# ------------------------------------------------------------ no machine

def test_without_a_machine_every_channel_says_so(tmp_path: Path) -> None:
    """No instance: creating stat and command works (as the reference),
    poll(), a command and error_channel() raise linuxcnc.error."""
    env = dict(os.environ, HALSDK_INSTANCE=f"nomachine-{os.getpid()}")
    proc = client("""
        import linuxcnc
        s = linuxcnc.stat()
        c = linuxcnc.command()
        for what in (s.poll, lambda: c.state(linuxcnc.STATE_ON),
                     c.wait_complete, linuxcnc.error_channel):
            try:
                what()
            except linuxcnc.error as e:
                print("error:", e)
        print("serial", c.serial, "task_state", s.task_state)
        """, env, tmp_path)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 5, proc.stdout
    for line in lines[:4]:
        assert line.startswith("error: no machine is running on HAL "
                               "instance 'nomachine-"), line
        assert "halsdk run" in line
    assert lines[4] == "serial 0 task_state 0"


def test_an_instance_without_a_task(hal: Any, tmp_path: Path) -> None:
    """An instance runs (this test hosts it) but no task: poll() says the
    instance has no task channel."""
    proc = client("""
        import linuxcnc
        try:
            linuxcnc.stat().poll()
        except linuxcnc.error as e:
            print(e)
        """, dict(os.environ), tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "has no task channel" in proc.stdout, proc.stdout


# ------------------------------------------------------ argument errors

C = linuxcnc.command()
L = linuxcnc

#: (call, exception, message) as the reference's C extension raises them
BAD_CALLS: list[tuple[str, Callable[[], Any], type, str]] = [
    ("state()", lambda: C.state(), TypeError,
     "function takes exactly 1 argument (0 given)"),
    ("state('a')", lambda: C.state("a"), TypeError,
     "'str' object cannot be interpreted as an integer"),
    ("state(9)", lambda: C.state(9), ValueError,
     "Machine state should be STATE_ESTOP, STATE_ESTOP_RESET, STATE_ON, "
     "or STATE_OFF"),
    ("mode(9)", lambda: C.mode(9), ValueError,
     "Mode should be MODE_MDI, MODE_MANUAL, or MODE_AUTO"),
    ("mode(None)", lambda: C.mode(None), TypeError,
     "'NoneType' object cannot be interpreted as an integer"),
    ("mode(2**40)", lambda: C.mode(2 ** 40), OverflowError,
     "signed integer is greater than maximum"),
    ("home(1.5)", lambda: C.home(1.5), TypeError,
     "'float' object cannot be interpreted as an integer"),
    ("abort(1)", lambda: C.abort(1), TypeError,
     "command.abort() takes no arguments (1 given)"),
    ("load_tool_table(1)", lambda: C.load_tool_table(1), TypeError,
     "command.load_tool_table() takes no arguments (1 given)"),
    ("mdi(5)", lambda: C.mdi(5), TypeError,
     "a bytes-like object is required, not 'int'"),
    ("mdi('x'*300)", lambda: C.mdi("x" * 300), ValueError,
     "MDI commands limited to 254 characters"),
    ("mdi('é'*200)", lambda: C.mdi("\u00e9" * 200), ValueError,
     "MDI commands limited to 254 characters"),
    ("mdi('G0', 1)", lambda: C.mdi("G0", 1), TypeError,
     "function takes exactly 1 argument (2 given)"),
    ("program_open(3)", lambda: C.program_open(3), TypeError,
     "a bytes-like object is required, not 'int'"),
    ("program_open('x'*300)", lambda: C.program_open("x" * 300), ValueError,
     "File name limited to 254 characters"),
    ("jog(1)", lambda: C.jog(1), TypeError,
     "function takes at least 3 arguments (1 given)"),
    ("jog(7, ...)", lambda: C.jog(7, True, 0), TypeError,
     "jog() first argument must be JOG_xxx"),
    ("jog(STOP, .., vel)", lambda: C.jog(L.JOG_STOP, True, 0, 1.0),
     TypeError, r"jog(JOG_STOP, ...) takes 3 arguments (4 given)"),
    ("jog(CONT, ..)", lambda: C.jog(L.JOG_CONTINUOUS, True, 0), TypeError,
     "jog(JOG_CONTINUOUS, ...) takes 4 arguments (3 given)"),
    ("jog(INCR, .., vel)", lambda: C.jog(L.JOG_INCREMENT, True, 0, 1.0),
     TypeError, "jog(JOG_INCREMENT, ...) takes 5 arguments (4 given)"),
    ("jog(STOP, 'x', 0)", lambda: C.jog(L.JOG_STOP, "x", 0), TypeError,
     "'str' object cannot be interpreted as an integer"),
    ("jog 6 args", lambda: C.jog(L.JOG_INCREMENT, True, 0, 1.0, 2.0, 3),
     TypeError, "function takes at most 5 arguments (6 given)"),
    ("spindle()", lambda: C.spindle(), TypeError,
     "function takes at least 1 argument (0 given)"),
    ("spindle(1, 'a')", lambda: C.spindle(1, "a"), TypeError,
     "must be real number, not str"),
    ("spindle 5 args", lambda: C.spindle(1, 100, 0, 0, 5), TypeError,
     "function takes at most 4 arguments (5 given)"),
    ("spindle(1, speed=)", lambda: C.spindle(1, speed=100), TypeError,
     "command.spindle() takes no keyword arguments"),
    ("spindle(7)", lambda: C.spindle(7), ValueError,
     "Spindle direction should be SPINDLE_FORWARD, SPINDLE_REVERSE, "
     "SPINDLE_OFF, SPINDLE_INCREASE, SPINDLE_DECREASE, or SPINDLE_CONSTANT"),
    ("brake(5)", lambda: C.brake(5), ValueError,
     "BRAKE should be BRAKE_ENGAGE or BRAKE_RELEASE"),
    ("flood(5)", lambda: C.flood(5), ValueError,
     "FLOOD should be FLOOD_ON or FLOOD_OFF"),
    ("mist(2)", lambda: C.mist(2), ValueError,
     "Mist should be MIST_ON or MIST_OFF"),
    ("auto()", lambda: C.auto(), TypeError,
     "function takes exactly 1 argument (0 given)"),
    ("auto(0, 'a')", lambda: C.auto(0, "a"), TypeError,
     "function takes exactly 1 argument (2 given)"),
    ("auto(PAUSE, 3)", lambda: C.auto(L.AUTO_PAUSE, 3), TypeError,
     "function takes exactly 1 argument (2 given)"),
    ("auto(9)", lambda: C.auto(9), linuxcnc.error,
     "Unexpected argument '9' to command.auto"),
    ("feedrate('x')", lambda: C.feedrate("x"), TypeError,
     "must be real number, not str"),
    ("feedrate(2**2000)", lambda: C.feedrate(2 ** 2000), OverflowError,
     "int too large to convert to float"),
    ("spindleoverride 3 args", lambda: C.spindleoverride(1.0, 0, 3),
     TypeError, "function takes at most 2 arguments (3 given)"),
    ("set_min_limit(0)", lambda: C.set_min_limit(0), TypeError,
     "function takes exactly 2 arguments (1 given)"),
    ("set_analog_output(1, 'a')", lambda: C.set_analog_output(1, "a"),
     TypeError, "must be real number, not str"),
    ("tool_offset 3 args", lambda: C.tool_offset(1, 2, 3), TypeError,
     "function takes exactly 7 arguments (3 given)"),
    ("tool_offset(.., 7.5)", lambda: C.tool_offset(1, 2.0, 3.0, 4.0, 5.0,
                                                   6.0, 7.5),
     TypeError, "'float' object cannot be interpreted as an integer"),
    ("text_msg(5)", lambda: C.text_msg(5), TypeError,
     "argument 1 must be str, not int"),
    ("wait_complete('a')", lambda: C.wait_complete("a"), TypeError,
     "must be real number, not str"),
    ("wait_complete(None)", lambda: C.wait_complete(None), TypeError,
     "must be real number, not NoneType"),
    ("wait_complete(1, 2)", lambda: C.wait_complete(1, 2), TypeError,
     "emc.command.wait_complete() takes at most 1 argument (2 given)"),
    ("wait_complete(timeout=)", lambda: C.wait_complete(timeout=1),
     TypeError, "command.wait_complete() takes no keyword arguments"),
]


@pytest.mark.parametrize("call, exc, message",
                         [case[1:] for case in BAD_CALLS],
                         ids=[case[0] for case in BAD_CALLS])
def test_bad_arguments_are_refused_as_the_reference_does(
        call: Callable[[], Any], exc: type, message: str) -> None:
    """Checked before anything is sent (no machine runs here)."""
    with pytest.raises(exc) as info:
        call()
    assert str(info.value) == message
    assert C.serial == 0


# ---------------------------------------------------------------- ini

INI = """\
# a comment
[EMC]
MACHINE = my mill<BLANKS>
EMPTY =
INLINE = x # not a comment ; nor this
[FILTER]
PROGRAM_EXTENSION = .png,.gif Greyscale Depth Image
PROGRAM_EXTENSION = .py Python Script
[DUP]
A = 1
[DUP]
A = 2
B = only in the second
[HALUI]
MDI_COMMAND = G0 \\
  X1 \\
Y2
""".replace("<BLANKS>", "   ")                # blanks after the value


@pytest.fixture
def inifile(tmp_path: Path) -> linuxcnc.ini:
    path = tmp_path / "t.ini"
    path.write_text(INI)
    return linuxcnc.ini(str(path))


@pytest.mark.parametrize("section, key, first, every", [
    ("EMC", "MACHINE", "my mill", ["my mill"]),
    ("EMC", "NOPE", None, []),
    ("NOPE", "X", None, []),
    ("emc", "machine", None, []),                   # case sensitive
    ("EMC", "EMPTY", None, []),                     # empty: absent
    ("EMC", "INLINE", "x # not a comment ; nor this",
     ["x # not a comment ; nor this"]),
    ("FILTER", "PROGRAM_EXTENSION", ".png,.gif Greyscale Depth Image",
     [".png,.gif Greyscale Depth Image", ".py Python Script"]),
    ("DUP", "A", "1", ["1"]),                       # the first [DUP] only
    ("DUP", "B", None, []),
    ("HALUI", "MDI_COMMAND", "G0 X1 Y2", ["G0 X1 Y2"]),   # continued
])
def test_ini_finds_as_the_reference(inifile: linuxcnc.ini, section: str,
                                    key: str, first: Any,
                                    every: list[str]) -> None:
    assert inifile.find(section, key) == first
    assert inifile.findall(section, key) == every


def test_ini_find_nth(inifile: linuxcnc.ini) -> None:
    key = ("FILTER", "PROGRAM_EXTENSION")
    assert inifile.find(*key, 2) == ".py Python Script"
    assert inifile.find(*key, 3) is None
    assert inifile.find(*key, 0) == inifile.find(*key, -1) == \
        ".png,.gif Greyscale Depth Image"


def test_ini_argument_errors(inifile: linuxcnc.ini, tmp_path: Path) -> None:
    with pytest.raises(TypeError, match=r"find\(\) takes at least 2"):
        inifile.find("EMC")
    with pytest.raises(TypeError,
                       match=r"find\(\) argument 1 must be str, not int"):
        inifile.find(1, 2)
    with pytest.raises(TypeError, match=r"findall\(\) takes exactly 2"):
        inifile.findall("EMC", "MACHINE", 1)
    with pytest.raises(TypeError, match="no keyword arguments"):
        inifile.find(section="EMC", option="MACHINE")
    with pytest.raises(TypeError, match="argument 1 must be str, not int"):
        linuxcnc.ini(5)
    with pytest.raises(TypeError, match="exactly 1 argument"):
        linuxcnc.ini()
    with pytest.raises(linuxcnc.error, match="inifile.open.. failed"):
        linuxcnc.ini(str(tmp_path / "missing.ini"))


# ------------------------------------------------------- a machine gone

def test_the_machine_gone_is_an_error_not_a_hang(tmp_path: Path) -> None:
    """A client polls a running machine; the machine stops; the next
    poll, command and error poll raise linuxcnc.error."""
    code = """
        import sys, time, linuxcnc
        s = linuxcnc.stat(); c = linuxcnc.command()
        e = linuxcnc.error_channel()
        s.poll()
        c.text_msg("hello")
        print("polled", s.task_state, c.wait_complete(), flush=True)
        sys.stdin.readline()            # the machine stops meanwhile
        for what in (s.poll, lambda: c.text_msg("again"), e.poll, e.poll):
            try:
                print("got", what())
            except linuxcnc.error as exc:
                print("error:", exc)
        """
    folder = tmp_path / "machine"
    folder.mkdir()
    with running_machine(folder) as machine:
        env = dict(machine.env)
        env["PYTHONPATH"] = os.pathsep.join(
            [env["PYTHONPATH"], str(Path(halsdk.__file__).parents[1])])
        proc = subprocess.Popen(
            [sys.executable, "-c", textwrap.dedent(code)], env=env,
            cwd=str(tmp_path), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True)
        assert proc.stdout is not None and proc.stdin is not None
        first = proc.stdout.readline()
        assert first == "polled 1 1\n", first + proc.stderr.read()
        machine.stop()
    out, err = proc.communicate("go\n", timeout=60)
    lines = out.splitlines()
    assert len(lines) == 4, out + err
    assert lines[0].startswith("error: the machine is gone"), lines
    assert lines[1].startswith("error: the machine is gone"), lines
    # the error channel gives what was posted, then says it is gone
    assert lines[2] == "got (12, 'hello')", lines
    assert lines[3].startswith("error: the machine is gone"), lines
