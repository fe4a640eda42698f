"""Tests of halsdk.compat.hal, LinuxCNC's Python ``hal`` module on halsdk.

The expected values, messages and exception types are those the LinuxCNC
2.9 module shows (checked on the reference); the few places where halsdk
deliberately differs say so.  The second half runs userspace components
written exactly as for LinuxCNC (``tests/data/compat/*.py``, ``import
hal``) unchanged in child processes attached to the test's instance, drives
their pins from the test and unloads them with SIGTERM.
"""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import sys
import tempfile
import threading
import time
from typing import Any, Callable, Optional

import pytest
from helpers import data_path

import halsdk
import halsdk.compat
from halsdk.compat import hal as compat
from halsdk.core import _core

DATA = data_path("compat")
TIMEOUT = 10.0          # seconds to wait for anything a child should do


# ---------------------------------------------------------------- helpers

def wait_until(predicate: Callable[[], Any], what: str,
               timeout: float = TIMEOUT) -> Any:
    """Poll ``predicate`` until it is truthy; AssertionError on timeout."""
    deadline = time.monotonic() + timeout
    while True:
        result = predicate()
        if result:
            return result
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:g} s waiting "
                                 f"for {what}")
        time.sleep(0.005)


def compat_env(**extra: str) -> dict[str, str]:
    """The test's environment with ``import hal`` resolving to the compat
    module (HALSDK_INSTANCE is the test's private instance)."""
    env = dict(os.environ)
    # the halsdk this test imported (installed, or the built source tree)
    parts = [halsdk.compat.pythonpath(),
             os.path.dirname(os.path.dirname(halsdk.__file__))]
    if env.get("PYTHONPATH"):
        parts.append(env["PYTHONPATH"])
    env["PYTHONPATH"] = os.pathsep.join(parts)
    env.update(extra)
    return env


class Child:
    """A child Python process; stdout lines are read with a deadline."""

    def __init__(self, args: list[str], env: dict[str, str]):
        self.proc = subprocess.Popen(
            [sys.executable, *args], env=env, stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self._lines: queue.Queue[Optional[str]] = queue.Queue()
        self._stderr: list[str] = []
        threading.Thread(target=self._pump_out, daemon=True).start()
        threading.Thread(target=self._pump_err, daemon=True).start()

    def _pump_out(self) -> None:
        for line in self.proc.stdout:
            self._lines.put(line.rstrip("\n"))
        self._lines.put(None)

    def _pump_err(self) -> None:
        for line in self.proc.stderr:
            self._stderr.append(line)

    @property
    def stderr(self) -> str:
        return "".join(self._stderr)

    def readline(self, timeout: float = TIMEOUT) -> str:
        try:
            line = self._lines.get(timeout=timeout)
        except queue.Empty:
            raise AssertionError(f"no output from child within {timeout:g} "
                                 f"s\n{self.stderr}") from None
        if line is None:
            raise AssertionError(f"child ended (rc {self.proc.poll()}) "
                                 f"without output\n{self.stderr}")
        return line

    def wait(self, timeout: float = TIMEOUT) -> int:
        try:
            return self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"child {self.proc.pid} did not exit within "
                                 f"{timeout:g} s\n{self.stderr}") from None

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        try:
            self.proc.wait(TIMEOUT)
        except subprocess.TimeoutExpired:
            pass


@pytest.fixture
def children():
    """Start children; every one is killed and awaited when the test ends."""
    started: list[Child] = []

    def start(script: str, *args: str, env: Optional[dict] = None) -> Child:
        child = Child([str(DATA / script), *args], env or compat_env())
        started.append(child)
        return child

    yield start
    for child in started:
        child.kill()


def wait_ready(name: str, child: Child) -> None:
    """Wait until the child's component ``name`` is ready in the host."""
    def ready() -> bool:
        if child.proc.poll() is not None:
            raise AssertionError(f"component '{name}' exited early (rc "
                                 f"{child.proc.returncode})\n{child.stderr}")
        comp = _core.find("component", name)
        return comp is not None and comp.ready
    wait_until(ready, f"component '{name}' to become ready")


def unload_and_check(hal_fixture: halsdk.Hal, name: str, child: Child) -> None:
    """``unload`` (SIGTERM): the child exits 0 and its component is gone."""
    pin_prefix = name + "."
    hal_fixture.unload(name, timeout=TIMEOUT)
    assert child.wait() == 0, child.stderr
    assert _core.find("component", name) is None
    assert not [p for p in hal_fixture.pins() if p.name.startswith(pin_prefix)]
    assert "Traceback" not in child.stderr, child.stderr


@pytest.fixture
def sigterm_guard():
    """Restore the test process's SIGTERM handler afterwards (creating a
    compat component installs one)."""
    old = signal.getsignal(signal.SIGTERM)
    yield
    signal.signal(signal.SIGTERM, old)


