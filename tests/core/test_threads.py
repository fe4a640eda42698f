"""Threads: deterministic stepping with exact simulated time, and realtime
pthreads (SCHED_FIFO when allowed, else normal scheduling with a note)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
import time

import pytest

import halsdk
from halsdk.core import _core


def lowpass(hal, period=1_000_000, tau=0.01):
    hal.loadrt("tlowpass")
    hal.newthread("servo", period)
    hal.addf("tlowpass.0", "servo")
    hal.setp("tlowpass.0.tau", tau)


# ---------------------------------------------------------------- stepping

def test_stepping_is_exact(hal):
    lowpass(hal)
    hal.setp("tlowpass.0.in", 1.0)
    trace = hal.run(50, record=["tlowpass.0.out", "tlowpass.0.now"])
    k = 1.0 - math.exp(-1e-3 / 0.01)
    expected = [1.0 - (1.0 - k) ** (n + 1) for n in range(50)]
    assert list(trace["tlowpass.0.out"]) == pytest.approx(expected, abs=1e-15)
    # the function saw rtapi_get_time() = exact simulated time
    assert list(trace["tlowpass.0.now"]) == [1_000_000 * (n + 1)
                                             for n in range(50)]
    assert list(trace.time) == list(trace["tlowpass.0.now"])
    assert hal.thread("servo").cycles == 50
    assert hal.time == 50_000_000


def test_stepping_is_repeatable(hal):
    lowpass(hal)
    runs = []
    for _ in range(2):
        hal.setp("tlowpass.0.in", 0.0)
        hal.step(5)
        trace = hal.run(30, inputs={"tlowpass.0.in": [math.sin(n / 3)
                                                      for n in range(30)]},
                        record=["tlowpass.0.out"])
        runs.append(trace["tlowpass.0.out"])
        hal.setp("tlowpass.0.in", 0.0)
        hal.setp("tlowpass.0.tau", 0)   # tau 0 passes the input: reset
        hal.step(1)
        hal.setp("tlowpass.0.tau", 0.01)
    assert list(runs[0]) == list(runs[1])


def test_multirate_order_and_counts(hal):
    calls = []
    hal.newthread("base", 250_000)
    hal.newthread("servo", 1_000_000)
    hal.add_python_function("fast", lambda p: calls.append(("fast", p,
                                                            hal.time)),
                            "base")
    hal.add_python_function("slow", lambda p: calls.append(("slow", p,
                                                            hal.time)),
                            "servo")
    hal.step(8)                          # 8 periods of the fastest thread
    assert [c[0] for c in calls].count("fast") == 8
    assert [c[0] for c in calls].count("slow") == 2
    # at equal times the faster thread runs first
    assert calls[3][0] == "fast" and calls[4][0] == "slow"
    assert calls[4][2] == 1_000_000 and calls[3][2] == 1_000_000
    assert {c[1] for c in calls if c[0] == "fast"} == {250_000}
    assert {c[1] for c in calls if c[0] == "slow"} == {1_000_000}
    hal.step(4, thread="servo")          # one thread only
    assert [c[0] for c in calls].count("slow") == 6
    assert hal.thread("base").cycles == 8


def test_addf_positions(hal):
    calls = []
    hal.newthread("t", 1_000_000)
    for name in ("a", "b", "c", "d"):
        hal.add_python_function(name, lambda p, n=name: calls.append(n))
    hal.addf("a", "t")
    hal.addf("b", "t")
    hal.addf("c", "t", 1)               # first
    hal.addf("d", "t", -2)              # before the last
    assert hal.thread("t").functions == ["c", "a", "d", "b"]
    hal.step(1)
    assert calls == ["c", "a", "d", "b"]
    hal.add_python_function("e", lambda p: None)
    with pytest.raises(halsdk.InvalidError, match="position"):
        hal.addf("e", "t", 9)
    for huge in (2**31, -2**31 - 1, 10**20):    # no C int: no overflow
        with pytest.raises(halsdk.InvalidError, match="out of range"):
            hal.addf("e", "t", huge)
    assert hal.function("e").users == 0
    hal.delf("a", "t")
    assert hal.thread("t").functions == ["c", "d", "b"]
    with pytest.raises(halsdk.NotFoundError, match="not in thread"):
        hal.delf("a", "t")


def test_function_rules(hal):
    hal.loadrt("tand2", count=2)
    hal.loadrt("tlowpass")
    hal.newthread("nofp", 1_000_000, fp=False)
    hal.newthread("fp", 1_000_000)
    with pytest.raises(halsdk.InvalidError, match="needs FP"):
        hal.addf("tlowpass.0", "nofp")
    hal.addf("tand2.0", "nofp")
    with pytest.raises(halsdk.InvalidError, match="only be added to one"):
        hal.addf("tand2.0", "fp")
    assert hal.function("tand2.0").users == 1
    assert not hal.function("tand2.0").uses_fp
    assert hal.function("tlowpass.0").uses_fp
    with pytest.raises(halsdk.NotFoundError, match="function 'nope'"):
        hal.addf("nope", "fp")
    with pytest.raises(halsdk.NotFoundError, match="thread 'nope'"):
        hal.addf("tand2.1", "nope")
    with pytest.raises(halsdk.ExistsError, match="thread name 'fp'"):
        hal.newthread("fp", 1_000_000)
    with pytest.raises(halsdk.InvalidError, match="period"):
        hal.newthread("tiny", 10)
    bad, report = _core.check_consistency()
    assert bad == 0, report


def test_thread_and_function_timing(hal):
    hal.loadrt("tand2")
    hal.newthread("every", 1_000_000, timing_every=1)
    hal.addf("tand2.0", "every")
    fn = hal.function("tand2.0")
    assert (fn.time, fn.tmax) == (0, 0)
    hal.step(10)
    th = hal.thread("every")
    assert th.time > 0 and th.tmax >= th.time
    assert fn.tmax > 0
    assert hal.getp("every.tmax") == th.tmax
    assert hal.pin("tand2.0.time").value == fn.time
    # tmax is writable (to reset it), as in the reference
    hal.setp("tand2.0.tmax", 0)
    hal.step(1)
    assert hal.getp("tand2.0.tmax") > 0


def test_sampled_function_timing(hal):
    hal.loadrt("tand2")
    hal.newthread("t", 1_000_000, timing_every=5)
    hal.addf("tand2.0", "t")
    hal.step(1)                 # the first cycle is timed
    hal.setp("tand2.0.tmax", 0)
    hal.step(4)                 # cycles 2..5 are not
    assert hal.getp("tand2.0.tmax") == 0
    assert hal.thread("t").tmax > 0      # the thread is timed every cycle
    hal.step(1)                 # cycle 6 is
    assert hal.getp("tand2.0.tmax") > 0


def test_python_function_is_marked_not_realtime(hal):
    hal.loadrt("tand2")
    hal.newthread("t", 1_000_000)
    hal.add_python_function("py.fn", lambda p: None, "t")
    assert not hal.function("py.fn").realtime
    assert hal.function("tand2.0").realtime


def test_python_function_errors_are_reported_once(hal, capfd):
    hal.newthread("t", 1_000_000)

    def broken(period):
        raise RuntimeError("boom")

    hal.add_python_function("bad", broken, "t")
    hal.step(3)
    err = capfd.readouterr().err
    assert err.count("RuntimeError: boom") == 1 and "'bad'" in err
    assert _core.python_funct_errors("bad") == 3


# ---------------------------------------------------------------- realtime

def test_realtime_threads_run_and_stop(hal):
    hal.loadrt("tand2")
    hal.newthread("servo", 1_000_000)
    hal.addf("tand2.0", "servo")
    hal.setp("tand2.0.in0", 1)
    hal.setp("tand2.0.in1", 1)
    hal.start()
    assert hal.thread("servo").running
    deadline = time.monotonic() + 5
    while hal.thread("servo").cycles < 100 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert hal.getp("tand2.0.out") is True
    hal.stop()
    assert not hal.thread("servo").running
    cycles = hal.thread("servo").cycles
    assert cycles >= 100
    time.sleep(0.05)
    assert hal.thread("servo").cycles == cycles     # really stopped
    assert hal.thread("servo").tmax > 0
    assert not hal.info()["simulated_clock"]


def _run_with_a_stall(hal, stall_s: float, at: int, total: int):
    """Run a 1 ms thread whose function sleeps stall_s in its call number
    `at`; return the call times (ns) and the thread's overruns."""
    calls: list[int] = []

    def fn(period: int) -> None:
        calls.append(time.monotonic_ns())
        if len(calls) == at:
            time.sleep(stall_s)

    hal.newthread("servo", 1_000_000)
    hal.add_python_function("stall.fn", fn, "servo")
    hal.start()
    try:
        deadline = time.monotonic() + 30
        while len(calls) < total and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        hal.stop()
    assert len(calls) >= total
    return calls, hal.thread("servo").overruns


