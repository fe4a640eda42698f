"""Streams (realtime FIFOs), the sampler component, halsampler, capture."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers import data_path

import halsdk
from halsdk.core import _core

DATA = str(data_path("streams"))


def _owner(name: str = "owner") -> int:
    return _core.comp_new(name, _core.COMP_USER)


def _halsampler(tmp_path, *args: str, timeout: float = 30):
    """Run halsampler in a child attached to the test's instance (the
    fixture sets HALSDK_INSTANCE); cwd is a temp folder so that the
    installed package, not the source tree, is imported."""
    return subprocess.run(
        [sys.executable, "-m", "halsdk.tools.halsampler", *args],
        cwd=tmp_path, capture_output=True, text=True, timeout=timeout)


# ---------------------------------------------------------------- the ring

def test_ring_wraps_around_and_numbers_samples(hal):
    s = _core.stream_create("ring", _owner(), 3, "s")
    assert (s.maxdepth, s.depth, s.nelem, s.typestring) == (3, 0, 1, "s")
    got = []
    for k in range(10):              # 10 passes over a 3-slot ring
        assert s.write([k]) is True
        assert s.write([100 + k]) is True
        assert s.depth == 2
        got.append(s.read())
        got.append(s.read())
    assert got == [(2 * k + j, (v,)) for k in range(10)
                   for j, v in enumerate((k, 100 + k))]
    assert (s.depth, s.overruns, s.underruns, s.sampleno) == (0, 0, 0, 20)


def test_overrun_and_underrun_counts(hal):
    # depth 3 holds 2 records, as the reference's streams
    s = _core.stream_create("oru", _owner(), 3, "u")
    assert s.read() is None
    assert s.underruns == 1
    assert s.room == 2
    assert [s.write([v]) for v in (1, 2, 3, 4)] == [True, True, False, False]
    assert (s.overruns, s.depth, s.sampleno, s.room) == (2, 2, 2, 0)
    # a dropped record takes no sample number; the oldest records stay
    assert s.read() == (0, (1,))
    assert s.write([5]) is True
    assert [s.read(), s.read(), s.read()] == [(1, (2,)), (2, (5,)), None]
    assert (s.overruns, s.underruns, s.room) == (2, 2, 2)


def test_depth_one_holds_nothing(hal):
    s = _core.stream_create("none", _owner(), 1, "f")
    assert (s.maxdepth, s.room, s.write([1.0]), s.overruns) == (1, 0, False, 1)


def test_all_types_with_64_bit_extremes(hal):
    s = _core.stream_create("types", _owner(), 4, "fbsulkFBSULK")
    assert s.types == [_core.FLOAT, _core.BIT, _core.S32, _core.U32,
                       _core.S64, _core.U64] * 2
    lo = [-1.5e300, False, -(1 << 31), 0, -(1 << 63), 0]
    hi = [float("inf"), True, (1 << 31) - 1, (1 << 32) - 1, (1 << 63) - 1,
          (1 << 64) - 1]
    assert s.write(lo + hi) and s.write(hi + lo)
    assert s.read() == (0, tuple(lo + hi))
    arr = s.read_many()
    assert arr.dtype.names == ("sample",) + tuple(f"v{i}" for i in range(12))
    assert arr["sample"].tolist() == [1]
    assert arr["v4"].dtype == np.int64 and arr["v4"][0] == (1 << 63) - 1
    assert arr["v5"].dtype == np.uint64 and arr["v5"][0] == (1 << 64) - 1
    assert arr["v1"].dtype == np.bool_ and bool(arr["v1"][0]) is True
    assert arr["v8"][0] == -(1 << 31) and arr["v10"][0] == -(1 << 63)
    with pytest.raises(halsdk.InvalidError, match="out of range for s32"):
        s.write([0, 0, 1 << 31, 0, 0, 0] * 2)
    with pytest.raises(halsdk.InvalidError, match="takes 12 values"):
        s.write([1, 2])


def test_more_than_21_values_up_to_256(hal):
    owner = _owner()
    s = _core.stream_create("wide", owner, 6, "l" * 256)
    for k in range(5):
        assert s.write([k * 1000 + i for i in range(256)])
    arr = s.read_many(names=[f"c{i}" for i in range(256)])
    assert len(arr) == 5 and arr["c255"].tolist() == [255, 1255, 2255,
                                                      3255, 4255]
    with pytest.raises(halsdk.InvalidError, match="more than 256 values"):
        _core.stream_create("wider", owner, 5, "f" * 257)


def test_read_many_limits_and_does_not_count_underruns(hal):
    s = _core.stream_create("bulk", _owner(), 1000, "fs")
    for k in range(700):
        s.write([k / 2, -k])
    first = s.read_many(300, names=["x", "y"])
    rest = s.read_many(names=["x", "y"])
    assert len(first) == 300 and len(rest) == 400
    assert first["x"][-1] == 149.5 and rest["y"][0] == -300
    assert rest["sample"][-1] == 699
    assert len(s.read_many()) == 0 and s.underruns == 0


@pytest.mark.parametrize("args, error, match", [
    (("bad name", 4, "f"), halsdk.InvalidError, "contains a blank"),
    (("s", 0, "f"), halsdk.InvalidError, "depth 0"),
    (("s", 4, ""), halsdk.InvalidError, "empty type string"),
    (("s", 4, "fxb"), halsdk.InvalidError,
     r"stream 's': unknown type 'x' in type string 'fxb'"),
    (("s", 1 << 30, "ffff"), halsdk.CapacityError, "do not fit"),
])
def test_bad_stream_arguments(hal, args, error, match):
    name, depth, types = args
    with pytest.raises(error, match=match):
        _core.stream_create(name, _owner(), depth, types)
    assert _core.items("stream") == []


def test_duplicate_names_and_owner_checks(hal):
    owner = _owner()
    _core.stream_create("dup", owner, 4, "b")
    with pytest.raises(halsdk.ExistsError, match="duplicate stream name"):
        _core.stream_create("dup", owner, 4, "b")
    with pytest.raises(halsdk.InvalidError, match="no component with id"):
        _core.stream_create("other", 99999, 4, "b")
    with pytest.raises(halsdk.NotFoundError, match="stream 'nope' not found"):
        _core.stream_attach("nope")
    # a stream and a function may share a name: separate name spaces
    assert _core.find("stream", "dup").name == "dup"
    assert _core.info()["counts"]["stream"] == 1
    hal.check()


def test_stream_vanishes_with_its_component(hal):
    owner = _owner("gone")
    s = _core.stream_create("gone.fifo", owner, 8, "f")
    other = _core.stream_create("kept", _owner("stays"), 8, "f")
    s.write([1.0])
    _core.comp_exit(owner)
    assert not s.exists and other.exists
    with pytest.raises(halsdk.StaleError, match="stream 'gone.fifo' no "
                       "longer exists"):
        s.read()
    with pytest.raises(halsdk.NotFoundError):
        _core.stream_attach("gone.fifo")
    assert [x.name for x in _core.items("stream")] == ["kept"]
    hal.check()


def test_instance_streams_go_with_the_instance(hal):
    hal.loadrt("tcounter", names="c1")
    hal.newinst("tcounter", "extra")
    inst = hal.instances("extra")[0]
    _core.stream_create("inst.fifo", inst.id, 4, "k")
    comp = hal.component("tcounter")
    _core.stream_create("comp.fifo", comp.id, 4, "k")
    hal.delinst(inst.name)
    assert [x.name for x in _core.items("stream")] == ["comp.fifo"]
    hal.check()


# ---------------------------------------------------------------- sampler

def _counting_sampler(hal, depth=4, cfg="fbsul"):
    hal.newthread("servo", 1_000_000)
    hal.loadrt("sampler", depth=str(depth), cfg=cfg)
    state = {"k": 0}

    def drive(period):
        k = state["k"] = state["k"] + 1
        hal.setp("sampler.0.pin.0", k / 4)
        hal.setp("sampler.0.pin.1", k % 2)
        hal.setp("sampler.0.pin.2", -k)
        hal.setp("sampler.0.pin.3", k * 3)
        hal.setp("sampler.0.pin.4", -(k << 40))

    hal.add_python_function("drive", drive, thread="servo")
    hal.addf("sampler.0", "servo")


def test_sampler_pins_and_functions(hal):
    hal.loadrt("sampler", depth="10,20", cfg="fbsu,bb")
    names = [p.name for p in hal.pins("sampler.*")]
    assert "sampler.0.pin.3" in names and "sampler.1.pin.1" in names
    assert "sampler.1.pin.2" not in names
    for n in ("curr-depth", "full", "enable", "overruns", "sample-num"):
        assert f"sampler.0.{n}" in names and f"sampler.1.{n}" in names
    kinds = {p.name: (_core.TYPE_NAMES[p.type], _core.DIR_NAMES[p.direction])
             for p in hal.pins("sampler.0.*")}
    assert kinds["sampler.0.pin.0"] == ("float", "IN")
    assert kinds["sampler.0.pin.3"] == ("u32", "IN")
    assert kinds["sampler.0.curr-depth"] == ("s32", "OUT")
    assert kinds["sampler.0.full"] == ("bit", "OUT")
    assert kinds["sampler.0.enable"] == ("bit", "IN")
    assert kinds["sampler.0.overruns"] == ("s32", "I/O")
    assert kinds["sampler.0.sample-num"] == ("s32", "I/O")
    assert hal.getp("sampler.0.enable") is True
    # FP as the reference shows it: only channels with a float pin
    assert [(f.name, f.uses_fp) for f in hal.functions()] == \
        [("sampler.0", True), ("sampler.1", False)]
    assert [(s.name, s.maxdepth, s.typestring)
            for s in _core.items("stream")] == [("sampler.0", 10, "fbsu"),
                                                ("sampler.1", 20, "bb")]
    hal.unloadrt("sampler")
    assert _core.items("stream") == [] and hal.pins("sampler.*") == []


def test_sampler_records_each_cycle_exactly(hal):
    _counting_sampler(hal, depth=5)   # holds 4 records
    hal.step(3)
    assert hal.getp("sampler.0.curr-depth") == 3
    assert hal.getp("sampler.0.full") is False
    hal.step(3)                       # 6 cycles into 4 slots
    assert hal.getp("sampler.0.curr-depth") == 5      # the depth
    assert hal.getp("sampler.0.full") is True
    assert hal.getp("sampler.0.overruns") == 2
    # as in the reference, sample-num is not advanced by sampler (the
    # sample number travels in the stream: halsampler -t)
    assert hal.getp("sampler.0.sample-num") == 0
    s = hal.stream("sampler.0")
    arr = s.read_many(names=["f", "b", "s", "u", "l"])
    assert arr["sample"].tolist() == [0, 1, 2, 3]
    assert arr["f"].tolist() == [0.25, 0.5, 0.75, 1.0]
    assert arr["b"].tolist() == [True, False, True, False]
    assert arr["s"].tolist() == [-1, -2, -3, -4]
    assert arr["u"].tolist() == [3, 6, 9, 12]
    assert arr["l"].tolist() == [-(k << 40) for k in (1, 2, 3, 4)]
    hal.step(1)                       # room again: cycle 7 goes in
    assert hal.getp("sampler.0.full") is False
    assert hal.getp("sampler.0.curr-depth") == 1
    assert s.read() == (4, (7 / 4, True, -7, 21, -(7 << 40)))
    hal.setp("sampler.0.enable", False)
    hal.step(5)
    # as the reference: while disabled, curr-depth follows the reader
    assert s.depth == 0 and hal.getp("sampler.0.curr-depth") == 0
    assert hal.getp("sampler.0.overruns") == 2


def test_sampler_overruns_pin_can_be_reset(hal):
    _counting_sampler(hal, depth=2)   # holds 1 record
    hal.step(4)
    assert hal.getp("sampler.0.overruns") == 3
    hal.setp("sampler.0.overruns", 0)
    hal.step(2)
    assert hal.getp("sampler.0.overruns") == 2


@pytest.mark.parametrize("params, match", [
    ({"depth": "4", "cfg": "fx"}, r"sampler\.0: unknown type 'x'"),
    ({"depth": "4,4", "cfg": "f,bq"}, r"sampler\.1: unknown type 'q'"),
    ({"depth": "4", "cfg": "f,b"}, r"sampler\.1: no depth given for cfg 'b'"),
    ({"depth": "4"}, "no channels specified"),
    ({"depth": "0", "cfg": "f"}, r"sampler\.0: depth 0"),
    ({"depth": "4", "cfg": "f" * 257}, r"sampler\.0: cfg string has 257"),
])
def test_sampler_bad_config(hal, params, match):
    with pytest.raises(halsdk.HalError, match=match):
        hal.loadrt("sampler", **params)
    assert hal.components() == [] and _core.items("stream") == []


def test_sampler_wide_channel(hal):
    hal.newthread("servo", 1_000_000)
    hal.loadrt("sampler", depth="3", cfg="s" * 40)
    hal.addf("sampler.0", "servo")
    for i in range(40):
        hal.setp(f"sampler.0.pin.{i}", i * i)
    hal.step(1)
    assert hal.stream("sampler.0").read() == (0, tuple(i * i
                                                       for i in range(40)))


# ---------------------------------------------------------------- halsampler

def _golden_config(hal):
    """tests/data/streams/sampler_fbsu.hal, built through the API and
    stepped instead of started."""
    hal.newthread("t1", 1_000_000)
    hal.loadrt("sampler", depth="100,20", cfg="fbsu,bb")
    hal.addf("sampler.0", "t1")
    hal.set({"sampler.0.pin.0": 1.5, "sampler.0.pin.1": 1,
             "sampler.0.pin.2": -3, "sampler.0.pin.3": 7})


def test_halsampler_matches_reference_output(hal, tmp_path):
    _golden_config(hal)
    hal.step(10)
    first = _halsampler(tmp_path, "-n", "3")
    second = _halsampler(tmp_path, "-t", "-n", "2")
    assert first.returncode == 0 and second.returncode == 0, \
        first.stderr + second.stderr
    with open(os.path.join(DATA, "sampler_fbsu.out")) as f:
        assert first.stdout + second.stdout == f.read()


def test_halsampler_number_formats_match_reference(hal, tmp_path):
    hal.newthread("t1", 1_000_000)
    hal.loadrt("sampler", depth="50", cfg="ffbbsu")
    hal.addf("sampler.0", "t1")
    hal.set({"sampler.0.pin.0": 1e10, "sampler.0.pin.1": -0.0000004,
             "sampler.0.pin.2": 0, "sampler.0.pin.3": 1,
             "sampler.0.pin.4": -2147483648, "sampler.0.pin.5": 4294967295})
    hal.step(2)
    proc = _halsampler(tmp_path, "-t", "-n", "2")
    with open(os.path.join(DATA, "sampler_formats.out")) as f:
        assert (proc.returncode, proc.stdout) == (0, f.read())


def test_halsampler_channel_file_and_64_bit(hal, tmp_path):
    hal.newthread("t1", 1_000_000)
    hal.loadrt("sampler", depth="5,5", cfg="f,lkb")
    hal.addf("sampler.1", "t1")
    hal.set({"sampler.1.pin.0": -(1 << 63), "sampler.1.pin.1": (1 << 64) - 1,
             "sampler.1.pin.2": 1})
    hal.step(2)
    out = tmp_path / "samples.txt"
    proc = _halsampler(tmp_path, "-c", "1", "-n", "2", str(out))
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "", "")
    line = f"{-(1 << 63)} {(1 << 64) - 1} 1 \n"
    assert out.read_text() == line * 2


def test_halsampler_errors(hal, tmp_path):
    hal.loadrt("sampler", depth="5", cfg="f")
    proc = _halsampler(tmp_path, "-c", "2", "-n", "1")
    assert proc.returncode == 1
    assert "stream 'sampler.2' not found" in proc.stderr
    proc = _halsampler(tmp_path, "-x")
    assert (proc.returncode, proc.stderr) == (1, "ERROR: unknown option "
                                                 "'x'\n")
    proc = _halsampler(tmp_path, "-n", "many")
    assert proc.returncode == 1 and "invalid value 'many'" in proc.stderr


def test_halsampler_waits_for_data_and_reports_removal(hal, tmp_path):
    hal.newthread("t1", 1_000_000)
    hal.loadrt("sampler", depth="5", cfg="s")
    hal.addf("sampler.0", "t1")
    hal.setp("sampler.0.pin.0", 42)
    proc = subprocess.Popen(
        [sys.executable, "-m", "halsdk.tools.halsampler", "-n", "3"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    stream = hal.find("stream", "sampler.0")

    def taken() -> None:
        """Until halsampler has read what is in the stream (a loaded
        machine may take long to start it)."""
        deadline = time.monotonic() + 30
        while stream.depth and time.monotonic() < deadline:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.01)

    try:
        hal.step(1)
        taken()
        time.sleep(0.2)               # it has one record and waits
        assert proc.poll() is None
        hal.step(1)
        taken()
        hal.unloadrt("sampler")       # the stream goes away under it
        out, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 1
    assert out == "42 \n42 \n"
    assert "stream 'sampler.0' was removed" in err


# ---------------------------------------------------------------- realtime

def test_reading_while_a_realtime_thread_writes(hal):
    hal.loadrt("tcounter", names="c1")
    hal.newthread("fast", 100_000, fp=False)
    hal.loadrt("sampler", depth="64", cfg="k")
    hal.net("cyc", "c1.cycles", "sampler.0.pin.0")
    hal.addf("c1", "fast")
    hal.addf("sampler.0", "fast")
    s = hal.stream("sampler.0")
    chunks = []
    hal.start()
    try:
        deadline = time.monotonic() + 20
        while sum(len(c) for c in chunks) < 3000:
            assert time.monotonic() < deadline, "the thread stalled"
            chunks.append(s.read_many())
    finally:
        hal.stop()
    chunks.append(s.read_many())
    arr = np.concatenate(chunks)
    # the records come in order with consecutive sample numbers; a value
    # is missing exactly where the FIFO was full
    assert (arr["sample"] == np.arange(len(arr))).all()
    values = arr["v0"].astype(np.int64)
    gaps = np.diff(values) - 1
    assert (gaps >= 0).all()
    assert int(gaps.sum()) == s.overruns == hal.getp("sampler.0.overruns")


# ---------------------------------------------------------------- capture

def test_capture_one_record_per_cycle(hal):
    hal.loadrt("tcounter", names="c1")
    hal.newthread("servo", 1_000_000, fp=False)
    hal.addf("c1", "servo")
    hal.newsig("edge", "bit")
    hal.net("edge", "c1.in")
    hal.setp("c1.step", 1 << 40)
    hal.step(2)
    got = hal.capture(["c1.cycles", "c1.count", "edge", "c1.step"], 1000)
    assert got["c1.cycles"].dtype == np.uint64
    assert got["c1.cycles"].tolist() == list(range(3, 1003))
    assert (got["c1.count"] == 0).all() and not got["edge"].any()
    assert (got["c1.step"] == 1 << 40).all()
    # the capture removed everything it made
    assert [c.name for c in hal.components()] == ["__servo", "tcounter"]
    assert hal.thread("servo").functions == ["c1"]
    assert _core.items("stream") == []
    hal.check()


def test_capture_of_a_slower_thread_and_errors(hal):
    hal.loadrt("tcounter", names="fastc,slowc")
    hal.newthread("fast", 1_000_000, fp=False)
    hal.newthread("slow", 3_000_000, fp=False)
    hal.addf("fastc", "fast")
    hal.addf("slowc", "slow")
    got = hal.capture(["slowc.cycles", "fastc.cycles"], 5, thread="slow")
    assert got["slowc.cycles"].tolist() == [1, 2, 3, 4, 5]
    assert np.diff(got["fastc.cycles"]).tolist() == [3, 3, 3, 3]
    with pytest.raises(halsdk.NotFoundError, match="'nope'"):
        hal.capture(["nope"], 3)
    with pytest.raises(halsdk.InvalidError, match="cycles"):
        hal.capture("fastc.cycles", 0)
    assert _core.items("stream") == []


def test_capture_while_threads_run(hal):
    hal.loadrt("tcounter", names="c1")
    hal.newthread("servo", 200_000, fp=False)
    hal.addf("c1", "servo")
    hal.start()
    try:
        got = hal.capture("c1.cycles", 500)
    finally:
        hal.stop()
    assert np.diff(got["c1.cycles"].astype(np.int64)).tolist() == [1] * 499


# ---------------------------------------------------------------- streamer

def _halstreamer(tmp_path, *args: str, stdin: str = "", timeout: float = 30):
    return subprocess.run(
        [sys.executable, "-m", "halsdk.tools.halstreamer", *args],
        cwd=tmp_path, input=stdin, capture_output=True, text=True,
        timeout=timeout)


def _read(name: str) -> str:
    with open(os.path.join(DATA, name)) as f:
        return f.read()


def test_streamer_pins_and_functions(hal):
    hal.loadrt("streamer", depth="8,4", cfg="fbsu,lk")
    kinds = {p.name: (_core.TYPE_NAMES[p.type], _core.DIR_NAMES[p.direction])
             for p in hal.pins("streamer.0.*")}
    assert kinds == {
        "streamer.0.clock": ("bit", "IN"),
        "streamer.0.clock-mode": ("s32", "IN"),
        "streamer.0.curr-depth": ("s32", "OUT"),
        "streamer.0.empty": ("bit", "OUT"),
        "streamer.0.enable": ("bit", "IN"),
        "streamer.0.pin.0": ("float", "OUT"),
        "streamer.0.pin.1": ("bit", "OUT"),
        "streamer.0.pin.2": ("s32", "OUT"),
        "streamer.0.pin.3": ("u32", "OUT"),
        "streamer.0.time": ("s32", "OUT"),
        "streamer.0.underruns": ("s32", "I/O"),
    }
    assert hal.getp("streamer.0.enable") is True
    assert hal.getp("streamer.0.empty") is True
    assert hal.pin("streamer.1.pin.1").type == _core.U64
    assert [(s.name, s.maxdepth, s.typestring)
            for s in _core.items("stream")] == [("streamer.0", 8, "fbsu"),
                                                ("streamer.1", 4, "lk")]
    hal.unloadrt("streamer")
    assert _core.items("stream") == []
    with pytest.raises(halsdk.HalError, match=r"streamer\.0: unknown type"):
        hal.loadrt("streamer", depth="8", cfg="z")
    with pytest.raises(halsdk.HalError, match=r"streamer\.1: no depth"):
        hal.loadrt("streamer", depth="8", cfg="f,f")
    assert hal.components() == []


def test_streamer_plays_one_record_per_cycle(hal):
    hal.newthread("servo", 1_000_000)
    hal.loadrt("streamer", depth="4", cfg="fbsl")
    hal.addf("streamer.0", "servo")
    s = hal.stream("streamer.0")
    for k in (1, 2, 3):
        assert s.write([k / 8, k % 2, -k, -(k << 40)])
    hal.step(1)
    assert [hal.getp(f"streamer.0.pin.{i}") for i in range(4)] == \
        [0.125, True, -1, -(1 << 40)]
    assert hal.getp("streamer.0.curr-depth") == 2
    assert hal.getp("streamer.0.empty") is False
    hal.step(2)
    assert hal.getp("streamer.0.pin.2") == -3
    assert hal.getp("streamer.0.underruns") == 0
    hal.step(2)                       # empty: the pins keep their values,
    # the underruns count on the pin only (as the reference's streamer)
    assert hal.getp("streamer.0.pin.2") == -3
    assert hal.getp("streamer.0.empty") is True
    assert hal.getp("streamer.0.underruns") == 2
    assert hal.getp("streamer.0.curr-depth") == 0
    assert s.underruns == 0
    hal.setp("streamer.0.enable", False)
    s.write([9.0, 0, 9, 9])
    hal.step(3)
    assert s.depth == 1 and hal.getp("streamer.0.pin.2") == -3
    # curr-depth and empty follow the FIFO while disabled
    assert hal.getp("streamer.0.curr-depth") == 1
    assert hal.getp("streamer.0.empty") is False
    assert hal.getp("streamer.0.underruns") == 2
    hal.setp("streamer.0.enable", True)
    hal.step(1)
    assert hal.getp("streamer.0.pin.2") == 9


@pytest.mark.parametrize("mode, clock, expect", [
    # the value shown after each cycle, for the clock level of that cycle
    (1, [1, 0, 0, 1, 0], [0, 1, 1, 1, 2]),        # falling edges
    (2, [1, 0, 0, 1, 0], [1, 1, 1, 2, 2]),        # rising edges
    (3, [1, 0, 0, 1, 0], [1, 2, 2, 3, 4]),        # both edges
    (0, [1, 0, 0, 1, 0], [1, 2, 3, 4, 5]),        # every cycle
])
def test_streamer_clock_modes(hal, mode, clock, expect):
    hal.newthread("servo", 1_000_000, fp=False)
    hal.loadrt("streamer", depth="10", cfg="s")
    hal.addf("streamer.0", "servo")
    hal.setp("streamer.0.clock-mode", mode)
    s = hal.stream("streamer.0")
    for k in range(1, 8):
        s.write([k])
    shown = []
    for level in clock:
        hal.setp("streamer.0.clock", level)
        hal.step(1)
        shown.append(hal.getp("streamer.0.pin.0"))
    assert shown == expect


def _streamer_sampler_config(hal):
    """tests/data/streams/streamer_sampler.hal through the API (stepped)."""
    hal.newthread("t1", 1_000_000)
    hal.loadrt("streamer", depth="20", cfg="fbsu")
    hal.loadrt("sampler", depth="50", cfg="fbsu")
    for i, sig in enumerate("abcd"):
        hal.net(sig, f"streamer.0.pin.{i}", f"sampler.0.pin.{i}")
    hal.addf("streamer.0", "t1")
    hal.addf("sampler.0", "t1")


@pytest.mark.parametrize("data, cycles, golden", [
    ("streamer_data.txt", 10, "streamer_sampler"),
    ("streamer_parse.txt", 14, "streamer_parse"),
])
def test_halstreamer_to_halsampler_matches_reference(hal, tmp_path, data,
                                                     cycles, golden):
    _streamer_sampler_config(hal)
    fed = _halstreamer(tmp_path, os.path.join(DATA, data))
    assert fed.returncode == 0
    assert fed.stderr == _read(golden + ".stderr")
    hal.step(cycles)
    out = _halsampler(tmp_path, "-t", "-n", str(cycles))
    assert (out.returncode, out.stdout) == (0, _read(golden + ".out"))


def test_halstreamer_waits_while_the_fifo_is_full(hal, tmp_path):
    hal.newthread("t1", 1_000_000, fp=False)
    hal.loadrt("streamer", depth="3", cfg="k")
    hal.addf("streamer.0", "t1")
    lines = "".join(f"{(1 << 64) - 1 - k}\n" for k in range(10))
    proc = subprocess.Popen(
        [sys.executable, "-m", "halsdk.tools.halstreamer", "-c", "0"],
        cwd=tmp_path, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)
    seen = []
    try:
        proc.stdin.write(lines)
        proc.stdin.close()
        deadline = time.monotonic() + 20
        while len(seen) < 10 and time.monotonic() < deadline:
            if hal.getp("streamer.0.curr-depth") == 0 and \
                    hal.stream("streamer.0").depth == 0:
                time.sleep(0.01)
            underruns = hal.getp("streamer.0.underruns")
            hal.step(1)
            # a cycle plays a record or counts an underrun
            if hal.getp("streamer.0.underruns") == underruns:
                seen.append(hal.getp("streamer.0.pin.0"))
        assert proc.wait(timeout=20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert seen == [(1 << 64) - 1 - k for k in range(10)]
    assert hal.stream("streamer.0").overruns == 0


def test_halstreamer_errors(hal, tmp_path):
    hal.loadrt("streamer", depth="3", cfg="f")
    proc = _halstreamer(tmp_path, "-c", "1", stdin="1\n")
    assert proc.returncode == 1
    assert "stream 'streamer.1' not found" in proc.stderr
    proc = _halstreamer(tmp_path, "-q")
    assert (proc.returncode, proc.stderr) == (1, "ERROR: unknown option "
                                                 "'q'\n")
    proc = _halstreamer(tmp_path, "missing.txt")
    assert proc.returncode == 1 and "cannot open 'missing.txt'" in proc.stderr
