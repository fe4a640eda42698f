#!/usr/bin/env python3
"""Task channels: status poll, command round trip and task CPU, side by side.

Ours (``halsdk run``) and LinuxCNC 2.9's (``milltask``), in one run.

Two parts, in one run of the script:

1. **Channel costs** (ours only, no task running): a private HAL instance
   holds the status channel's block (``task.channel``) and this process
   publishes a full snapshot as the task makes it (every field of
   :mod:`halsdk.channels.statusfields` set, 3 joint dicts, 9 axes, one
   spindle, a tool table of 20 tools).  Timed (µs per call, best and
   median of ``--repeat`` batches): ``StatusWriter.publish``,
   ``StatusReader.poll`` in this process and in another one while this one
   publishes every 10 ms, poll plus three fields, poll plus ``as_dict``,
   ``ErrorReader.poll`` with nothing waiting, ``post`` of a message.

2. **A running task** and a client in another process (the *driver*):

   * ours: ``halsdk run mill.ini`` (``examples/mill``, realtime threads)
     with ``[TASK]CYCLE_TIME`` 0.010 (its default) and 0.001 (an INI copy),
     each on a private ``HALSDK_INSTANCE``.  The client uses the compat
     ``linuxcnc`` module (``halsdk.compat.pythonpath()``) when it imports
     and works, the native classes otherwise (``StatusReader.poll``,
     ``CommandClient.send`` + ``wait``); the table says which.
   * the reference: its ``linuxcnc`` launcher with a copy of its sample
     configuration ``sim/axis/axis_mm.ini`` (HAL files ``core_sim.hal`` and
     ``simulated_home.hal`` from its hallib, no halui, no spindle encoder
     nor manual tool changer) whose ``[DISPLAY]DISPLAY`` is this script in
     driver mode, run by the project's ``reference`` tool (as an
     unprivileged user, on a copy of the folder; the driver writes its
     figures beside itself and the tool copies them back).  Its
     ``[TASK]CYCLE_TIME`` is 0.001 as shipped, and 0.010 as a second run.

   The driver turns the machine on (E-stop reset, on), then measures:

   * **poll**: ``stat.poll()`` (native: ``StatusReader.poll()``) of the
     full snapshot, each call timed alone (``--polls`` calls): median,
     p99, and the mean of a loop of as many; then poll plus three fields
     (``task_state``, ``position``, ``joint[0]``), as a display reads them;
   * **round trip**: a command sent and its done echo seen, at a random
     moment of the task cycle (a random pause of up to one cycle before
     each), ``--trips`` of each of: ``mode`` (MDI and manual in turn),
     ``feedrate`` (0.5 and 1.0 in turn) and ``state`` (off and on in
     turn); median, p99, max.  Three figures per command: the client's
     send + wait for done (``c.mode(m)``, ``c.wait_complete()``; native:
     ``send`` + ``wait``), the send call alone, and when a *watcher*
     process, looking at the status every 200 µs, saw the done echo
     (``echo_serial_number`` the command's, ``state`` RCS_DONE) after the
     send began.  The reference's ``linuxcnc`` module waits in steps of
     about 10 ms (in the send call, until the task has taken the command,
     and in ``wait_complete``), so its first figure is mostly the module's
     sleeping; the watcher's is the task's own latency;
   * **task CPU**: user + system time of the task over ``--cpu-seconds``
     (``/proc/PID/task/*/schedstat``, ns; ``/proc/PID/stat`` utime+stime
     as a cross-check), idle, with ``--clients`` client processes each
     polling the full status at ``--rate`` Hz, and idle again (the idle
     figure is the mean of the two idle windows; their difference is the
     noise).  The reference's task is the ``milltask`` process (motion
     runs in ``rtapi_app``); ours is the task thread of the ``halsdk run``
     process (the thread that waits in ``epoll_wait``: the command socket),
     and the whole process (servo thread included) is printed too;
   * **servo thread's longest cycle** (``servo-thread.tmax``, reset before
     each phase and read after it with the side's own ``halcmd``; the
     reference's CPU clocks converted with the clock of /proc/cpuinfo):
     what the task and its clients do to the realtime thread.

Goals (issue 17): poll at most 20 µs; round trip in realtime mode at most
one task cycle + 1 ms; 10 clients at 100 Hz cost the task less than 1 % of
a core.  Only one reference HAL runs on a machine: the script takes the
lock that the tests take.

Run: ``python bench/task.py [--quick] [--no-reference] [--polls 20000]
[--trips 100] [--cpu-seconds 5] [--clients 10] [--rate 100]``.
"""

# The driver and client modes of this file run under the reference's
# Python too (inside its session, ``import linuxcnc``): everything at the
# top level is the standard library; halsdk is imported where ours run.

from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import threading
import time
from typing import Any, Callable, Optional

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = "task-results.json"
REFERENCE_LINUXCNC = "/usr/bin/linuxcnc"
REFERENCE_CONFIGS = "/usr/share/doc/linuxcnc/examples/sample-configs/sim"
RCS_DONE, RCS_EXEC, RCS_ERROR = 1, 2, 3
STATE_ESTOP_RESET, STATE_OFF, STATE_ON = 2, 3, 4
MODE_MANUAL, MODE_MDI = 1, 3
#: the round-trip commands: (name, the two argument values taken in turn)
TRIPS = (("mode", (MODE_MDI, MODE_MANUAL)),
         ("feedrate", (0.5, 1.0)),
         ("state", (STATE_OFF, STATE_ON)))