@pytest.fixture
def comp(hal, sigterm_guard):
    """A compat component 'cmp' in the test process (prefix 'cmp')."""
    c = compat.component("cmp")
    yield c
    if not c._c_state.closed:
        c.exit()


# ---------------------------------------------------------------- module

def test_constants_have_the_reference_values():
    assert (compat.HAL_BIT, compat.HAL_FLOAT, compat.HAL_S32, compat.HAL_U32) == \
        (1, 2, 3, 4)
    assert (compat.HAL_S64, compat.HAL_U64) == (6, 7)
    assert (compat.HAL_IN, compat.HAL_OUT, compat.HAL_IO) == (16, 32, 48)
    assert (compat.HAL_RO, compat.HAL_RW) == (64, 192)
    assert [compat.MSG_NONE, compat.MSG_ERR, compat.MSG_WARN, compat.MSG_INFO,
            compat.MSG_DBG, compat.MSG_ALL] == [0, 1, 2, 3, 4, 5]
    assert (compat.is_kernelspace, compat.is_rt, compat.is_sim, compat.is_userspace) \
        == (0, 0, 1, 1)
    assert compat.kernel_version == "Not Available"
    # halsdk's own numbers agree
    assert (compat.HAL_S64, compat.HAL_U64) == (halsdk.S64, halsdk.U64)
    assert compat.HAL_RW == halsdk.RW


def test_error_is_a_halsdk_error():
    assert issubclass(compat.error, halsdk.HalError)
    assert issubclass(compat.error, Exception)
    assert not issubclass(compat.error, (ValueError, RuntimeError))


def test_pythonpath_makes_import_hal_the_compat_module():
    folder = halsdk.compat.pythonpath()
    assert os.path.isfile(os.path.join(folder, "hal.py"))
    out = subprocess.run(
        [sys.executable, "-c",
         "import hal, halsdk.compat.hal as m; print(hal is m, hal.HAL_RW, "
         "hal.error.__module__)"],
        env=compat_env(), capture_output=True, text=True, timeout=60,
        cwd=tempfile.gettempdir())
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "192", "halsdk.compat.hal"]


def test_module_functions_need_a_component_or_instance():
    """As in LinuxCNC, module functions before any component raise
    RuntimeError (here: while the process is attached to no instance)."""
    script = (
        "import json, hal\n"
        "out = []\n"
        "for f, a in [(hal.component_exists, ('x',)),\n"
        "             (hal.get_value, ('x',)), (hal.get_info_pins, ()),\n"
        "             (hal.new_sig, ('s', hal.HAL_BIT))]:\n"
        "    try:\n"
        "        f(*a)\n"
        "        out.append('no error')\n"
        "    except RuntimeError as e:\n"
        "        out.append(str(e))\n"
        "out.append(hal.get_msg_level())\n"
        "print(json.dumps(out))\n")
    env = compat_env()
    env.pop("HALSDK_INSTANCE", None)
    res = subprocess.run([sys.executable, "-c", script], env=env,
                         capture_output=True, text=True, timeout=60,
                         cwd=tempfile.gettempdir())
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout) == \
        ["Cannot call before creating component"] * 4 + [compat.MSG_ERR]


# ---------------------------------------------------------------- component

def test_component_pins_and_params(hal, comp):
    assert repr(comp) == \
        f"<hal component cmp({hal.component('cmp').id}) with 0 pins and params>"
    assert comp.getprefix() == "cmp"
    pin = comp.newpin("in", compat.HAL_FLOAT, compat.HAL_IN)
    assert isinstance(pin, compat.Pin)
    assert (pin.name, pin.type, pin.dir) == ("in", 2, 16)
    assert (pin.get_name(), pin.get_type(), pin.get_dir(), pin.is_pin()) == \
        ("in", 2, 16, True)
    param = comp.newparam("gain", compat.HAL_S32, compat.HAL_RW)
    assert isinstance(param, compat.Param)
    assert (param.name, param.type, param.dir, param.is_pin()) == \
        ("gain", 3, 192, False)
    assert len(comp) == 2
    assert repr(comp).endswith("with 2 pins and params>")
    # the host sees them under the prefix
    assert hal.pin("cmp.in").direction == halsdk.IN
    assert hal.param("cmp.gain").type == halsdk.S32
    assert comp["in"] == 0.0 and comp["gain"] == 0
    assert type(comp["gain"]) is int and type(comp["in"]) is float


def test_component_with_prefix(hal, sigterm_guard):
    c = compat.component("named", "pre")
    try:
        c.newpin("x", compat.HAL_BIT, compat.HAL_OUT)
        assert c.getprefix() == "pre"
        assert hal.pin("pre.x").owner == "named"
        assert compat.component_exists("named")
        assert not compat.component_exists("pre")
        # halsdk honours prefix= as a keyword as well
        k = compat.component("kw", prefix="kwp")
        k.newpin("y", compat.HAL_BIT, compat.HAL_IN)
        assert hal.pin("kwp.y").owner == "kw"
        k.exit()
    finally:
        c.exit()