def _lag(calls: list[int], k: int) -> float:
    """How many periods call k came after it was due (call 0 on time)."""
    return (calls[k] - calls[0]) / 1e6 - k


def test_missed_cycles_run_back_to_back(hal):
    """A cycle that runs long costs no cycles: the ones that fell due
    meanwhile run at once, back to back, and count as overruns (a
    stepgen then makes every step it was asked for)."""
    calls, overruns = _run_with_a_stall(hal, 0.03, at=20, total=150)
    # right after the 30 ms stall the missed cycles run back to back
    burst = [(calls[k + 1] - calls[k]) / 1e6 for k in range(20, 40)]
    assert sorted(burst)[10] < 0.5
    # then the thread is on schedule again: no cycle was lost (a lost
    # cycle would leave every later call about a period later than due)
    assert min(_lag(calls, k) for k in range(100, len(calls))) < 5
    assert overruns >= 20


def test_a_long_stall_drops_its_cycles(hal):
    """Past 100 ms behind (a stopped process, a debugger) the missed
    cycles are dropped, not run in a burst; they count as overruns."""
    calls, overruns = _run_with_a_stall(hal, 0.25, at=10, total=60)
    after = calls[10]
    burst = sum(1 for t in calls[11:] if t - after < 10_000_000)
    assert burst < 50                   # not the 250 missed cycles
    assert min(_lag(calls, k) for k in range(11, len(calls))) > 200
    assert overruns >= 240


