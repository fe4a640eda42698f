"""Tests of ``hal.stream``, ``hal.shm``, ``hal.streamer_base`` and
``hal.sampler_base`` of halsdk.compat.hal.

The first half runs reference-style programs unchanged: the HAL files of
``tests/data/pystreams/`` start them with ``loadusr`` (beside ``loadrt
streamer``/``sampler``, ``halsampler`` and ``halstreamer``) and our
``halrun``'s stdout must equal ``NAME.out``, the reference's stdout of
``.../reference halrun -f NAME.hal`` run in a folder holding the inputs.
The scripts avoid what the reference does wrong (``depth`` after the ring
wraps, a second writer process, a crash after some argument errors; see
docs/compat.md).  The ``python-stream-*`` folders of ``tests/lcnc-format``
are run the same way and checked as LinuxCNC's runtests checks them.

The second half tests in the test process what the goldens do not show.
"""

from __future__ import annotations

import ctypes
import gc
import os
import shutil
import signal
import struct
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import data_path, repo_path
from helpers.docblocks import fenced_blocks
from helpers.halrun import tools_env

import halsdk
from halsdk.compat import hal as compat

PYSTREAMS = data_path("pystreams")
GOLDENS = sorted(PYSTREAMS.glob("*.hal"))
LCNC = repo_path("tests", "lcnc-format")
LCNC_TESTS = sorted(LCNC.glob("python-stream-*"))


def _env(name: str, tmp_path: Path) -> dict:
    """halrun's environment: a private instance, this Python's tools and
    this Python as ``python3`` first on PATH, and this halsdk importable
    by the programs halrun starts."""
    env = tools_env(name, tmp_path / "bin")
    py = tmp_path / "bin" / "python3"
    py.write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    py.chmod(0o755)
    src = os.path.dirname(os.path.dirname(halsdk.__file__))
    env["PYTHONPATH"] = os.pathsep.join(
        p for p in (src, env.get("PYTHONPATH", "")) if p)
    return env


def _halrun(hal_file: str, work: Path, env: dict
            ) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-f",
         hal_file], cwd=work, env=env, capture_output=True, text=True,
        timeout=120)


def _shm_left(env: dict) -> list[str]:
    return [n for n in os.listdir("/dev/shm")
            if env["HALSDK_INSTANCE"] in n]


# ---------------------------------------------------------------- goldens

def test_golden_corpus_is_there():
    assert len(GOLDENS) >= 4
    texts = " ".join(p.read_text() for p in PYSTREAMS.iterdir())
    for word in ("loadrt streamer", "loadrt sampler", "halsampler",
                 "halstreamer", "hal.streamer_base", "hal.sampler_base",
                 "num_overruns", "num_underruns", "hal.shm"):
        assert word in texts, word
    assert len(LCNC_TESTS) >= 4


@pytest.mark.parametrize("hal_file", GOLDENS, ids=lambda p: p.stem)
def test_golden(hal_file: Path, tmp_path: Path):
    work = tmp_path / "work"
    shutil.copytree(PYSTREAMS, work)
    env = _env(hal_file.stem, tmp_path)
    proc = _halrun(hal_file.name, work, env)
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.stdout == hal_file.with_suffix(".out").read_text()
    assert proc.returncode == 0, proc.stderr
    assert _shm_left(env) == []


@pytest.mark.parametrize("folder", LCNC_TESTS, ids=lambda p: p.name)
def test_lcnc_format(folder: Path, tmp_path: Path):
    """``halrun -f test.hal > result``, then ``expected`` byte for byte or
    ``checkresult result``."""
    work = tmp_path / folder.name
    shutil.copytree(folder, work)
    env = _env(folder.name, tmp_path)
    proc = _halrun("test.hal", work, env)
    assert proc.returncode == 0, proc.stderr
    (work / "result").write_text(proc.stdout)
    if (folder / "expected").exists():
        assert proc.stdout == (folder / "expected").read_text()
    else:
        check = subprocess.run([sys.executable, str(work / "checkresult"),
                                "result"], cwd=work, capture_output=True,
                               text=True, timeout=60)
        assert check.returncode == 0, check.stdout + proc.stderr
    assert _shm_left(env) == []