def test_setprefix_applies_to_later_pins(hal, comp):
    comp.newpin("a", compat.HAL_S32, compat.HAL_IN)
    comp.setprefix("other")
    assert comp.getprefix() == "other"
    comp.newpin("b", compat.HAL_S32, compat.HAL_IN)
    assert [p.name for p in hal.pins("*")] == ["cmp.a", "other.b"]
    comp["b"] = 7                   # items are keyed by their short name
    assert compat.get_value("other.b") == 7
    with pytest.raises(AttributeError, match="Pin 'other.b' does not exist"):
        comp["other.b"]
    with pytest.raises(TypeError):
        comp.setprefix(3)


def test_ready_unready(hal, comp):
    m = compat
    comp.newpin("a", m.HAL_BIT, m.HAL_IN)
    assert m.component_exists("cmp") and not m.component_is_ready("cmp")
    with pytest.raises(m.error, match="already unready"):
        comp.unready()
    comp.ready()
    assert m.component_is_ready("cmp") and hal.component("cmp").ready
    with pytest.raises(m.error, match="already ready"):
        comp.ready()
    with pytest.raises(m.error):
        comp.newpin("late", m.HAL_BIT, m.HAL_IN)
    assert _core.find("pin", "cmp.late") is None
    comp.unready()
    assert not m.component_is_ready("cmp")
    comp.newpin("late", m.HAL_BIT, m.HAL_IN)       # allowed again
    comp.ready()
    assert hal.pin("cmp.late").owner == "cmp"
    assert not m.component_is_ready("nope")
    assert not m.component_exists("nope")


def test_item_access_by_key_and_attribute(hal, comp):
    m = compat
    comp.newpin("f", m.HAL_FLOAT, m.HAL_OUT)
    comp.newpin("in", m.HAL_U32, m.HAL_IN)
    comp.newpin("ready", m.HAL_BIT, m.HAL_IN)
    comp["f"] = 2.5
    assert comp.f == 2.5 and hal.getp("cmp.f") == 2.5
    comp.f = 4
    assert comp["f"] == 4.0 and hal.getp("cmp.f") == 4.0
    assert getattr(comp, "in") == 0          # a keyword, as getattr
    setattr(comp, "in", 9)
    assert hal.getp("cmp.in") == 9
    # methods win over pins of the same name
    assert callable(comp.ready)
    assert comp["ready"] is False
    for bad in (lambda: comp["nope"], lambda: comp.nope):
        with pytest.raises(AttributeError, match="Pin 'nope' does not exist"):
            bad()
    with pytest.raises(AttributeError, match="Pin 'zzz' does not exist"):
        comp.zzz = 1
    with pytest.raises(AttributeError, match="Pin 'nope' does not exist"):
        comp["nope"] = 1
    with pytest.raises(TypeError, match="bad argument type"):
        comp[3]
    with pytest.raises(TypeError):
        del comp["f"]
    with pytest.raises(AttributeError):
        del comp.f
    assert comp.getpins() == {"f": 4.0, "in": 9, "ready": False}
    assert list(comp.getpins()) == ["f", "in", "ready"]


def test_owner_writes_any_direction_and_linked_pins(hal, comp):
    m = compat
    comp.newpin("i", m.HAL_S32, m.HAL_IN)
    comp.newparam("ro", m.HAL_FLOAT, m.HAL_RO)
    comp["i"] = -4
    comp["ro"] = 1.25
    assert hal.getp("cmp.i") == -4 and hal.getp("cmp.ro") == 1.25
    hal.newsig("s", "s32")
    hal.linkps("cmp.i", "s")
    hal.sets("s", 11)
    assert comp["i"] == 11
    comp["i"] = 12                  # writes through to the signal
    assert hal.gets("s") == 12


_S64_MAX = (1 << 63) - 1

