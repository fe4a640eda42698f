"""The latency test's engine (halsdk.tools.latency): the binning and the
figures it reads from timedelta and latencybins, stepped (exact periods)
and in running threads, from the host and from an attached process; the
refusals; and that stop leaves nothing in the instance."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import pytest
from hypothesis import given
from hypothesis import strategies as st

from halsdk.tools import latency
from halsdk.tools.latency import (
    Histogram,
    LatencyError,
    LatencyTest,
    bin_of,
    bin_range,
    setups,
)


def names(hal) -> dict[str, list[str]]:
    """What the instance holds (components, threads, functions)."""
    # records taken under the instance lock: a test being removed
    # meanwhile (by the server) does not make a listing fail
    return {kind + "s": sorted(r.name for r in hal.snapshot(kind))
            for kind in ("component", "thread", "function")}


def user_machine(hal) -> dict[str, list[str]]:
    """A user's running machine the test must leave alone."""
    hal.newthread("servo", 1_000_000)
    hal.loadrt("and2", count=1)
    hal.addf("and2.0", "servo")
    hal.start()
    return names(hal)


# ---------------------------------------------------------------- binning

@given(st.integers(-10**7, 10**7), st.integers(1, 10**5),
       st.integers(1, 1000))
def test_a_latency_falls_in_its_bin(lat, binsize, bins):
    b = bin_of(lat, binsize, bins)
    edge = (bins + 1) * binsize             # the first latency beyond
    if abs(lat) >= edge:
        assert b is None
    else:
        assert b is not None and -bins <= b <= bins
        lo, hi = bin_range(b, binsize)
        assert lo <= lat <= hi
        assert hi - lo + 1 == (2 * binsize - 1 if b == 0 else binsize)


@given(st.lists(st.integers(-50_000, 50_000), min_size=1, max_size=300),
       st.integers(1, 2000), st.integers(1, 60))
def test_a_histogram_of_random_latencies(lats, binsize, bins):
    h = Histogram(binsize, bins)
    for lat in lats:
        b = bin_of(lat, binsize, bins)
        if b is None:
            if lat > 0:
                h.above += 1
            else:
                h.below += 1
        else:
            h.counts[b] = h.counts.get(b, 0) + 1
    assert h.total == len(lats)
    avg, sdev = h.moments(min(lats), max(lats))
    assert avg is not None
    assert min(lats) - binsize <= avg <= max(lats) + binsize
    if h.below == h.above == 0:
        # each latency moved by less than a bin: so is the average
        assert abs(avg - sum(lats) / len(lats)) < binsize
    if len(lats) > 1:
        assert sdev is not None and sdev >= 0
    else:
        assert sdev is None
    data = h.as_json()
    assert data["total"] == len(lats)
    assert sum(c for _, c in data["counts"]) + h.below + h.above \
        == len(lats)


def test_the_settings_are_checked():
    with pytest.raises(LatencyError, match="latency-base.*period 1000 "):
        setups(1000, 1_000_000)
    with pytest.raises(LatencyError, match="latency-base.*bins 1001"):
        setups(25_000, 1_000_000, bins=1001)
    with pytest.raises(LatencyError, match="shorter than the servo"):
        setups(2_000_000, 1_000_000)
    assert [s.thread for s in setups(0, 1_000_000)] == ["latency-servo"]
    assert [(s.period, s.binsize, s.bins) for s in setups()] == [
        (25_000, 100, 200), (1_000_000, 100, 200)]


# ---------------------------------------------------------------- stepped

def test_stepped_threads_have_no_latency(hal):
    """Stepped threads run at exactly their period: every latency is 0,
    in bin 0, and the histogram counts every run but the first."""
    s = setups(0, 1_000_000)[0]
    test = LatencyTest(hal, [s], tick=lambda: hal.step(1, s.thread))
    test.start(run=False)
    hal.step(50, s.thread)
    fig = test.figures(read=True)["threads"][0]
    cycles = hal.thread(s.thread).cycles
    assert fig["samples"] == cycles - 1 == fig["histogram"]["total"]
    assert fig["histogram"]["counts"] == [[0, cycles - 1]]
    assert fig["min"] == fig["max"] == fig["avg"] == fig["jitter"] == 0
    assert fig["sdev"] == 0
    assert fig["interval_max"] == fig["interval_last"] == 1_000_000
    test.stop()
    assert names(hal) == {"components": [], "threads": [], "functions": []}


def test_a_reset_starts_the_count_afresh(hal):
    s = setups(0, 1_000_000)[0]
    test = LatencyTest(hal, [s], tick=lambda: hal.step(1, s.thread))
    test.start(run=False)
    hal.step(30, s.thread)
    test.reset()
    before = hal.thread(s.thread).cycles
    hal.step(5, s.thread)
    fig = test.figures(read=True)["threads"][0]
    runs = hal.thread(s.thread).cycles - before
    # latencybins keeps reading the clock while reset: the first run
    # after it measures
    assert fig["samples"] == runs
    test.stop()


# ---------------------------------------------------------------- running