#: keyword of the native client for each command's one argument
NATIVE_ARG = {"mode": "mode", "feedrate": "scale", "state": "state"}
#: the watcher's pause between two looks at the status
WATCH_S = 200e-6


# ====================================================== driver side
# (stdlib only: runs under the reference's python3 too)

def summary(values: list[float]) -> dict[str, float]:
    v = sorted(values)
    if not v:
        return {"n": 0}
    p99 = v[min(len(v) - 1, max(0, -(-len(v) * 99 // 100) - 1))]
    return {"n": len(v), "median": statistics.median(v), "p99": p99,
            "max": v[-1], "min": v[0], "mean": statistics.fmean(v)}


class RefClient:
    """The reference's ``linuxcnc`` module, or ours (compat): the same
    calls."""

    sent = 0.0                          # s, the last send call
    serial = 0                          # of the last command

    def __init__(self) -> None:
        import linuxcnc  # type: ignore[import-not-found]  # either one
        self.mod = linuxcnc
        self.s = linuxcnc.stat()
        self.c = linuxcnc.command()
        where = getattr(linuxcnc, "__file__", "") or ""
        self.where = "compat linuxcnc" if "halsdk" in where else "linuxcnc"

    def ready(self) -> bool:
        self.s.poll()
        return self.s.task_state in (1, 2, 3, 4)

    def poll(self) -> None:
        self.s.poll()

    def poll_fields(self) -> None:
        s = self.s
        s.poll()
        s.task_state, s.position, s.joint[0]        # noqa: B018

    def command(self, name: str, value: Any) -> int:
        t0 = time.perf_counter()
        getattr(self.c, name)(value)
        self.sent = time.perf_counter() - t0
        self.serial = self.c.serial
        return self.c.wait_complete(5.0)

    def echo(self) -> tuple[int, int]:
        """(echo_serial_number, state) of a new poll."""
        s = self.s
        s.poll()
        return s.echo_serial_number, s.state


class NativeClient:
    """Ours: ``StatusReader`` and ``CommandClient``."""

    sent = 0.0                          # s, the last send call
    serial = 0                          # of the last command

    def __init__(self) -> None:
        import halsdk
        from halsdk.channels.cmdclient import CommandClient
        from halsdk.channels.shmchannel import BLOCK_NAME, StatusReader
        self.hal = halsdk.Hal(create=False)
        self.reader = StatusReader(*self.hal.shared_block(BLOCK_NAME))
        self.client = CommandClient(self.hal.private_socket_path("task"),
                                    name="bench")
        self.where = "native"

    def ready(self) -> bool:
        return self.reader.poll().task_state in (1, 2, 3, 4)

    def poll(self) -> None:
        self.reader.poll()

    def poll_fields(self) -> None:
        s = self.reader.poll()
        s.task_state, s.position, s.joint[0]        # noqa: B018

    def command(self, name: str, value: Any) -> int:
        t0 = time.perf_counter()
        serial = self.client.send(name, **{NATIVE_ARG[name]: value})
        self.sent = time.perf_counter() - t0
        self.serial = serial
        return self.client.wait(serial, 5.0)[0]

    def echo(self) -> tuple[int, int]:
        s = self.reader.poll()
        return s.echo_serial_number, s.state


def connect(kind: str, seconds: float = 90.0) -> Any:
    """The client of ``kind`` once the task answers (it may still be
    starting)."""
    deadline = time.monotonic() + seconds
    while True:
        try:
            client = NativeClient() if kind == "native" else RefClient()
            if client.ready():
                return client
        except Exception:
            if time.monotonic() > deadline:
                raise
        if time.monotonic() > deadline:
            raise RuntimeError("the task did not come up")
        time.sleep(0.2)


def time_polls(client: Any, n: int) -> dict[str, Any]:
    poll, clock = client.poll, time.perf_counter_ns
    for _ in range(min(n, 500)):
        poll()
    each = []
    for _ in range(n):
        t0 = clock()
        poll()
        each.append((clock() - t0) / 1000)
    t0 = clock()
    for _ in range(n):
        poll()
    out: dict[str, Any] = dict(summary(each))
    out["batch_mean"] = (clock() - t0) / 1000 / n
    fields, each = client.poll_fields, []
    for _ in range(max(1, n // 4)):
        t0 = clock()
        fields()
        each.append((clock() - t0) / 1000)
    out["fields"] = summary(each)
    return out


def watch_main(kind: str) -> None:
    """The watcher: polls the status every WATCH_S until SIGTERM, then
    prints every change of (echo_serial_number, state) with its time
    (``perf_counter``: CLOCK_MONOTONIC, the same in every process)."""
    import signal
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    client = connect(kind, 30)
    echo, clock = client.echo, time.perf_counter
    last = echo()
    seen = [(clock(), *last)]
    print("ready", flush=True)
    while not stop:
        now = echo()
        if now != last:
            seen.append((clock(), *now))
            last = now
        time.sleep(WATCH_S)
    print(json.dumps(seen), flush=True)


def time_trips(client: Any, kind: str, trips: int, cycle: float
               ) -> dict[str, Any]:
    """``trips`` round trips of each command of TRIPS, timed by the
    client (send, then wait for done with the client's API) and by a
    watcher process that sees the done echo on the status channel."""
    rnd = random.Random(17)
    watcher = subprocess.Popen(
        [sys.executable, os.path.abspath(__file__), "--watch", kind],
        stdout=subprocess.PIPE, text=True)
    assert watcher.stdout is not None
    watcher.stdout.readline()           # "ready"
    done: dict[str, list[tuple[int, float, float, float]]] = {
        name: [] for name, _ in TRIPS}
    failed: dict[str, int] = {name: 0 for name, _ in TRIPS}
    for i in range(trips):
        for name, values in TRIPS:
            time.sleep(rnd.uniform(0, cycle))
            t0 = time.perf_counter()
            state = client.command(name, values[i % 2])
            t1 = time.perf_counter()
            done[name].append((client.serial, t0, t1, client.sent))
            if state != RCS_DONE:
                failed[name] += 1
    time.sleep(0.05)
    watcher.send_signal(15)
    seen = json.loads(watcher.communicate(timeout=60)[0].splitlines()[-1])
    out: dict[str, Any] = {}
    for name, _ in TRIPS:
        watched, missed = [], 0
        for serial, t0, _t1, _sent in done[name]:
            t = next((t for t, echo, st in seen if t >= t0 and (
                echo > serial or (echo == serial and st in (
                    RCS_DONE, RCS_ERROR)))), None)
            if t is None:
                missed += 1
            else:
                watched.append((t - t0) * 1000)
        out[name] = dict(summary([(t1 - t0) * 1000
                                  for _, t0, t1, _ in done[name]]))
        out[name]["not_done"] = failed[name]
        out[name]["send"] = summary([s * 1000 for *_, s in done[name]])
        out[name]["watched"] = dict(summary(watched))
        out[name]["watched"]["missed"] = missed
    client.command("feedrate", 1.0)
    return out


# ------------------------------------------------------------ servo

def cpu_mhz() -> Optional[float]:
    """The CPU clock of /proc/cpuinfo: the reference's thread times are
    in CPU clocks (time-stamp counter), ours in ns."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("cpu MHz"):
                    return float(line.split(":")[1])
    except (OSError, ValueError):
        pass
    return None


class ServoMax:
    """The servo thread's longest cycle (``servo-thread.tmax``), reset
    and read with the side's own halcmd."""

    def __init__(self, reference: bool) -> None:
        self.halcmd = "/usr/bin/halcmd" if reference else os.path.join(
            os.path.dirname(sys.executable), "halcmd")
        self.scale = 1000.0 / (cpu_mhz() or 1000.0) if reference else 1.0

    def reset(self) -> None:
        subprocess.run([self.halcmd, "setp", "servo-thread.tmax", "0"],
                       capture_output=True, timeout=30)

    def read_us(self) -> Optional[float]:
        """µs since the last reset, None when it cannot be read."""
        p = subprocess.run([self.halcmd, "getp", "servo-thread.tmax"],
                           capture_output=True, text=True, timeout=30)
        try:
            return int(p.stdout.split()[-1]) * self.scale / 1000
        except (ValueError, IndexError):
            return None


# ------------------------------------------------------------ CPU

TICK = os.sysconf("SC_CLK_TCK")


def thread_ns(pid: int, tid: int) -> int:
    with open(f"/proc/{pid}/task/{tid}/schedstat") as f:
        return int(f.read().split()[0])


def threads_of(pid: int) -> list[int]:
    return [int(t) for t in os.listdir(f"/proc/{pid}/task")]


def cpu_sample(pid: int, tid: Optional[int]) -> dict[str, float]:
    """CPU seconds so far: the process (all its threads; schedstat ns and
    stat ticks) and thread ``tid`` (when given)."""
    total = 0
    for t in threads_of(pid):
        try:
            total += thread_ns(pid, t)
        except OSError:
            pass                        # ended meanwhile
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    out = {"proc": total / 1e9,
           "proc_ticks": (int(fields[11]) + int(fields[12])) / TICK,
           "t": time.monotonic()}
    if tid is not None:
        out["thread"] = thread_ns(pid, tid) / 1e9
        with open(f"/proc/{pid}/task/{tid}/stat") as f:
            tf = f.read().rsplit(")", 1)[1].split()
        out["thread_ticks"] = (int(tf[11]) + int(tf[12])) / TICK
    return out


def cpu_window(pid: int, tid: Optional[int], seconds: float
               ) -> dict[str, float]:
    """% of a core over ``seconds``, per key of cpu_sample."""
    a = cpu_sample(pid, tid)
    time.sleep(seconds)
    b = cpu_sample(pid, tid)
    wall = b["t"] - a["t"]
    return {k: (b[k] - a[k]) / wall * 100 for k in a if k != "t"}


def epoll_thread(pid: int, looks: int = 100) -> Optional[int]:
    """Ours: the task thread, the one found waiting in epoll_wait (the
    command socket's selector) most often."""
    seen: dict[int, int] = {}
    for _ in range(looks):
        for t in threads_of(pid):
            try:
                with open(f"/proc/{pid}/task/{t}/wchan") as f:
                    if "epoll" in f.read():
                        seen[t] = seen.get(t, 0) + 1
            except OSError:
                pass
        time.sleep(0.005)
    return max(seen, key=seen.__getitem__) if seen else None


def milltask_pid(folder: str) -> Optional[int]:
    """The reference's task process started with an INI file of
    ``folder``."""
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/comm") as f:
                if f.read().strip() != "milltask":
                    continue
            with open(f"/proc/{name}/cmdline", "rb") as f:
                cmdline = f.read().replace(b"\0", b" ").decode()
        except OSError:
            continue
        if folder in cmdline or "axis_mm.ini" in cmdline:
            return int(name)
    return None


def run_clients(kind: str, n: int, rate: float, seconds: float
                ) -> list[subprocess.Popen]:
    cmd = [sys.executable, os.path.abspath(__file__), "--client", kind,
           "--rate", str(rate), "--seconds", str(seconds)]
    return [subprocess.Popen(cmd, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
            for _ in range(n)]


def client_main(kind: str, rate: float, seconds: float) -> None:
    """A polling client: the full status every 1/rate s for ``seconds``;
    prints its poll count and its CPU."""
    client = connect(kind, 30)
    period = 1.0 / rate
    polls = 0
    c0 = time.process_time()
    start = next_t = time.monotonic()
    while True:
        client.poll()
        polls += 1
        next_t += period
        now = time.monotonic()
        if now - start >= seconds:
            break
        if next_t > now:
            time.sleep(next_t - now)
    wall = time.monotonic() - start
    print(json.dumps({"polls": polls, "rate": polls / wall,
                      "cpu_pct": (time.process_time() - c0) / wall * 100}),
          flush=True)


def measure_cpu(kind: str, pid: int, tid: Optional[int], seconds: float,
                clients: int, rate: float, servo: ServoMax
                ) -> dict[str, Any]:
    """The task's CPU idle, with the clients, idle again (the idle
    figure is the mean of the two idle windows)."""
    servo.reset()
    idle = [cpu_window(pid, tid, seconds)]
    out: dict[str, Any] = {"servo_idle": servo.read_us()}
    warm = 1.5
    procs = run_clients(kind, clients, rate, warm + seconds + 0.5)
    time.sleep(warm)
    servo.reset()
    out["clients"] = cpu_window(pid, tid, seconds)
    out["servo_clients"] = servo.read_us()
    reports = []
    for p in procs:
        stdout, stderr = p.communicate(timeout=60)
        try:
            reports.append(json.loads(stdout.strip().splitlines()[-1]))
        except (ValueError, IndexError):
            out.setdefault("client_errors", []).append(stderr[-500:])
    time.sleep(0.5)
    idle.append(cpu_window(pid, tid, seconds))
    out["idle"] = {k: (idle[0][k] + idle[1][k]) / 2 for k in idle[0]}
    out["idle_windows"] = idle
    if reports:
        out["client_rate"] = statistics.fmean(r["rate"] for r in reports)
        out["client_cpu_pct"] = statistics.fmean(r["cpu_pct"]
                                                 for r in reports)
    out["clients_ok"] = len(reports)
    return out


def driver_main(a: argparse.Namespace) -> None:
    """Inside the reference's session (``--driver reference``) or beside
    ``halsdk run`` (``--driver ours``): measure, write the JSON."""
    out_path = a.out or os.path.join(HERE, RESULTS)
    res: dict[str, Any] = {"cycle": a.cycle}
    try:
        if a.driver == "reference":
            kind = "linuxcnc"
        else:
            kind = a.api
        client = connect(kind)
        res["api"] = client.where
        client.command("state", STATE_ESTOP_RESET)
        client.command("state", STATE_ON)
        client.command("mode", MODE_MANUAL)
        servo = ServoMax(a.driver == "reference")
        res["poll"] = time_polls(client, a.polls)
        servo.reset()
        res["trips"] = time_trips(client, kind, a.trips, a.cycle)
        res["servo_trips"] = servo.read_us()
        if a.driver == "reference":
            pid, tid = milltask_pid(os.path.dirname(os.path.abspath(
                a.ini or "."))), None
        else:
            pid = a.host_pid
            tid = epoll_thread(pid)
        res["pid"], res["tid"] = pid, tid
        if pid:
            res["cpu"] = measure_cpu(kind, pid, tid, a.cpu_seconds,
                                     a.clients, a.rate, servo)
        client.command("state", STATE_OFF)
    except Exception as e:              # reported by the main process
        import traceback
        res["error"] = f"{type(e).__name__}: {e}\n{traceback.format_exc()}"
    with open(out_path, "w") as f:
        json.dump(res, f)


# ====================================================== main side

def _ours_api() -> str:
    """``linuxcnc`` (our compat module) when it imports and offers the
    calls the driver makes, else ``native``."""
    try:
        import halsdk.compat
        path = halsdk.compat.pythonpath()
        if not os.path.exists(os.path.join(path, "linuxcnc.py")):
            return "native"
        probe = ("import linuxcnc as l; l.stat; l.command; "
                 "l.command.wait_complete; l.command.mode")
        env = dict(os.environ, PYTHONPATH=path)
        ok = subprocess.run([sys.executable, "-c", probe], env=env,
                            capture_output=True, timeout=60).returncode == 0
        return "linuxcnc" if ok else "native"
    except (ImportError, OSError, subprocess.SubprocessError):
        return "native"


def driver_args(a: argparse.Namespace, cycle: float) -> list[str]:
    return ["--polls", str(a.polls), "--trips", str(a.trips),
            "--cycle", str(cycle), "--cpu-seconds", str(a.cpu_seconds),
            "--clients", str(a.clients), "--rate", str(a.rate)]


def run_ours(a: argparse.Namespace, cycle: float, api: str
             ) -> dict[str, Any]:
    """``halsdk run`` of a copy of examples/mill with
    ``[TASK]CYCLE_TIME`` = ``cycle``, and the driver beside it."""
    import tempfile

    from benchlib import REPO, run_folder, session
    mill = os.path.join(REPO, "examples", "mill")
    files = {}
    for name in os.listdir(mill):
        with open(os.path.join(mill, name), encoding="utf-8") as f:
            files[name] = f.read()
    files["bench.ini"] = (f"[TASK]\nCYCLE_TIME = {cycle}\n\n"
                          + files["mill.ini"])
    instance = f"benchtask-{os.getpid()}-{int(cycle * 1e4)}"
    env = dict(os.environ, HALSDK_INSTANCE=instance)
    if api == "linuxcnc":
        import halsdk.compat
        env["PYTHONPATH"] = os.pathsep.join(
            [halsdk.compat.pythonpath()]
            + [p for p in [os.environ.get("PYTHONPATH")] if p])
    with run_folder("halsdk-bench-task-", files) as folder, \
            tempfile.TemporaryFile("w+") as log, \
            session([sys.executable, "-m", "halsdk.machine.cli", "run",
                     "bench.ini"], cwd=folder, env=env, stdout=log,
                    stderr=subprocess.STDOUT) as host:
        out = os.path.join(folder, RESULTS)
        cmd = [sys.executable, os.path.abspath(__file__), "--driver", "ours",
               "--api", api, "--host-pid", str(host.pid), "--out", out]
        subprocess.run(cmd + driver_args(a, cycle), env=env, timeout=600,
                       check=False)
        alive = host.poll() is None
        if alive:
            host.send_signal(15)
            try:
                host.wait(timeout=20)
            except subprocess.TimeoutExpired:
                pass
        log.seek(0)
        text = log.read()
        try:
            with open(out) as f:
                res = json.load(f)
        except (OSError, ValueError):
            res = {"error": "the driver wrote no results"}
        if "error" in res or not alive:
            res["host_log"] = text[-3000:]
        return res


def reference_ini(cycle: float, display: str) -> str:
    """The reference's sample axis_mm.ini with our driver as its display,
    ``cycle`` as [TASK]CYCLE_TIME, no halui, no spindle encoder nor manual
    tool changer (core_sim.hal loops the tool change)."""
    with open(os.path.join(REFERENCE_CONFIGS, "axis", "axis_mm.ini")) as f:
        lines = f.read().splitlines()
    out, section = [], ""
    for line in lines:
        s = line.strip()
        if s.startswith("["):
            section = s
        key = s.split("=", 1)[0].strip() if "=" in s else ""
        if section == "[DISPLAY]" and key == "DISPLAY":
            line = f"DISPLAY = {display}"
        elif section == "[TASK]" and key == "CYCLE_TIME":
            line = f"CYCLE_TIME = {cycle}"
        elif section == "[HAL]" and key == "HALUI":
            continue
        elif section == "[HAL]" and key == "HALFILE" and s.split("=", 1)[
                1].strip() in ("sim_spindle_encoder.hal",
                               "axis_manualtoolchange.hal"):
            continue
        out.append(line)
    return "\n".join(out) + "\n"


def run_reference(a: argparse.Namespace, cycle: float) -> dict[str, Any]:
    import tempfile

    from benchlib import REFERENCE_TOOL, reference_lock, run_folder, session
    display = "./task.py --driver reference " + " ".join(driver_args(a,
                                                                      cycle))
    with open(os.path.join(REFERENCE_CONFIGS, "sim_mm.tbl")) as f:
        table = f.read()
    files = {"axis_mm.ini": reference_ini(cycle, display),
             "sim_mm.tbl": table}
    with open(os.path.abspath(__file__)) as f:
        files["task.py"] = f.read()
    with reference_lock(), \
            run_folder("halsdk-bench-reftask-", files) as folder, \
            tempfile.TemporaryFile("w+") as log:
        os.chmod(os.path.join(folder, "task.py"), 0o755)
        with session([REFERENCE_TOOL, "linuxcnc", "axis_mm.ini"],
                     cwd=folder, stdout=log,
                     stderr=subprocess.STDOUT) as proc:
            try:
                proc.wait(timeout=600)
            except subprocess.TimeoutExpired:
                pass
        log.seek(0)
        text = log.read()
        try:
            with open(os.path.join(folder, RESULTS)) as f:
                res = json.load(f)
        except (OSError, ValueError):
            res = {"error": "the driver wrote no results"}
        if "error" in res:
            res["host_log"] = text[-3000:]
        return res


# ------------------------------------------------------------ part 1

def full_snapshot(joints: int) -> dict[str, Any]:
    """Every status field set, as the task publishes it."""
    from halsdk.channels.statusfields import FIELDS
    snap: dict[str, Any] = {}
    for name, kind, count in FIELDS:
        if kind == "s":
            snap[name] = f"/home/user/machines/mill/{name}.ngc"
        elif count == 1:
            snap[name] = {"i": 3, "b": True, "d": 1.25}[kind]
        else:
            snap[name] = tuple({"i": i, "b": i % 2 == 0, "d": i * 0.5}[kind]
                               for i in range(count))
    snap["joint"] = [{"jointType": 1, "units": 1.0, "backlash": 0.0,
                      "min_position_limit": -254.0,
                      "max_position_limit": 254.0, "max_ferror": 1.27,
                      "min_ferror": 0.254, "ferror_current": 0.0,
                      "ferror_highmark": 0.01, "output": 12.5, "input": 12.5,
                      "velocity": 0.0, "inpos": 1, "homing": 0, "homed": 1,
                      "fault": 0, "enabled": 1, "min_soft_limit": 0,
                      "max_soft_limit": 0, "min_hard_limit": 0,
                      "max_hard_limit": 0, "override_limits": 0}
                     for _ in range(joints)]
    snap["axis"] = [{"velocity": 0.0, "min_position_limit": -254.0,
                     "max_position_limit": 254.0} for _ in range(9)]
    snap["spindle"] = [{"brake": 1, "direction": 0, "enabled": 0,
                        "override_enabled": True, "speed": 0.0,
                        "override": 1.0, "homed": False, "orient_state": 0,
                        "orient_fault": 0}]
    return snap


def per_call(fn: Callable[[], Any], calls: int, repeat: int
             ) -> tuple[float, float]:
    """(best, median) µs per call over ``repeat`` batches of ``calls``."""
    fn()
    batches = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        batches.append((time.perf_counter() - t0) / calls * 1e6)
    return min(batches), statistics.median(batches)


def poll_cases(reader: Any, calls: int, repeat: int
               ) -> dict[str, tuple[float, float]]:
    def fields() -> None:
        s = reader.poll()
        s.task_state, s.position, s.joint[0]        # noqa: B018
    return {
        "poll": per_call(reader.poll, calls, repeat),
        "poll + 3 fields": per_call(fields, calls, repeat),
        "poll + as_dict": per_call(lambda: reader.poll().as_dict(),
                                   max(1, calls // 20), repeat),
    }


def channel_child(calls: int, repeat: int) -> None:
    """Part 1's reader in another process: prints its figures as JSON."""
    import halsdk
    from halsdk.channels.shmchannel import BLOCK_NAME, StatusReader
    hal = halsdk.Hal(create=False)
    reader = StatusReader(*hal.shared_block(BLOCK_NAME))
    out = poll_cases(reader, calls, repeat)
    print(json.dumps({k: list(v) for k, v in out.items()}), flush=True)
    hal.close()


def channel_costs(calls: int, repeat: int) -> dict[str, tuple[float, float]]:
    import halsdk
    from halsdk.channels.shmchannel import (
        BLOCK_NAME,
        ErrorReader,
        StatusReader,
        StatusWriter,
        block_size,
    )
    name = f"benchtaskch-{os.getpid()}"
    rows: dict[str, tuple[float, float]] = {}
    with halsdk.Hal(name, create=True, size=16 * 1024 * 1024) as hal:
        comp = hal.new_component("benchtask")
        addr, size = hal.new_shared_block(BLOCK_NAME, block_size(), comp)
        writer = StatusWriter(addr, size, os.getpid())
        snap = full_snapshot(3)
        writer.publish(snap)
        writer.publish_tools(1, [
            {"id": i, "zoffset": i * 0.1, "diameter": i * 0.5, "pocket": i,
             "comment": f"tool {i}"} for i in range(1, 21)])
        reader, errors = StatusReader(addr, size), ErrorReader(addr, size)
        rows["publish"] = per_call(lambda: writer.publish(snap), calls,
                                   repeat)
        same = poll_cases(reader, calls, repeat)
        rows["poll, same process"] = same.pop("poll")
        rows.update(same)
        rows["error poll (empty)"] = per_call(errors.poll, calls, repeat)

        def post() -> None:
            writer.post(11, "Linear move on line 4 would exceed X's "
                        "positive limit")
            errors.poll()
        rows["post (+ its error poll)"] = per_call(post, calls, repeat)
        stop = threading.Event()

        def publisher() -> None:        # as the task: every 10 ms
            while not stop.wait(0.010):
                writer.publish(snap)
        pub = threading.Thread(target=publisher, daemon=True)
        pub.start()
        try:
            proc = subprocess.run(
                [sys.executable, os.path.abspath(__file__), "--channel-child",
                 "--calls", str(calls), "--repeat", str(repeat)],
                env=dict(os.environ, HALSDK_INSTANCE=name),
                capture_output=True, text=True, timeout=600)
        finally:
            stop.set()
            pub.join()
        if proc.returncode == 0:
            other = json.loads(proc.stdout.splitlines()[-1])
            rows["poll, other process"] = tuple(other["poll"])
            rows["poll + as_dict, other process"] = tuple(
                other["poll + as_dict"])
        else:
            print("the reader process failed:\n" + proc.stderr[-1500:],
                  file=sys.stderr)
        writer.close()
    return rows


# ------------------------------------------------------------ report

def _f(x: Optional[float], fmt: str = "{:.2f}") -> str:
    return "-" if x is None else fmt.format(x)


def _get(res: dict[str, Any], *keys: str) -> Optional[float]:
    cur: Any = res
    for k in keys:
        if not isinstance(cur, dict) or k not in cur:
            return None
        cur = cur[k]
    return cur


def _task_key(r: dict[str, Any]) -> str:
    """The CPU figure that is the task's: ours the task thread, the
    reference's the milltask process."""
    return "thread" if "thread" in r.get("cpu", {}).get("idle", {}) \
        else "proc"


def _clients_cost(r: dict[str, Any]) -> Optional[float]:
    key = _task_key(r)
    idle = _get(r, "cpu", "idle", key)
    busy = _get(r, "cpu", "clients", key)
    return None if idle is None or busy is None else busy - idle


def report(runs: list[tuple[str, dict[str, Any]]], clients: int,
           rate: float) -> None:
    w = 42
    heads = [label for label, _ in runs]
    cw = max(20, *(len(h) + 2 for h in heads))

    def row(label: str, cells: list[str]) -> None:
        print(f"{label:<{w}}" + "".join(f"{c:>{cw}}" for c in cells))

    def trip(s: Any) -> str:
        if not isinstance(s, dict) or not s.get("n"):
            return "-"
        return f"{s['median']:.2f}/{s['p99']:.2f}/{s['max']:.1f}"

    row("", heads)
    row("task cycle (ms)", [_f(r.get("cycle", 0) * 1000, "{:g}")
                            for _, r in runs])
    row("client API", [str(r.get("api", "-")) for _, r in runs])
    for k in ("median", "p99"):
        row(f"status poll µs, {k}", [_f(_get(r, "poll", k))
                                     for _, r in runs])
    row("status poll µs, mean of a loop",
        [_f(_get(r, "poll", "batch_mean")) for _, r in runs])
    for k in ("median", "p99"):
        row(f"poll + 3 fields µs, {k}",
            [_f(_get(r, "poll", "fields", k)) for _, r in runs])
    print(f"{'round trips, ms: median/p99/max':<{w}}")
    for name, _ in TRIPS:
        row(f"  {name}: send + wait for done",
            [trip(_get(r, "trips", name)) for _, r in runs])
        row("    of which the send call",
            [trip(_get(r, "trips", name, "send")) for _, r in runs])
        row("    done echo seen by a watcher",
            [trip(_get(r, "trips", name, "watched")) for _, r in runs])
    bad = [sum((_get(r, "trips", name, "not_done") or 0)
               + (_get(r, "trips", name, "watched", "missed") or 0)
               for name, _ in TRIPS) for _, r in runs]
    if any(bad):
        row("  commands not done or not seen done",
            [str(x) for x in bad])
    for key, label in (("thread", "task thread"), ("proc", "task process")):
        row(f"{label} CPU %, idle",
            [_f(_get(r, "cpu", "idle", key)) for _, r in runs])
        row("  the two idle windows (before/after)",
            ["/".join(_f(w.get(key)) for w in
                      r.get("cpu", {}).get("idle_windows", []))
             or "-" for _, r in runs])
        row("  cross-check: /proc stat utime+stime",
            [_f(_get(r, "cpu", "idle", key + "_ticks"), "{:.1f}")
             for _, r in runs])
        row(f"{label} CPU %, {clients} clients @{rate:g} Hz",
            [_f(_get(r, "cpu", "clients", key)) for _, r in runs])
    row("clients' cost to the task, % of a core",
        [_f(_clients_cost(r), "{:+.2f}") for _, r in runs])
    row("client poll rate achieved (Hz)",
        [_f(_get(r, "cpu", "client_rate"), "{:.1f}") for _, r in runs])
    row("one client's own CPU %",
        [_f(_get(r, "cpu", "client_cpu_pct")) for _, r in runs])
    print(f"{'servo thread longest cycle, µs':<{w}}")
    for key, label in (("servo_trips", "during the round trips"),
                       ("servo_idle", "idle window")):
        row(f"  {label}", [_f(_get(r, key) if key in r else
                              _get(r, "cpu", key), "{:.0f}")
                           for _, r in runs])
    row("  with the clients", [_f(_get(r, "cpu", "servo_clients"), "{:.0f}")
                               for _, r in runs])
    print("(task CPU: ours = the task thread of `halsdk run` and the whole "
          "process,\n servo thread included; the reference's = the "
          "milltask process, both rows)")
    for label, r in runs:
        if "error" in r:
            print(f"\n{label}: FAILED: {r['error']}")
            if r.get("host_log"):
                print(r["host_log"])
        for e in r.get("cpu", {}).get("client_errors", [])[:1]:
            print(f"\n{label}: a client failed: {e}")


def goals(runs: list[tuple[str, dict[str, Any]]]) -> None:
    print("\ngoals (ours):")
    for label, r in runs:
        if not label.startswith("ours") or "error" in r:
            continue
        poll = _get(r, "poll", "median")
        p99 = _get(r, "poll", "p99")
        if poll is not None:
            ok = poll <= 20
            print(f"  {label}: poll <= 20 µs: {'met' if ok else 'NOT met'} "
                  f"(median {poll:.2f}, p99 {p99:.2f} µs)")
        limit = r["cycle"] * 1000 + 1
        worst = [(name, _get(r, "trips", name, "max"),
                  _get(r, "trips", name, "p99")) for name, _ in TRIPS]
        worst = [(n, m, p) for n, m, p in worst if m is not None]
        if worst:
            ok_p99 = all(p <= limit for _, _, p in worst)
            ok_max = all(m <= limit for _, m, _ in worst)
            print(f"  {label}: round trip <= {limit:g} ms: "
                  f"{'met' if ok_p99 else 'NOT met'} at p99, "
                  f"{'met' if ok_max else 'NOT met'} at max ("
                  + ", ".join(f"{n} p99 {p:.2f} max {m:.1f}"
                              for n, m, p in worst) + ")")
        idle = _get(r, "cpu", "idle", "thread")
        busy = _get(r, "cpu", "clients", "thread")
        if idle is not None and busy is not None:
            d = busy - idle
            print(f"  {label}: clients' cost < 1 % of a core: "
                  f"{'met' if d < 1 else 'NOT met'} ({d:+.2f} %; the task "
                  f"thread idle costs {idle:.1f} % of a core)")


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true",
                   help="a short run (fewer calls, polls, trips; 2 s CPU "
                        "windows): about a minute and a half")
    p.add_argument("--repeat", type=int, default=5,
                   help="part 1: batches per figure (default 5)")
    p.add_argument("--calls", type=int, default=2000,
                   help="part 1: calls per batch (default 2000)")
    p.add_argument("--polls", type=int, default=20000,
                   help="polls timed one by one (default 20000)")
    p.add_argument("--trips", type=int, default=100,
                   help="round trips of each command (default 100)")
    p.add_argument("--cpu-seconds", type=float, default=5.0,
                   help="CPU window, idle and with clients (default 5)")
    p.add_argument("--clients", type=int, default=10,
                   help="polling client processes (default 10)")
    p.add_argument("--rate", type=float, default=100.0,
                   help="polls per second of each client (default 100)")
    p.add_argument("--cycles", default="0.010,0.001",
                   help="our [TASK]CYCLE_TIME values (default 0.010,0.001)")
    p.add_argument("--ref-cycles", default="0.001,0.010",
                   help="the reference's (default 0.001 as shipped, and "
                        "0.010)")
    p.add_argument("--no-reference", action="store_true",
                   help="do not run the LinuxCNC reference")
    p.add_argument("--api", choices=("auto", "native", "linuxcnc"),
                   default="auto",
                   help="our client: the compat linuxcnc module or the "
                        "native classes (default: compat when it works)")
    p.add_argument("--json", metavar="FILE",
                   help="also write every figure to FILE")
    # internal modes
    p.add_argument("--driver", choices=("ours", "reference"),
                   help=argparse.SUPPRESS)
    p.add_argument("--client", help=argparse.SUPPRESS)
    p.add_argument("--watch", help=argparse.SUPPRESS)
    p.add_argument("--channel-child", action="store_true",
                   help=argparse.SUPPRESS)
    p.add_argument("--host-pid", type=int, help=argparse.SUPPRESS)
    p.add_argument("--out", help=argparse.SUPPRESS)
    p.add_argument("--cycle", type=float, default=0.01,
                   help=argparse.SUPPRESS)
    p.add_argument("--seconds", type=float, default=5.0,
                   help=argparse.SUPPRESS)
    p.add_argument("-ini", help=argparse.SUPPRESS)   # the launcher's
    a = p.parse_args(argv)
    if a.driver:
        driver_main(a)
        return 0
    if a.client:
        client_main(a.client, a.rate, a.seconds)
        return 0
    if a.watch:
        watch_main(a.watch)
        return 0
    if a.channel_child:
        channel_child(a.calls, a.repeat)
        return 0
    if a.quick:
        a.calls, a.repeat = 500, 3
        a.polls, a.trips, a.cpu_seconds = 3000, 40, 2.0

    sys.path.insert(0, HERE)
    from benchlib import REFERENCE_TOOL
    t_start = time.monotonic()
    rows = channel_costs(a.calls, a.repeat)
    print(f"1. status channel, no task (µs per call, best / median of "
          f"{a.repeat} batches of {a.calls})")
    for label, (best, median) in rows.items():
        print(f"   {label:34} {best:8.2f} {median:8.2f}")

    api = _ours_api() if a.api == "auto" else a.api
    runs: list[tuple[str, dict[str, Any]]] = []
    for c in [float(x) for x in a.cycles.split(",") if x]:
        runs.append((f"ours {c * 1000:g} ms", run_ours(a, c, api)))
    use_ref = not a.no_reference and os.path.exists(REFERENCE_LINUXCNC)
    if use_ref and not os.access(REFERENCE_TOOL, os.X_OK):
        print(f"reference tool {REFERENCE_TOOL} not found", file=sys.stderr)
        use_ref = False
    if use_ref:
        for c in [float(x) for x in a.ref_cycles.split(",") if x]:
            runs.append((f"ref {c * 1000:g} ms", run_reference(a, c)))
    print(f"\n2. a running task, a client in another process ("
          f"{a.polls} polls, {a.trips} round trips of each command, "
          f"{a.cpu_seconds:g} s CPU windows)")
    if not use_ref:
        why = "disabled (--no-reference)" if a.no_reference else \
            f"not installed ({REFERENCE_LINUXCNC} missing)"
        print(f"reference (LinuxCNC 2.9): {why}; ours only")
    report(runs, a.clients, a.rate)
    goals(runs)
    print(f"\n(whole run {time.monotonic() - t_start:.0f} s)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"channel": rows, "runs": dict(runs)}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