CONVERSIONS = [
    # (type, value, expected value or exception type, message part)
    ("BIT", 1, True, None), ("BIT", 2, True, None), ("BIT", -1, True, None),
    ("BIT", 0.5, True, None), ("BIT", "0", True, None), ("BIT", "", False,
                                                          None),
    ("BIT", None, False, None), ("BIT", [], False, None),
    ("FLOAT", 1, 1.0, None), ("FLOAT", "3", 3.0, None),
    ("FLOAT", "1e3", 1000.0, None), ("FLOAT", True, 1.0, None),
    ("FLOAT", None, TypeError, "Number expected, not NoneType"),
    ("FLOAT", "abc", TypeError, "Number expected, not str"),
    ("FLOAT", 10 ** 400, OverflowError, "too large"),
    ("S32", 2.7, 2, None), ("S32", -2.7, -2, None), ("S32", " 7 ", 7, None),
    ("S32", True, 1, None), ("S32", -(1 << 31), -(1 << 31), None),
    ("S32", (1 << 31) - 1, (1 << 31) - 1, None),
    ("S32", 1 << 31, OverflowError, "Value 2147483648 out of range"),
    ("S32", -(1 << 31) - 1, OverflowError, "Value -2147483649 out of range"),
    ("S32", _S64_MAX, OverflowError, f"Value {_S64_MAX} out of range"),
    ("S32", 1 << 63, OverflowError, "int too big to convert"),
    ("S32", 1e20, OverflowError, "int too big to convert"),
    ("S32", "abc", ValueError, "invalid literal"),
    ("S32", "0x10", ValueError, "invalid literal"),
    ("S32", None, TypeError, "NoneType"),
    ("S32", float("nan"), ValueError, "NaN"),
    ("S32", float("inf"), OverflowError, "infinity"),
    ("U32", 3.9, 3, None), ("U32", "9", 9, None),
    ("U32", (1 << 32) - 1, (1 << 32) - 1, None),
    ("U32", -1, OverflowError, "Value -1 out of range"),
    ("U32", -3.9, OverflowError, "Value -3 out of range"),
    ("U32", 1 << 32, OverflowError, "Value 4294967296 out of range"),
    ("U32", (1 << 64) - 1, OverflowError, "int too big to convert"),
    # halsdk's 64-bit types
    ("S64", _S64_MAX, _S64_MAX, None), ("S64", -_S64_MAX - 1, -_S64_MAX - 1,
                                        None),
    ("S64", 1 << 63, OverflowError, "int too big to convert"),
    ("U64", (1 << 64) - 1, (1 << 64) - 1, None),
    ("U64", -1, OverflowError, "Value -1 out of range"),
    ("U64", 1 << 64, OverflowError, "int too big to convert"),
]


@pytest.mark.parametrize("tname,value,expected,message", CONVERSIONS)
def test_value_conversion(hal, comp, tname, value, expected, message):
    m = compat
    comp.newpin("p", getattr(m, "HAL_" + tname), m.HAL_IO)
    item = comp.getitem("p")
    comp["p"] = {"BIT": True, "FLOAT": 0.5}.get(tname, 5)
    before = comp["p"]
    if isinstance(expected, type) and issubclass(expected, BaseException):
        with pytest.raises(expected, match=message):
            comp["p"] = value
        with pytest.raises(expected, match=message):
            item.set(value)
        assert comp["p"] == before          # unchanged
        return
    comp["p"] = value
    assert comp["p"] == expected and type(comp["p"]) is type(expected)
    assert hal.getp("cmp.p") == expected
    comp["p"] = before
    item.set(value)
    assert item.get() == expected


def test_newpin_errors(hal, comp):
    m = compat
    comp.newpin("a", m.HAL_BIT, m.HAL_IN)
    comp.newparam("p", m.HAL_BIT, m.HAL_RW)
    with pytest.raises(ValueError, match="Duplicate pin name 'a'"):
        comp.newpin("a", m.HAL_FLOAT, m.HAL_OUT)
    with pytest.raises(ValueError, match="Duplicate pin name 'p'"):
        comp.newpin("p", m.HAL_FLOAT, m.HAL_OUT)
    with pytest.raises(ValueError, match="Duplicate parameter name 'a'"):
        comp.newparam("a", m.HAL_FLOAT, m.HAL_RW)
    for bad_type in (0, 5, 99):
        with pytest.raises(m.error, match=f"Invalid pin type {bad_type}"):
            comp.newpin("t", bad_type, m.HAL_IN)
    with pytest.raises(m.error, match="Invalid param type 99"):
        comp.newparam("t", 99, m.HAL_RW)
    for bad_dir in (99, m.HAL_RW, m.HAL_RO):
        with pytest.raises(m.error, match="direction"):
            comp.newpin("d", m.HAL_BIT, bad_dir)
    with pytest.raises(m.error, match="direction"):
        comp.newparam("d", m.HAL_BIT, m.HAL_IN)
    with pytest.raises(TypeError, match="cannot be interpreted as an integer"):
        comp.newpin("s", "bit", m.HAL_IN)
    with pytest.raises(TypeError, match="must be str, not int"):
        comp.newpin(5, m.HAL_BIT, m.HAL_IN)
    with pytest.raises(TypeError):
        comp.newpin(name="kw", htype=m.HAL_BIT, hdir=m.HAL_IN)
    # names halsdk refuses are a hal.error (LinuxCNC accepts blanks)
    with pytest.raises(m.error, match="cmp.a b"):
        comp.newpin("a b", m.HAL_BIT, m.HAL_IN)
    with pytest.raises(halsdk.HalError):    # catchable as a HalError too
        comp.newpin("x" * 200, m.HAL_BIT, m.HAL_IN)
    assert len(comp) == 2
    assert sorted(p.name for p in hal.pins()) == ["cmp.a"]


