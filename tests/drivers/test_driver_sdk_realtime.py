"""Realtime driver helpers (halsdk/driverkit/rt.pxd) and the worked example
examples/rt-driver/rtboard.pyx, built and loaded as realtime modules."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest
from helpers import REPO

import halsdk
from halsdk import build
from halsdk.build import build_component
from halsdk.core import _core
from halsdk.errors import HalError, InvalidError

ROOT = str(REPO)
EXAMPLE = os.path.join(ROOT, "examples", "rt-driver")
# rt.pxd as the build finds it: Cython's include path is the folder that
# holds the installed halsdk package
DRIVER_PXD_DIR = os.path.join(build.PACKAGE_DIR, "driverkit")
B = "rtboard.0."

# a second driver that uses the helpers the example does not: 32-bit
# counters, functions per io-type, and the fault helpers from Python
MINI = textwrap.dedent("""
    from halsdk cimport hal
    from halsdk.driverkit cimport rt

    hal.import_halsdk()

    cdef struct mini_t:
        unsigned int counter
        rt.device_t dev
        rt.digin_t din
        rt.encoder_t enc

    cdef mini_t *m = NULL
    cdef int comp_id = -1

    cdef void read_enc(void *arg, long period) noexcept nogil:
        cdef mini_t *p = <mini_t *>arg
        rt.encoder_update(&p.enc, p.counter, period)

    cdef void read_din(void *arg, long period) noexcept nogil:
        cdef mini_t *p = <mini_t *>arg
        rt.digin_update(&p.din, p.counter & 1)
        if p.counter == 13:
            rt.device_fault(&p.dev, rt.RT_FAULT_READ, b"unlucky count")
        else:
            rt.device_ok(&p.dev)

    modparams = {"bits": (int, 32, "counter width")}

    def setup(bits=32):
        global comp_id, m
        comp_id = hal.hal_init(b"mini")
        rt.check(comp_id, "hal_init")
        m = <mini_t *>hal.hal_malloc(sizeof(mini_t))
        m.counter = 0
        rt.check(rt.device_export(&m.dev, comp_id, b"mini", 3), "device")
        rt.check(rt.digin_export(&m.din, comp_id, b"mini", 3, 12), "digin")
        rt.check(rt.encoder_export(&m.enc, comp_id, b"mini", 3, 7, bits, 0),
                 f"mini.3.encoder.07 (bits={bits})")
        rt.check(rt.export_funct(read_enc, m, comp_id, b"mini", 3,
                                 b"encoder", b"read"), "funct")
        rt.check(rt.export_funct(read_din, m, comp_id, b"mini", 3,
                                 b"digin", b"read"), "funct")
        rt.check(hal.hal_ready(comp_id), "hal_ready")

    def set_counter(value):
        m.counter = value & 0xffffffff

    def cleanup():
        global comp_id
        if comp_id >= 0:
            hal.hal_exit(comp_id)
            comp_id = -1