def test_stepping_refused_while_running(hal):
    hal.newthread("servo", 1_000_000)
    hal.start()
    try:
        with pytest.raises(halsdk.ConflictError, match="running"):
            hal.step(1)
    finally:
        hal.stop()
    hal.step(1)
    assert hal.info()["simulated_clock"]


def test_addf_delf_while_running(hal):
    hal.loadrt("tcounter", names="c0,c1")
    hal.newthread("servo", 200_000)
    hal.addf("c0", "servo")
    hal.start()
    try:
        for _ in range(200):
            hal.addf("c1", "servo")
            hal.delf("c1", "servo")
        hal.addf("c1", "servo")
        deadline = time.monotonic() + 5
        while hal.getp("c1.cycles") < 20 and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        hal.stop()
    assert hal.getp("c1.cycles") >= 20
    assert hal.getp("c0.cycles") >= hal.getp("c1.cycles")
    # unloading the module while its functions are in a thread is safe
    hal.start()
    hal.unloadrt("tcounter")
    hal.stop()
    assert hal.thread("servo").functions == []


def test_non_realtime_note_without_permission(tmp_path):
    """A process that may not use SCHED_FIFO runs normally, with a note."""
    script = textwrap.dedent("""
        import ctypes, os, resource, sys, time
        # drop CAP_SYS_NICE (23) and CAP_IPC_LOCK (14); RTPRIO limit 0
        libc = ctypes.CDLL(None, use_errno=True)
        hdr = (ctypes.c_uint32 * 2)(0x20080522, 0)
        data = (ctypes.c_uint32 * 6)()
        assert libc.capget(hdr, data) == 0
        for k in (0, 1):                      # effective, permitted
            data[k] &= ~((1 << 23) | (1 << 14))
        assert libc.capset(hdr, data) == 0, ctypes.get_errno()
        resource.setrlimit(resource.RLIMIT_RTPRIO, (0, 0))
        import halsdk
        with halsdk.Hal(f"note-{os.getpid()}", create=True,
                        size=1 << 22) as h:
            h.newthread("t", 1_000_000)
            note = h.start()
            time.sleep(0.1)
            h.stop()
            print("NOTE:", note)
            print("CYCLES:", h.thread("t").cycles)
    """)
    env = dict(os.environ)
    env.pop("HALSDK_INSTANCE", None)
    src = os.path.dirname(os.path.dirname(halsdk.__file__))
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    proc = subprocess.run([sys.executable, "-c", script], env=env,
                          capture_output=True, text=True, timeout=60,
                          cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "Using POSIX non-realtime" in proc.stderr
    assert proc.stderr.count("non-realtime") == 1
    assert "NOTE: Note: Using POSIX non-realtime" in proc.stdout
    cycles = int(proc.stdout.split("CYCLES:")[1])
    assert cycles > 10


def test_no_deadlock_between_gil_mutex_and_python_functions(tmp_path):
    """Deleting a thread that runs a Python function, while other Python
    threads keep taking the instance mutex, must not deadlock: nobody
    waits for the mutex with the GIL held."""
    script = textwrap.dedent("""
        import os, threading, time, halsdk
        from halsdk.core import _core
        h = halsdk.Hal(f"dl-{os.getpid()}", create=True, size=1 << 22)
        stop = False
        def busy():
            while not stop:
                _core.find("signal", "nothing")
                c = halsdk.component("churn")
                c.exit()
        churn = threading.Thread(target=busy, daemon=True)
        churn.start()
        for k in range(40):
            h.newthread("t", 200_000)
            h.add_python_function(f"f{k}", lambda p: None, thread="t")
            h.start(False)
            time.sleep(0.005)
            h.delthread("t")
        stop = True
        # the churn ends before the instance goes: closing it under a
        # thread still in a call is not guarded (Hal.close says so)
        churn.join(10)
        print("done")
        h.close()
    """)
    env = dict(os.environ)
    env.pop("HALSDK_INSTANCE", None)
    src = os.path.dirname(os.path.dirname(halsdk.__file__))
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    proc = subprocess.run([sys.executable, "-c", script], env=env,
                          capture_output=True, text=True, timeout=120,
                          cwd=tmp_path)     # not the source tree
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "done"


def test_thread_made_while_running_starts_at_once(hal):
    hal.newthread("first", 1_000_000)
    hal.start()
    try:
        hal.newthread("late", 500_000)
        hal.add_python_function("late.fn", lambda p: None, "late")
        assert hal.thread("late").running
        deadline = time.monotonic() + 5
        while hal.thread("late").cycles < 20 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert hal.thread("late").cycles >= 20
    finally:
        hal.stop()
    assert not hal.thread("late").running


@pytest.mark.parametrize("nfuncts", [1, 2, 3, 6, 17])
def test_delthread_of_a_thread_with_many_functions(hal, nfuncts):
    """Deleting a thread drops its whole function list; the bounded walk
    of that list must not take the shrinking count for damage."""
    hal.newthread("busy", 1_000_000)
    hal.loadrt("and2", count=nfuncts)
    for k in range(nfuncts):
        hal.addf(f"and2.{k}", "busy")
    hal.delthread("busy")
    assert hal.threads() == []
    assert all(f.users == 0 for f in hal.functions())
    hal.check()