def test_component_errors(hal, comp):
    m = compat
    with pytest.raises(m.error):
        m.component("cmp")                  # the name is taken
    with pytest.raises(TypeError, match="must be str, not int"):
        m.component(5)
    with pytest.raises(TypeError):
        m.component()
    with pytest.raises(m.error):
        m.component("c" * 200)
    assert [c.name for c in hal.components()] == ["cmp"]
    # a pin name taken by another component is a hal.error
    comp.newpin("a", m.HAL_BIT, m.HAL_IN)
    other = m.component("other", "cmp")
    try:
        with pytest.raises(m.error, match="cmp.a"):
            other.newpin("a", m.HAL_BIT, m.HAL_IN)
        assert len(other) == 0 and hal.pin("cmp.a").owner == "cmp"
    finally:
        other.exit()


def test_pin_param_and_item_objects(hal, comp):
    m = compat
    comp.newpin("u", m.HAL_U32, m.HAL_OUT)
    comp.newparam("pr", m.HAL_FLOAT, m.HAL_RO)
    comp.newpin("io", m.HAL_S32, m.HAL_IO)
    comp.newparam("rw", m.HAL_BIT, m.HAL_RW)
    it = comp.getitem("u")
    assert isinstance(it, m.item)
    assert repr(it) == '<hal pin "u" U32-OUT>'
    assert repr(comp.getitem("pr")) == '<hal param "pr" FLOAT-RO>'
    assert repr(comp.getitem("io")) == '<hal pin "io" S32-IO>'
    assert repr(comp.getitem("rw")) == '<hal param "rw" BIT-RW>'
    pin = comp.getpin("u")
    pin.set(11)
    assert pin.get() == 11 and pin.value == 11 and comp["u"] == 11
    pin.value = 12
    assert hal.getp("cmp.u") == 12
    with pytest.raises(OverflowError, match="Value -1 out of range"):
        pin.set(-1)
    param = comp.getparam("pr")
    param.value = 4.5                       # the owner writes RO params
    assert (param.get(), param.type, param.dir, param.is_pin()) == \
        (4.5, 2, 64, False)
    assert hal.getp("cmp.pr") == 4.5
    with pytest.raises(TypeError, match="Must be constructed from pin"):
        comp.getpin("pr")
    with pytest.raises(TypeError, match="Must be constructed from param"):
        comp.getparam("u")
    with pytest.raises(TypeError, match="Must be constructed from pin"):
        m.Pin(comp.getitem("pr"))
    with pytest.raises(TypeError, match="Constructor argument must be"):
        m.Pin(3)
    with pytest.raises(TypeError):
        m.item()
    with pytest.raises(AttributeError, match="Pin 'nope' does not exist"):
        comp.getitem("nope")
    with pytest.raises(AttributeError, match="Pin 'nope' does not exist"):
        comp.getpin("nope")
    with pytest.raises(TypeError, match="must be str"):
        comp.getitem(3)
    assert m.Pin(it).name == "u"


def test_exit_closes_the_component(hal, comp):
    m = compat
    pin = comp.newpin("a", m.HAL_S32, m.HAL_IN)
    it = comp.getitem("a")
    comp.ready()
    comp.exit()
    assert _core.find("component", "cmp") is None
    assert _core.find("pin", "cmp.a") is None
    assert repr(comp) == "<hal component cmp (closed)>"
    closed = "Invalid operation on closed HAL component"
    for op in (lambda: comp["a"], lambda: comp.__setitem__("a", 1),
               lambda: comp.a, lambda: comp.newpin("b", m.HAL_BIT, m.HAL_IN),
               comp.ready, comp.unready, comp.exit, comp.getpins,
               lambda: len(comp), it.get, lambda: it.set(1),
               lambda: pin.value):
        with pytest.raises(RuntimeError, match=closed):
            op()
    # the name can be used again
    again = m.component("cmp")
    again.exit()


def test_unload_from_the_host_closes_items(hal, comp):
    m = compat
    pin = comp.newpin("a", m.HAL_S32, m.HAL_IN)
    comp.ready()
    hal.unload("cmp")               # same process: removed directly
    assert not m.component_exists("cmp")
    with pytest.raises(RuntimeError, match="closed HAL component"):
        pin.get()
    with pytest.raises(RuntimeError, match="closed HAL component"):
        comp["a"] = 3
    for op in (comp.ready, comp.unready,
               lambda: comp.newpin("b", m.HAL_BIT, m.HAL_IN)):
        with pytest.raises(RuntimeError, match="closed HAL component"):
            op()
    comp.exit()                     # still allowed: releases the instance
    assert repr(comp) == "<hal component cmp (closed)>"