def test_compat_page_example_feeds_a_streamer(tmp_path: Path):
    """The Python example of docs/compat.md, started as the page says."""
    (block,) = fenced_blocks(repo_path("docs", "compat.md"), "python")
    work = tmp_path / "work"
    work.mkdir()
    (work / "feed.py").write_text(block)
    (work / "feed.hal").write_text(
        "loadrt threads name1=servo period1=1000000\n"
        "loadrt streamer depth=8 cfg=ff\n"
        "addf streamer.0 servo\n"
        "start\n"
        "loadusr -w python3 feed.py\n"
        "loadusr -w sleep 0.1\n"
        "stop\n"
        "getp streamer.0.pin.0\n"
        "getp streamer.0.curr-depth\n")
    env = _env("doc", tmp_path)
    proc = _halrun("feed.hal", work, env)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "fed 20 records, overruns: 0\n9.5\n0\n"
    assert _shm_left(env) == []


# ---------------------------------------------------------------- stream

@pytest.fixture
def comp(hal):
    """A compat component in the test process (SIGTERM restored)."""
    old = signal.getsignal(signal.SIGTERM)
    c = compat.component("streams")
    yield c
    if not c._c_state.closed:
        c.exit()
    signal.signal(signal.SIGTERM, old)


def test_bases_and_key_names(hal, comp):
    assert (compat.streamer_base, compat.sampler_base) == \
        (0x48535430, 0x48534130)
    for key, name in ((compat.streamer_base + 2, "streamer.2"),
                      (compat.sampler_base, "sampler.0"),
                      (0x1234, "stream.00001234"),
                      (-1, "stream.ffffffff")):
        s = compat.stream(comp, key, 3, "f")
        assert hal.stream(name).maxdepth == 3
        assert repr(s) == f"<stream 0x{key & 0xFFFFFFFF:x} creator>"
    assert repr(compat.stream(comp, -1)) == "<stream 0xffffffff>"


def test_loadrt_channels_by_key(hal, comp):
    hal.newthread("t", 1_000_000)
    hal.loadrt("streamer", depth="4,3", cfg="fb,lk")
    s = compat.stream(comp, compat.streamer_base + 1, "lk")
    assert (s.element_types, s.maxdepth) == (b"lk", 3)
    s.write((-(1 << 63), (1 << 64) - 1))
    hal.addf("streamer.1", "t")
    hal.step(1)
    assert hal.getp("streamer.1.pin.0") == -(1 << 63)
    assert hal.getp("streamer.1.pin.1") == (1 << 64) - 1
    with pytest.raises(OverflowError):
        s.write((0, -1))


def test_keywords_create_or_attach(hal, comp):
    # the reference ignores keyword arguments; here they mean what the
    # positions mean
    s = compat.stream(comp, 5, depth=4, cfg="fs")
    assert repr(s) == "<stream 0x5 creator>" and s.maxdepth == 4
    assert repr(compat.stream(comp, 5, cfg="fs")) == "<stream 0x5>"
    with pytest.raises(TypeError, match="needs cfg"):
        compat.stream(comp, 6, depth=4)
    with pytest.raises(TypeError, match="by name"):
        compat.stream(comp, 6, 4, "f", cfg="f")
    with pytest.raises(TypeError, match="unexpected keyword"):
        compat.stream(comp, 6, size=4)


def test_argument_errors_that_crash_the_reference(hal, comp):
    # the reference raises these, then crashes freeing the half-made object
    with pytest.raises(TypeError, match="argument 3 must be str, not int"):
        compat.stream(comp, 6, 4)
    with pytest.raises(TypeError, match="cannot be interpreted"):
        compat.stream(comp, "x", 4, "f")
    with pytest.raises(OverflowError, match="greater than maximum"):
        compat.stream(comp, 1 << 32, 4, "f")
    with pytest.raises(TypeError, match="argument 4 must be str, not bytes"):
        compat.stream(comp, 6, 4, b"f")
    with pytest.raises(TypeError, match="at most 4 arguments"):
        compat.stream(comp, 6, 4, "f", 1)


def test_create_errors(hal, comp, capsys):
    compat.stream(comp, 7, 4, "f")
    with pytest.raises(OSError) as exc:
        compat.stream(comp, 7, 4, "f")     # the reference re-creates it
    assert exc.value.errno == 17
    for cfg in ("fx", "", "f" * 257):
        with pytest.raises(OSError) as exc:
            compat.stream(comp, 8, 4, cfg)
        assert exc.value.errno == 22
    assert "stream: ERROR:" in capsys.readouterr().err
    for depth in (0, -1):
        with pytest.raises(OSError):
            compat.stream(comp, 8, depth, "f")