""")


@pytest.fixture(scope="module")
def modules(tmp_path_factory: pytest.TempPathFactory) -> str:
    """Build rtboard and mini into a folder (cached by the build, whose
    key covers rt.pxd)."""
    folder = tmp_path_factory.mktemp("rt-driver")
    mini = folder / "src" / "mini.pyx"
    mini.parent.mkdir()
    mini.write_text(MINI)
    for source in (os.path.join(EXAMPLE, "rtboard.pyx"), str(mini)):
        build_component(source, out_dir=str(folder / "lib"))
    return str(folder / "lib")


@pytest.fixture
def path(modules: str, monkeypatch: pytest.MonkeyPatch) -> str:
    old = os.environ.get("HALSDK_PATH")
    monkeypatch.setenv("HALSDK_PATH",
                       modules + (os.pathsep + old if old else ""))
    return modules


@pytest.fixture
def board(hal, path):
    """One board on a 1 ms thread (read, then write); returns the module
    for peek/poke."""
    hal.loadrt("rtboard")
    hal.newthread("servo", 1_000_000)
    hal.addf(B + "read", "servo")
    hal.addf(B + "write", "servo")
    return hal.module("rtboard")


def kinds(items):
    return {x.name: (x.type, x.direction) for x in items}


def test_rt_pxd_is_on_the_build_include_path():
    # the build passes the parent of the halsdk package to Cython, so the
    # installed halsdk/driverkit/rt.pxd is what `cimport rt` finds
    assert os.path.isfile(os.path.join(DRIVER_PXD_DIR, "rt.pxd"))
    assert os.path.isfile(os.path.join(DRIVER_PXD_DIR, "__init__.py"))
    assert os.path.dirname(halsdk.__file__) == build.PACKAGE_DIR


def test_names_types_directions(hal, path):
    assert hal.loadrt("rtboard", boards=2) == ["rtboard"]
    pins = kinds(hal.pins("rtboard.*"))
    for n in (0, 1):
        p = f"rtboard.{n}."
        assert pins[p + "fault"] == (_core.BIT, _core.OUT)
        assert pins[p + "fault-code"] == (_core.U32, _core.OUT)
        assert pins[p + "fault-count"] == (_core.U32, _core.OUT)
        assert pins[p + "digin.03.in"] == (_core.BIT, _core.OUT)
        assert pins[p + "digin.03.in-not"] == (_core.BIT, _core.OUT)
        assert pins[p + "digout.03.out"] == (_core.BIT, _core.IN)
        assert pins[p + "adcin.01.value"] == (_core.FLOAT, _core.OUT)
        assert pins[p + "dacout.01.value"] == (_core.FLOAT, _core.IN)
        assert pins[p + "dacout.01.enable"] == (_core.BIT, _core.IN)
        assert pins[p + "encoder.01.count"] == (_core.S32, _core.OUT)
        assert pins[p + "encoder.01.position"] == (_core.FLOAT, _core.OUT)
        assert pins[p + "encoder.01.velocity"] == (_core.FLOAT, _core.OUT)
        assert pins[p + "encoder.01.reset"] == (_core.BIT, _core.IN)
        assert pins[p + "encoder.01.index-enable"] == (_core.BIT, _core.IO)
    assert "rtboard.0.digin.04.in" not in pins
    assert not [n for n in pins if n.startswith("rtboard.2.")]
    params = kinds(hal.params("rtboard.0.*"))
    defaults = {"digout.00.invert": False, "adcin.01.scale": 1.0,
                "adcin.01.offset": 0.0, "adcin.01.bit_weight": 1.0,
                "adcin.01.hw_offset": 0.0, "dacout.01.scale": 1.0,
                "dacout.01.offset": 0.0, "dacout.01.high_limit": 1e30,
                "dacout.01.low_limit": -1e30, "dacout.01.bit_weight": 1.0,
                "dacout.01.hw_offset": 0.0,
                "encoder.01.position-scale": 1.0}
    for name, value in defaults.items():
        assert params[B + name][1] == _core.RW, name
        assert hal.getp(B + name) == value, name
    names = {f.name for f in hal.functions("rtboard.*")}
    assert names == {"rtboard.0.read", "rtboard.0.write",
                     "rtboard.1.read", "rtboard.1.write"}
    # digin.in-not is true before the first read, as in the Python SDK
    assert hal.getp(B + "digin.00.in-not") is True


def test_functions_per_io_type_and_device_pins(hal, path):
    hal.loadrt("mini")
    names = {f.name for f in hal.functions("mini.*")}
    assert names == {"mini.3.encoder.read", "mini.3.digin.read"}
    pins = kinds(hal.pins("mini.*"))
    assert pins["mini.3.digin.12.in"] == (_core.BIT, _core.OUT)
    assert pins["mini.3.encoder.07.count"] == (_core.S32, _core.OUT)
    assert "mini.3.encoder.07.index-enable" not in pins
    assert "mini.3.fault" in pins


def test_digin_and_digout_invert(hal, board):
    board.poke(0, "din", 0b0101)
    hal.step()
    ins = [hal.getp(f"{B}digin.{i:02d}.in") for i in range(4)]
    nots = [hal.getp(f"{B}digin.{i:02d}.in-not") for i in range(4)]
    assert ins == [True, False, True, False]
    assert nots == [False, True, False, True]
    hal.setp(B + "digout.00.out", True)
    hal.setp(B + "digout.02.out", True)
    hal.step()
    assert board.peek(0, "dout") == 0b0101
    hal.setp(B + "digout.00.invert", True)
    hal.setp(B + "digout.01.invert", True)
    hal.step()
    assert board.peek(0, "dout") == 0b0110


def test_adcin_scale_offset_and_converter(hal, board):
    board.poke(0, "adc0", 1000)
    board.poke(0, "adc1", 4095)
    hal.setp(B + "adcin.00.scale", 2.0)
    hal.setp(B + "adcin.00.offset", 5.0)
    hal.step()
    assert hal.getp(B + "adcin.00.value") == 1995.0
    assert hal.getp(B + "adcin.01.value") == 4095.0
    # counts -> input units: (counts - hw_offset) * bit_weight
    hal.setp(B + "adcin.00.bit_weight", 0.5)
    hal.setp(B + "adcin.00.hw_offset", 2048.0)
    hal.step()
    assert hal.getp(B + "adcin.00.value") == (1000 - 2048) * 0.5 * 2 - 5


def test_dacout_scale_clamp_and_enable(hal, board):
    hal.setp(B + "dacout.00.value", 3.0)
    hal.setp(B + "dacout.00.scale", 2.0)
    hal.setp(B + "dacout.00.offset", 1.0)
    hal.step()
    assert board.peek(0, "dac0") == 0           # not enabled
    hal.setp(B + "dacout.00.enable", True)
    hal.step()
    assert board.peek(0, "dac0") == 7
    hal.setp(B + "dacout.00.high_limit", 5.0)
    hal.step()
    assert board.peek(0, "dac0") == 5
    hal.setp(B + "dacout.00.value", -10.0)
    hal.setp(B + "dacout.00.low_limit", -4.0)
    hal.step()
    assert board.peek(0, "dac0") == 2**32 - 4   # -4 in the 32-bit register
    # output units -> counts: (raw - hw_offset) / bit_weight, rounded
    hal.setp(B + "dacout.00.bit_weight", 0.25)
    hal.setp(B + "dacout.00.hw_offset", 0.5)
    hal.step()
    assert board.peek(0, "dac0") == 2**32 - 18  # (-4 - 0.5) / 0.25
    hal.setp(B + "dacout.00.enable", False)
    hal.step()
    assert board.peek(0, "dac0") == 0


def test_encoder_wraps_resets_and_measures_velocity(hal, board):
    enc = B + "encoder.00."
    board.poke(0, "enc0", 65530)                # reads as -6 (16 bit)
    hal.step()
    assert hal.getp(enc + "count") == -6
    assert hal.getp(enc + "velocity") == 0.0    # no velocity on the first
    board.poke(0, "enc0", 4)                    # +10 across the wrap
    hal.step()
    assert hal.getp(enc + "count") == 4
    assert hal.getp(enc + "velocity") == 10_000.0   # counts/s at 1 ms
    board.poke(0, "enc0", 65526)                # -14 back across it
    hal.step()
    assert hal.getp(enc + "count") == -10
    assert hal.getp(enc + "velocity") == -14_000.0
    hal.setp(enc + "position-scale", 4.0)
    for _ in range(5):                          # 5 x 30000: several wraps
        board.poke(0, "enc0", (board.peek(0, "enc0") + 30000) & 0xffff)
        hal.step()
    assert hal.getp(enc + "count") == 149_990
    assert hal.getp(enc + "position") == 149_990 / 4
    assert hal.getp(enc + "velocity") == 30000 / 4 / 0.001
    hal.setp(enc + "reset", True)
    board.poke(0, "enc0", (board.peek(0, "enc0") + 3) & 0xffff)
    hal.step(2)
    assert hal.getp(enc + "count") == 0
    assert hal.getp(enc + "position") == 0.0
    hal.setp(enc + "reset", False)
    board.poke(0, "enc0", (board.peek(0, "enc0") - 8) & 0xffff)
    hal.step()
    assert hal.getp(enc + "count") == -8
    assert hal.getp(enc + "position") == -2.0
    hal.setp(enc + "position-scale", 0.0)       # 0 counts as 1
    hal.step()
    assert hal.getp(enc + "position") == -8.0
    # the other encoder did not move
    assert hal.getp(B + "encoder.01.count") == 0


def test_encoder_index_zeroes_at_the_latch(hal, board):
    enc = B + "encoder.01."
    board.poke(0, "enc1", 100)
    hal.step()
    board.poke(0, "latch1", 120)                # ignored: not enabled
    board.poke(0, "index", 0b10)
    board.poke(0, "enc1", 130)
    hal.step()
    assert hal.getp(enc + "count") == 130
    assert board.peek(0, "index") == 0          # acknowledged
    hal.setp(enc + "index-enable", True)
    board.poke(0, "latch1", 65530)              # index 136 counts back,
    board.poke(0, "enc1", 10)                   # across the wrap
    board.poke(0, "index", 0b10)
    hal.step()
    assert hal.getp(enc + "index-enable") is False
    assert hal.getp(enc + "count") == 16        # 10 - (-6)
    board.poke(0, "enc1", 20)
    hal.step()
    assert hal.getp(enc + "count") == 26


def test_32_bit_counter_and_s32_count(hal, path):
    hal.loadrt("mini")
    mini = hal.module("mini")
    hal.newthread("t", 1_000_000)
    hal.addf("mini.3.encoder.read", "t")
    enc = "mini.3.encoder.07."
    mini.set_counter(2**32 - 5)
    hal.step()
    assert hal.getp(enc + "count") == -5
    mini.set_counter(2**31 + 100)               # -2**31 + 105 counts away
    hal.step()
    assert hal.getp(enc + "count") == -2**31 + 100
    # the count pin is s32 and wraps; position keeps the full count
    mini.set_counter(2**31 - 50)
    hal.step()
    assert hal.getp(enc + "count") == 2**31 - 50
    assert hal.getp(enc + "position") == -2**31 - 50
    hal.unloadrt("mini")
    with pytest.raises(HalError, match=r"bits=33\): Numerical argument"):
        hal.loadrt("mini", bits=33)


def test_fault_pins_count_once_and_log_once(hal, path, capfd):
    hal.loadrt("mini")
    mini = hal.module("mini")
    hal.newthread("t", 1_000_000)
    hal.addf("mini.3.digin.read", "t")
    mini.set_counter(13)
    hal.step(20)
    assert hal.getp("mini.3.fault") is True
    assert hal.getp("mini.3.fault-code") == 2
    assert hal.getp("mini.3.fault-count") == 1
    mini.set_counter(14)
    hal.step(3)
    assert hal.getp("mini.3.fault") is False
    assert hal.getp("mini.3.fault-code") == 0
    mini.set_counter(13)
    hal.step(3)
    assert hal.getp("mini.3.fault-count") == 2
    err = capfd.readouterr().err
    assert err.count("mini.3: unlucky count") == 2
    assert err.count("mini.3: recovered") == 1


def test_board_fault_keeps_inputs(hal, board, capfd):
    board.poke(0, "din", 1)
    hal.step()
    board.poke(0, "status", 0)
    board.poke(0, "din", 0)
    hal.step(10)
    assert hal.getp(B + "fault") is True
    assert hal.getp(B + "fault-count") == 1
    assert hal.getp(B + "fault-code") == 3      # the write failed last
    assert hal.getp(B + "digin.00.in") is True  # last good value
    board.poke(0, "status", 1)
    hal.step()
    assert hal.getp(B + "fault") is False
    assert hal.getp(B + "digin.00.in") is False
    assert capfd.readouterr().err.count("board does not answer") == 1


@pytest.mark.parametrize("params, message", [
    ({"boards": 0}, "boards=0 is not 1..4"),
    ({"boards": 5}, "boards=5 is not 1..4"),
    ({"loopback": 2}, "loopback=2 is not 0 or 1"),
])
def test_bad_load_params(hal, path, params, message):
    with pytest.raises(InvalidError, match=message) as info:
        hal.loadrt("rtboard", **params)
    assert str(info.value).startswith("rtboard: ")
    assert not hal.pins("rtboard.*")
    hal.loadrt("rtboard")                       # nothing was left behind
    assert hal.pins("rtboard.0.fault")


def test_bad_board_access(hal, board):
    with pytest.raises(IndexError, match="no board 1"):
        board.peek(1, "din")
    with pytest.raises(KeyError, match="no register 'bogus'"):
        board.poke(0, "bogus", 1)


def test_unload_and_reload(hal, board):
    board.poke(0, "enc0", 50)
    hal.step()
    hal.unloadrt("rtboard")
    assert not hal.pins("rtboard.*")
    assert not hal.functions("rtboard.*")
    hal.loadrt("rtboard", boards=1)
    assert hal.module("rtboard").peek(0, "enc0") == 0   # a fresh board
    assert hal.getp(B + "encoder.00.count") == 0


def test_example_hal_file(hal, path):
    hal.source(os.path.join(EXAMPLE, "rtboard.hal"))
    hal.step(10)
    assert hal.gets("drive-on") is True
    assert hal.gets("speed-fb") == 5.0
    # 5 V is 16384 DAC counts; the rig moves the encoder 64 counts a cycle
    assert hal.gets("motor-vel") == 64.0
    before = hal.gets("motor-pos")
    hal.step(10)
    assert hal.gets("motor-pos") == pytest.approx(before + 0.64)
    hal.sets("drive-on-cmd", False)
    hal.step(3)
    assert hal.getp(B + "adcin.00.value") == 0.0  # disabled: 0 V
    assert hal.gets("motor-vel") == 0.0


LEAK_SCRIPT = """
import sys
import halsdk

with halsdk.Hal(sys.argv[1], create=True) as hal:
    hal.loadrt("rtboard", boards=2)
    hal.newthread("servo", 1_000_000)
    hal.addf("rtboard.1.read", "servo")
    hal.module("rtboard").poke(1, "enc0", 7)
    hal.step(3)
    print(hal.getp("rtboard.1.encoder.00.count"))
"""


def test_no_shared_memory_left(path, tmp_path):
    name = f"rtleak-{os.getpid()}"
    env = dict(os.environ, HALSDK_PATH=path)
    env.pop("HALSDK_INSTANCE", None)
    proc = subprocess.run([sys.executable, "-c", LEAK_SCRIPT, name],
                          capture_output=True, text=True, env=env,
                          cwd=str(tmp_path), timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["7"]
    assert not [n for n in os.listdir("/dev/shm") if name in n]