def test_dropping_the_component_removes_it(hal, sigterm_guard):
    m = compat
    m.component("temp").newpin("x", m.HAL_BIT, m.HAL_IN)
    assert _core.find("component", "temp") is None
    assert _core.find("pin", "temp.x") is None


# ---------------------------------------------------------------- functions

def test_signals_connect_disconnect(hal, comp, capsys):
    m = compat
    comp.newpin("o", m.HAL_FLOAT, m.HAL_OUT)
    comp.newpin("i", m.HAL_FLOAT, m.HAL_IN)
    comp.newpin("b", m.HAL_BIT, m.HAL_IN)
    comp.newpin("io", m.HAL_S32, m.HAL_IO)
    comp.ready()
    # False means success, True failure, as in LinuxCNC
    assert m.new_sig("sf", m.HAL_FLOAT) is False
    assert m.new_sig("sb", True) is False          # HAL_BIT == 1
    assert m.new_sig("s64", m.HAL_S64) is False
    assert hal.stype("s64") == "s64"
    assert m.new_sig("sf", m.HAL_FLOAT) is True
    assert "HAL: ERROR:" in capsys.readouterr().err
    with pytest.raises(RuntimeError, match="not a valid HAL signal type"):
        m.new_sig("sx", 99)
    with pytest.raises(TypeError):
        m.new_sig("sx", "float")
    with pytest.raises(TypeError):
        m.new_sig("sx", 2.0)
    assert _core.find("signal", "sx") is None

    assert not m.pin_has_writer("cmp.i")
    assert m.connect("cmp.i", "sf") is False
    assert m.connect("cmp.i", "sf") is False       # already there: fine
    assert not m.pin_has_writer("cmp.i")            # linked, no writer
    assert m.connect("cmp.o", "sf") is False
    assert m.pin_has_writer("cmp.i") and m.pin_has_writer("cmp.o")
    comp["o"] = 3.5
    assert comp["i"] == 3.5 and m.get_value("sf") == 3.5
    capsys.readouterr()
    assert m.connect("cmp.b", "sf") is True        # type mismatch
    assert m.connect("nope", "sf") is True
    assert m.connect("cmp.b", "nosig") is True
    assert m.connect("cmp.i", "sb") is True        # linked elsewhere
    err = capsys.readouterr().err
    assert err.count("HAL: ERROR:") == 4 and "nosig" in err
    assert hal.pin("cmp.b").signal is None
    with pytest.raises(NameError, match="Pin `nope' does not exist"):
        m.pin_has_writer("nope")
    with pytest.raises(TypeError, match="must be str"):
        m.connect("cmp.i", 3)

    # two io pins: no writer (only an out pin counts)
    m.new_sig("sio", m.HAL_S32)
    m.connect("cmp.io", "sio")
    assert not m.pin_has_writer("cmp.io")

    assert m.disconnect("cmp.i") is False
    assert comp["i"] == 3.5                         # keeps the last value
    assert hal.pin("cmp.i").signal is None
    assert m.disconnect("cmp.i") is False           # unlinked: no-op
    assert m.disconnect("nope") is True


def test_set_p_and_get_value(hal, comp):
    m = compat
    comp.newpin("u", m.HAL_U32, m.HAL_IN)
    comp.newpin("f", m.HAL_FLOAT, m.HAL_IN)
    comp.newpin("b", m.HAL_BIT, m.HAL_IN)
    comp.newpin("o", m.HAL_S32, m.HAL_OUT)
    comp.newparam("pw", m.HAL_U32, m.HAL_RW)
    comp.newparam("pb", m.HAL_BIT, m.HAL_RW)
    comp.newparam("pr", m.HAL_FLOAT, m.HAL_RO)
    comp.ready()
    assert m.set_p("cmp.u", "33") is False and comp["u"] == 33
    assert m.set_p("cmp.u", "0x10") is False and comp["u"] == 16
    assert m.set_p("cmp.f", "2.25") is False and comp["f"] == 2.25
    assert m.set_p("cmp.b", "TRUE") is False and comp["b"] is True
    assert m.set_p("cmp.b", "0") is False and comp["b"] is False
    assert m.set_p("cmp.pw", "17") is False and comp["pw"] == 17
    assert m.set_p("cmp.pb", "1") is False and comp["pb"] is True
    # a bad value string: True, value unchanged
    assert m.set_p("cmp.f", "abc") is True and comp["f"] == 2.25
    assert m.set_p("cmp.u", "abc") is True and comp["u"] == 16
    assert m.set_p("cmp.b", "2") is True and comp["b"] is False
    assert m.set_p("cmp.u", "99999999999") is True and comp["u"] == 16
    with pytest.raises(RuntimeError, match="pin not writable"):
        m.set_p("cmp.o", "1")
    with pytest.raises(RuntimeError, match="param not writable"):
        m.set_p("cmp.pr", "1")
    with pytest.raises(RuntimeError, match="pin not found"):
        m.set_p("nope", "1")
    with pytest.raises(TypeError, match="argument 2 must be str, not int"):
        m.set_p("cmp.u", 1)
    m.new_sig("sb", m.HAL_BIT)
    m.connect("cmp.b", "sb")
    with pytest.raises(RuntimeError, match="pin connected to signal"):
        m.set_p("cmp.b", "1")
    with pytest.raises(RuntimeError, match="pin not found"):
        m.set_p("sb", "1")                          # a signal is no pin

    hal.sets("sb", 1)
    assert m.get_value("cmp.b") is True and m.get_value("sb") is True
    assert m.get_value("cmp.pw") == 17 and m.get_value("cmp.pr") == 0.0
    with pytest.raises(RuntimeError, match="pin / param nope not found"):
        m.get_value("nope")