def test_running_figures_are_consistent(hal):
    before = user_machine(hal)
    test = LatencyTest(hal)
    test.start()
    try:
        assert test.realtime in (True, False)
        assert test.note
        assert "servo" in names(hal)["threads"]
        time.sleep(0.5)
        data = test.figures(read=True)
    finally:
        test.stop()
    assert [t["thread"] for t in data["threads"]] == ["latency-base",
                                                      "latency-servo"]
    for t in data["threads"]:
        h = t["histogram"]
        assert t["samples"] == h["total"] > 0
        assert t["samples"] <= t["cycles"]
        assert t["min"] <= t["avg"] <= t["max"]
        assert t["sdev"] >= 0
        assert t["jitter"] >= 0
        for b, c in h["counts"]:
            lo, hi = bin_range(b, h["binsize"])
            assert c > 0 and lo <= t["max"] and hi >= t["min"]
        edge = (h["bins"] + 1) * h["binsize"]
        assert h["above"] == 0 or t["max"] >= edge
        assert h["below"] == 0 or t["min"] <= -edge
    assert names(hal) == before
    assert hal.info()["threads_running"]        # the user's still run


def test_a_started_instance_is_stopped_again(hal):
    test = LatencyTest(hal, setups(0, 1_000_000))
    test.start()
    assert hal.info()["threads_running"]
    test.stop()
    test.stop()                                 # idempotent
    assert not hal.info()["threads_running"]
    assert names(hal) == {"components": [], "threads": [], "functions": []}


def test_the_monitor_reads_histograms(hal):
    test = LatencyTest(hal, setups(0, 1_000_000, bins=20))
    test.start()
    monitor = latency.LatencyMonitor(test, interval=0.01)
    monitor.start()
    try:
        deadline = time.monotonic() + 20
        while monitor.sweeps < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        data = monitor.figures()
    finally:
        monitor.stop()
        test.stop()
    assert data["sweeps"] >= 2 and data["error"] is None
    t = data["threads"][0]
    assert t["histogram"]["total"] == t["samples"] > 0


# ---------------------------------------------------------------- scheduling

def test_without_realtime_scheduling_it_says_so(hal):
    test = LatencyTest(hal, setups(0, 1_000_000, bins=10))
    test.start(realtime=False)
    try:
        assert test.realtime is False
        assert "non-realtime" in test.note
        # no thread of the host got SCHED_FIFO
        assert latency.host_realtime(os.getpid()) is False
        time.sleep(0.2)
        t = test.figures(read=True)["threads"][0]
        assert t["samples"] == t["histogram"]["total"] > 0
    finally:
        test.stop()


@pytest.mark.parametrize("realtime", [False, True])
def test_in_a_running_instance_it_reads_the_hosts_scheduling(hal,
                                                             realtime):
    """The threads start as the instance's did: realtime when the host
    got it (its start returned no note)."""
    hal.newthread("servo", 1_000_000)
    note = hal.start(realtime)
    got = realtime and note is None
    test = LatencyTest(hal, setups(0, 1_000_000, bins=10))
    test.start()
    try:
        assert test.realtime is got
        assert "SCHED_FIFO" in test.note
        assert ("non-realtime" in test.note) == (not got)
    finally:
        test.stop()


# ---------------------------------------------------------------- refusals

def test_a_stopped_instance_with_threads_is_refused(hal):
    hal.newthread("servo", 1_000_000)
    before = names(hal)
    with pytest.raises(LatencyError, match="would start 'servo'"):
        LatencyTest(hal).start()
    assert names(hal) == before
    assert not hal.info()["threads_running"]


def test_a_loaded_timedelta_is_refused(hal):
    hal.loadrt("timedelta", names="mine")
    with pytest.raises(LatencyError, match="'timedelta' is already loaded"):
        LatencyTest(hal).start()
    assert names(hal)["components"] == ["timedelta"]
    assert names(hal)["threads"] == []


@pytest.mark.parametrize("level", [1, 2, 4, 8, 255])
def test_a_locked_instance_refuses_and_nothing_is_left(hal, level):
    before = user_machine(hal)
    hal.lock(level)
    try:
        with pytest.raises(LatencyError, match="cannot start: .*lock"):
            LatencyTest(hal).start()
        assert names(hal) == before
    finally:
        hal.unlock()


# ---------------------------------------------------------------- attached

ATTACHED = """
import json, sys, time
from halsdk.hal import Hal
from halsdk.tools.latency import LatencyTest, LatencyError, setups
with Hal(create=False) as hal:
    test = LatencyTest(hal, setups(50_000, 1_000_000, bins=50))
    try:
        test.start()
    except LatencyError as exc:
        print(json.dumps({"error": str(exc)}))
        sys.exit(0)
    time.sleep(0.3)
    data = test.figures(read=True)
    test.stop()
    print(json.dumps(data))
"""


def _attached() -> dict:
    # cwd: not the checkout, whose unbuilt halsdk "python -c" would find
    # before the installed one
    proc = subprocess.run([sys.executable, "-c", ATTACHED],
                          capture_output=True, text=True, timeout=120,
                          env=dict(os.environ), cwd=tempfile.gettempdir())
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_an_attached_process_runs_the_test(hal):
    """loadrt, newthread, addf and start go to the host: they work from
    an attached process (the web server is one)."""
    before = user_machine(hal)
    data = _attached()
    assert [t["thread"] for t in data["threads"]] == ["latency-base",
                                                      "latency-servo"]
    for t in data["threads"]:
        assert t["samples"] == t["histogram"]["total"] > 0
        assert t["min"] <= t["avg"] <= t["max"]
    assert names(hal) == before


def test_an_attached_process_is_refused_by_the_lock(hal):
    before = user_machine(hal)
    hal.lock(hal.LOCK_LOAD)
    try:
        data = _attached()
    finally:
        hal.unlock()
    assert "cannot start" in data["error"] and "lock" in data["error"]
    assert names(hal) == before