def test_depth_one_is_never_writable(hal, comp):
    s = compat.stream(comp, 9, 1, "f")
    assert (s.readable, s.writable, s.depth) == (False, False, 0)
    with pytest.raises(OSError):
        s.write((1.0,))
    assert s.num_overruns == 1


def test_conversions_as_pins(hal, comp):
    s = compat.stream(comp, 10, 20, "fbsulk")
    s.write(("2.5", [], -1.9, 4294967295.5, -(1 << 63), (1 << 64) - 1))
    assert s.read() == (2.5, False, -1, 4294967295, -(1 << 63),
                        (1 << 64) - 1)
    with pytest.raises(TypeError, match="Number expected, not NoneType"):
        s.write((None, 1, 1, 1, 1, 1))
    with pytest.raises(OverflowError, match="int too large"):
        s.write((10 ** 400, 1, 1, 1, 1, 1))
    assert s.depth == 0 and s.num_overruns == 0


def test_sampleno_and_tuple_subclass(hal, comp):
    s = compat.stream(comp, 11, 3, "u")
    a = compat.stream(comp, 11)
    pair = type("Pair", (tuple,), {})
    for k in range(5):
        s.write(pair((k,)))
        assert (a.read(), a.sampleno, s.sampleno) == ((k,), k + 1, 0)
    with pytest.raises(AttributeError, match="readonly attribute"):
        a.sampleno = 0
    with pytest.raises(AttributeError, match="no attribute 'x'"):
        a.x = 0
    with pytest.raises(TypeError, match="no keyword arguments"):
        a.read(block=True)
    with pytest.raises(TypeError, match="no keyword arguments"):
        s.write(values=(1,))


def test_stream_ends_with_its_component(hal, comp):
    s = compat.stream(comp, 12, 3, "f")
    a = compat.stream(comp, 12)
    comp.exit()
    with pytest.raises(RuntimeError, match="closed HAL component"):
        compat.stream(comp, 13, 3, "f")
    for obj in (s, a):
        with pytest.raises(RuntimeError, match="no longer exists"):
            obj.write((1.0,))
        with pytest.raises(RuntimeError, match="no longer exists"):
            obj.read()
    with pytest.raises(OSError):
        compat.stream(compat.component("other"), 12)


# ---------------------------------------------------------------- shm

def test_shm_buffer(hal, comp):
    m = compat.shm(comp, 0x4321, 16)
    assert repr(m).startswith("<shared memory buffer key=00004321 id=")
    assert repr(m).endswith(" size=16>")
    buf = m.getbuffer()
    assert (buf.format, buf.nbytes, buf.readonly, len(buf)) == \
        ("B", 16, False, 16)
    struct.pack_into("<I", buf, 4, 0x01020304)
    buf.cast("B")[0] = 7
    buf[15] = 255
    other = compat.shm(comp, 0x4321, 8)          # attaches: same bytes
    assert bytes(other.getbuffer()) == b"\x07\0\0\0\x04\x03\x02\x01"
    assert ctypes.c_uint32.from_buffer(other.getbuffer(), 4).value == \
        0x01020304
    addr, size = hal.shared_block("shm.00004321")
    assert size == 16
    assert ctypes.string_at(addr, 16)[-1] == 255
    m.setsize(4)
    assert m.getbuffer().nbytes == 4 and repr(m).endswith(" size=4>")
    m.setsize(0)
    assert m.getbuffer().nbytes == 0
    with pytest.raises(ValueError, match="outside the block"):
        m.setsize(17)
    with pytest.raises(compat.error, match="Invalid argument"):
        compat.shm(comp, 0x4321, 17)             # larger than the block
    with pytest.raises(compat.error, match="Invalid argument"):
        compat.shm(comp, 0x4322, 0)
    with pytest.raises(TypeError, match="exactly 3 arguments"):
        compat.shm(comp, key=1, size=2)


def test_shm_buffer_keeps_its_component(hal):
    old = signal.getsignal(signal.SIGTERM)
    try:
        c = compat.component("keeper")
        buf = compat.shm(c, 1, 8).getbuffer()
        del c
        assert hal.find("component", "keeper") is not None
        buf[0] = 1
        del buf
        gc.collect()
        assert hal.find("component", "keeper") is None
    finally:
        signal.signal(signal.SIGTERM, old)