def test_get_info(hal, comp):
    m = compat
    comp.newpin("z", m.HAL_BIT, m.HAL_OUT)
    comp.newpin("a", m.HAL_FLOAT, m.HAL_IN)
    comp.newparam("p", m.HAL_U32, m.HAL_RW)
    comp.newparam("c", m.HAL_S32, m.HAL_RO)
    comp.ready()
    comp["z"] = 1
    comp["p"] = 9
    m.new_sig("sz", m.HAL_BIT)
    m.new_sig("free", m.HAL_FLOAT)
    m.connect("cmp.z", "sz")
    assert m.get_info_pins() == [
        {"NAME": "cmp.a", "VALUE": 0.0, "DIRECTION": 16, "TYPE": 2},
        {"NAME": "cmp.z", "VALUE": True, "DIRECTION": 32, "TYPE": 1}]
    assert m.get_info_params() == [
        {"NAME": "cmp.c", "DIRECTION": 64, "VALUE": 0},
        {"NAME": "cmp.p", "DIRECTION": 192, "VALUE": 9}]
    assert m.get_info_signals() == [
        {"NAME": "free", "VALUE": 0.0, "DRIVER": None, "TYPE": 2},
        {"NAME": "sz", "VALUE": True, "DRIVER": "cmp.z", "TYPE": 1}]
    assert list(m.get_info_pins()[0]) == ["NAME", "VALUE", "DIRECTION",
                                          "TYPE"]


def test_msg_level(hal, comp):
    m = compat
    assert m.get_msg_level() == m.MSG_ERR
    m.set_msg_level(m.MSG_DBG)
    assert m.get_msg_level() == 4 and hal.info()["msg_level"] == 4
    m.set_msg_level(9)                      # clamped (LinuxCNC keeps 9)
    assert m.get_msg_level() == m.MSG_ALL
    m.set_msg_level(-3)
    assert m.get_msg_level() == m.MSG_NONE
    with pytest.raises(TypeError):
        m.set_msg_level("x")
    m.set_msg_level(m.MSG_ERR)


def test_sigterm_raises_keyboard_interrupt_unless_handled(hal,
                                                          sigterm_guard):
    m = compat
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    c = m.component("sig1")
    try:
        assert signal.getsignal(signal.SIGTERM) is signal.default_int_handler
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1)               # the handler runs before this ends
    finally:
        c.exit()

    def mine(signum, frame):
        pass

    signal.signal(signal.SIGTERM, mine)
    c = m.component("sig2")
    try:
        assert signal.getsignal(signal.SIGTERM) is mine     # kept
    finally:
        c.exit()


# ---------------------------------------------------------------- children

def test_scale_component_runs_unchanged(hal, children):
    child = children("scale.py")
    wait_ready("scale", child)
    assert [p.name for p in hal.pins("scale.*")] == ["scale.in", "scale.out"]
    assert hal.getp("scale.gain") == 1.0
    hal.setp("scale.gain", 3.0)
    hal.setp("scale.offset", 0.5)
    hal.setp("scale.in", 2.0)
    wait_until(lambda: hal.getp("scale.out") == 6.5, "scale.out == 6.5")
    # drive the input through a net from a test-owned component
    drv = halsdk.component("drv")
    try:
        drv.newpin("x", "float", "out")
        drv.ready()
        hal.net("cmd", "drv.x", "scale.in")
        drv["x"] = -1.5
        wait_until(lambda: hal.getp("scale.out") == -4.0, "scale.out == -4")
        hal.net("result", "scale.out")
        drv["x"] = 10.0
        wait_until(lambda: hal.gets("result") == 30.5, "result == 30.5")
        unload_and_check(hal, "scale", child)
        assert hal.signal("cmd").readers == 0
        assert hal.signal("result").writers == 0
    finally:
        drv.exit()


