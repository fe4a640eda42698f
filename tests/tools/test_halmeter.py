"""halmeter (text mode): watch a pin, signal or param of a running instance."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

import halsdk
from halsdk.core import _core
from halsdk.tools import halmeter


def _halmeter(tmp_path, *args: str, env=None, timeout: float = 30):
    """Run halmeter in a child attached to the test's instance (the fixture
    sets HALSDK_INSTANCE); cwd is a temp folder so that the installed
    package, not the source tree, is imported."""
    return subprocess.run(
        [sys.executable, "-m", "halsdk.tools.halmeter", *args],
        cwd=tmp_path, capture_output=True, text=True, timeout=timeout,
        env=env)


def _popen(tmp_path, *args: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "halsdk.tools.halmeter", *args],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)


def _finish(proc: subprocess.Popen) -> tuple[str, str]:
    try:
        return proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


# ---------------------------------------------------------------- formats

@pytest.mark.parametrize("hal_type, value, text", [
    (_core.BIT, True, "TRUE"),
    (_core.BIT, False, "FALSE"),
    (_core.FLOAT, 3.14159265, "3.141593"),
    (_core.FLOAT, 1e10, "1e+10"),
    (_core.FLOAT, -0.0000004, "-4e-07"),
    (_core.FLOAT, 0.0, "0"),
    (_core.FLOAT, -0.0, "-0"),
    (_core.FLOAT, 123456789.0, "1.234568e+08"),
    (_core.FLOAT, float("inf"), "inf"),
    (_core.FLOAT, float("nan"), "nan"),
    (_core.FLOAT, -float("nan"), "-nan"),
    (_core.S32, 42, "        42"),
    (_core.S32, -2147483648, "-2147483648"),
    (_core.U32, 0, "         0 (0x00000000)"),
    (_core.U32, 4294967295, "4294967295 (0xFFFFFFFF)"),
    (_core.S64, -(1 << 63), "-9223372036854775808"),
    (_core.U64, (1 << 64) - 1,
     "18446744073709551615 (0xFFFFFFFFFFFFFFFF)"),
])
def test_value_formats(hal_type, value, text):
    assert halmeter.format_value(hal_type, value) == text


def test_signals_of_every_type_through_the_program(hal, tmp_path):
    values = {"b": ("bit", 1), "f": ("float", 2.5), "s": ("s32", -7),
              "u": ("u32", 3000000000), "l": ("s64", 1 << 40),
              "k": ("u64", 1 << 63)}
    for sig, (type_word, value) in values.items():
        hal.newsig(sig, type_word)
        hal.sets(sig, value)
    got = {sig: _halmeter(tmp_path, "-s", "sig", sig, "-n", "1")
           for sig in values}
    assert {s: (p.returncode, p.stdout, p.stderr) for s, p in got.items()} \
        == {"b": (0, "TRUE\n", ""), "f": (0, "2.5\n", ""),
            "s": (0, "        -7\n", ""),
            "u": (0, "3000000000 (0xB2D05E00)\n", ""),
            "l": (0, "1099511627776\n", ""),
            "k": (0, "9223372036854775808 (0x8000000000000000)\n", "")}


def test_pin_param_alias_and_linked_pin(hal, tmp_path):
    comp = halsdk.component("mc")
    comp.newpin("in", "s32", "in")
    comp.newparam("gain", "float", "rw")
    comp.ready()
    comp["gain"] = 0.25
    hal.setp("mc.in", 11)
    assert _halmeter(tmp_path, "-s", "pin", "mc.in", "-n", "1").stdout \
        == "        11\n"
    assert _halmeter(tmp_path, "-s", "param", "mc.gain", "-n", "2").stdout \
        == "0.25\n0.25\n"
    hal.alias("pin", "mc.in", "my-in")
    assert _halmeter(tmp_path, "-s", "pin", "my-in", "-n", "1").stdout \
        == "        11\n"
    # a linked in-pin shows the value of its signal
    hal.newsig("wire", "s32")
    hal.net("wire", "my-in")
    hal.sets("wire", -3)
    assert _halmeter(tmp_path, "-s", "pin", "my-in", "-n", "1").stdout \
        == "        -3\n"
    # the kind word matters: a pin is not found as a param
    proc = _halmeter(tmp_path, "-s", "param", "my-in", "-n", "1")
    assert (proc.returncode, proc.stdout) == (1, "")
    assert "param 'my-in' not found" in proc.stderr
    comp.exit()


# ---------------------------------------------------------------- updates

def test_follows_changes_of_the_value(hal, tmp_path):
    hal.newsig("level", "float")
    hal.sets("level", 1.5)
    proc = _popen(tmp_path, "-s", "sig", "level", "-p", "20")
    try:
        assert proc.stdout.readline() == "1.5\n"
        hal.sets("level", -2.75)
        deadline = time.monotonic() + 10
        seen = []
        while time.monotonic() < deadline:
            line = proc.stdout.readline()
            seen.append(line)
            if line == "-2.75\n":
                break
        assert seen[-1] == "-2.75\n", seen
        assert set(seen) <= {"1.5\n", "-2.75\n"}
        proc.send_signal(signal.SIGTERM)
        out, err = _finish(proc)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert set(out.splitlines()) <= {"-2.75"}


def test_period_and_count(hal, tmp_path):
    hal.newsig("x", "bit")
    t0 = time.monotonic()
    proc = _halmeter(tmp_path, "-s", "sig", "x", "-n", "4", "-p", "150")
    elapsed = time.monotonic() - t0
    assert (proc.returncode, proc.stdout) == (0, "FALSE\n" * 4)
    assert elapsed >= 0.45           # three waits of 150 ms between lines
    proc = _halmeter(tmp_path, "-s", "sig", "x", "-n", "0")
    assert (proc.returncode, proc.stdout) == (0, "")


def test_geometry_is_accepted_and_ignored(hal, tmp_path):
    hal.newsig("x", "u32")
    hal.sets("x", 255)
    proc = _halmeter(tmp_path, "-s", "sig", "x", "-g", "100", "500", "400",
                     "-n", "1")
    assert (proc.returncode, proc.stdout, proc.stderr) == \
        (0, "       255 (0x000000FF)\n", "")
    proc = _halmeter(tmp_path, "-s", "sig", "x", "-g", "100", "-n", "1")
    assert proc.returncode == 1
    assert "option '-g' needs X and Y" in proc.stderr


def test_item_deleted_while_watched(hal, tmp_path):
    hal.newsig("gone", "s32")
    proc = _popen(tmp_path, "-s", "sig", "gone", "-p", "20")
    try:
        assert proc.stdout.readline() == "         0\n"
        hal.delsig("gone")
        out, err = _finish(proc)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 1
    assert set(out.splitlines()) <= {"         0"}
    assert "signal 'gone' was deleted" in err


# ---------------------------------------------------------------- errors

def test_unknown_item(hal, tmp_path):
    for kind, word in (("pin", "pin"), ("sig", "signal"),
                       ("param", "param")):
        proc = _halmeter(tmp_path, "-s", kind, "no.such", "-n", "1")
        assert (proc.returncode, proc.stdout) == (1, "")
        assert proc.stderr == f"halmeter: ERROR: {word} 'no.such' not " \
                              "found\n"


def test_gui_is_not_supported(hal, tmp_path):
    hal.newsig("x", "bit")
    for args in ((), ("sig", "x"), ("sig", "x", "-g", "1", "2")):
        proc = _halmeter(tmp_path, *args)
        assert (proc.returncode, proc.stdout) == (1, "")
        assert "not supported" in proc.stderr
        assert "halmeter -s" in proc.stderr


@pytest.mark.parametrize("args, message", [
    (("-s",), "-s option requires a probe type and a pin/signal/parameter "
              "name"),
    (("-s", "pin"), "no pin/signal/parameter name"),
    (("-s", "wire", "x"), "'wire' is not a valid probe type"),
    (("-s", "sig", "x", "extra"), "extra argument 'extra'"),
    (("-s", "sig", "x", "-n", "many"), "invalid value 'many' for option "
                                       "'-n'"),
    (("-s", "sig", "x", "-n"), "option '-n' needs a value"),
    (("-s", "sig", "x", "-p", "0"), "invalid period 0"),
    (("-s", "sig", "x", "-q"), "unknown option '-q'"),
])
def test_usage_errors(hal, tmp_path, args, message):
    hal.newsig("x", "bit")
    proc = _halmeter(tmp_path, *args)
    assert (proc.returncode, proc.stdout) == (1, "")
    assert message in proc.stderr


def test_help(tmp_path):
    proc = _halmeter(tmp_path, "--help")
    assert proc.returncode == 0
    assert proc.stdout.startswith("usage: halmeter -s {pin|sig|param} NAME")


def test_no_instance(tmp_path):
    name = f"halmeter-none-{os.getpid()}"
    env = dict(os.environ, HALSDK_INSTANCE=name)
    proc = _halmeter(tmp_path, "-s", "sig", "x", "-n", "1", env=env)
    assert (proc.returncode, proc.stdout) == (1, "")
    assert "cannot attach to the HAL instance" in proc.stderr
    # nothing made under that name (other runs on the machine may make
    # and remove segments of their own meanwhile)
    assert [n for n in os.listdir("/dev/shm") if name in n] == []