def test_debounce_component_runs_unchanged(hal, children):
    child = children("debounce.py")
    wait_ready("debounce", child)
    assert hal.getp("db.samples") == 3
    assert hal.getp("db.out") is False and hal.getp("db.changes") == 0
    hal.setp("db.in", 1)
    wait_until(lambda: hal.getp("db.out") is True, "db.out to follow in")
    assert hal.getp("db.changes") == 1
    hal.setp("db.in", 0)
    wait_until(lambda: hal.getp("db.out") is False, "db.out to follow in")
    assert hal.getp("db.changes") == 2
    # a very long debounce time: the output holds
    hal.setp("db.samples", 1_000_000)
    hal.setp("db.in", 1)
    time.sleep(0.1)
    assert hal.getp("db.out") is False and hal.getp("db.changes") == 2
    hal.setp("db.samples", 1)
    wait_until(lambda: hal.getp("db.out") is True, "db.out to follow in")
    assert hal.getp("db.changes") == 3
    unload_and_check(hal, "debounce", child)
    assert _core.find("pin", "db.in") is None


def test_counter_component_runs_unchanged(hal, children):
    child = children("counter.py")
    wait_ready("counter", child)
    assert hal.pin("counter.count").type == halsdk.S32
    assert hal.pin("counter.total").type == halsdk.U32
    assert hal.getp("counter.step") == 1

    def edge() -> None:
        hal.setp("counter.up", 1)
        wait_until(lambda: hal.getp("counter.state") is True, "state 1")
        hal.setp("counter.up", 0)
        wait_until(lambda: hal.getp("counter.state") is False, "state 0")

    edge()
    edge()
    assert hal.getp("counter.count") == 2 and hal.getp("counter.total") == 2
    hal.setp("counter.step", -5)
    edge()
    assert hal.getp("counter.count") == -3
    assert hal.getp("counter.total") == 3
    hal.setp("counter.reset", 1)
    wait_until(lambda: hal.getp("counter.count") == 0, "count reset")
    hal.setp("counter.reset", 0)
    assert hal.getp("counter.total") == 3
    unload_and_check(hal, "counter", child)


def test_mirror_component_wires_itself(hal, children):
    child = children("mirror.py", "m1")
    wait_ready("m1", child)
    assert child.readline() == "wired False True True"
    sig = hal.signal("m1-loop")
    assert sig.writers == 1 and [p.name for p in sig.pins] == ["m1.out"]
    assert hal.pin("m1.extra.seen").owner == "m1"
    hal.setp("m1.in", 42)
    wait_until(lambda: hal.gets("m1-loop") == 42, "m1-loop == 42")
    wait_until(lambda: hal.getp("m1.extra.seen") == 1, "seen == 1")
    # a second copy under another name runs alongside
    other = children("mirror.py", "m2")
    wait_ready("m2", other)
    assert other.readline() == "wired False True True"
    unload_and_check(hal, "m1", child)
    assert child.readline() == "bye"
    assert hal.signal("m1-loop").writers == 0       # the signal stays
    assert hal.component("m2").ready
    hal.unload("all")
    assert other.wait() == 0, other.stderr
    assert not [c for c in hal.components() if not c.name.startswith("__")]


def test_component_creates_an_instance_when_none_runs(tmp_path):
    """With no instance running, hal.component() makes one (this process is
    its host) and removes it at exit."""
    name = f"compat-{os.getpid()}-solo"
    shm = halsdk.core.instance.shm_name(name)
    script = (
        "import hal, signal\n"
        "h = hal.component('solo')\n"
        "h.newpin('x', hal.HAL_S32, hal.HAL_OUT)\n"
        "h.ready()\n"
        "h['x'] = 5\n"
        "print(hal.component_exists('solo'), hal.get_value('solo.x'),\n"
        "      signal.getsignal(signal.SIGTERM) is "
        "signal.default_int_handler)\n")
    res = subprocess.run([sys.executable, "-c", script],
                         env=compat_env(HALSDK_INSTANCE=name),
                         capture_output=True, text=True, timeout=60,
                         cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["True", "5", "True"]
    assert not os.path.exists("/dev/shm" + shm)


def test_own_instance_is_left_clean(children, monkeypatch):
    """A component run in an instance made here: nothing stays in /dev/shm
    once it is unloaded and the instance closed."""
    name = f"compat-{os.getpid()}-own"
    monkeypatch.setenv("HALSDK_INSTANCE", name)
    shm = "/dev/shm" + halsdk.core.instance.shm_name(name)
    with halsdk.Hal(name, create=True) as host:
        assert os.path.exists(shm)
        child = children("scale.py")
        wait_ready("scale", child)
        host.setp("scale.in", 4.0)
        wait_until(lambda: host.getp("scale.out") == 4.0, "scale.out == 4")
        host.unload("scale")
        assert child.wait() == 0, child.stderr
    assert not os.path.exists(shm)

