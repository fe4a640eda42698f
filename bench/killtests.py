"""Kill tests of the reliability campaign (bench/reliability.py).

One run starts a HAL session the way a user does, with the installed
programs:

* the host: ``halrun -I -f session.hal`` (threads running, realtime
  components, a userspace component started with ``loadusr -W``);
* the userspace component: a Python ``import hal`` program (the
  "component" target);
* with the "halcmd" target, a ``halcmd -f`` of a long command file that
  lists, sets, links and unlinks while it runs;
* with the "client" target, a Python program attached with
  ``halsdk.Hal(create=False)`` that lists and sets in a loop.

At a random point (0 to 300 ms after everything is up) it sends SIGKILL
or SIGSTOP to the target's process, then checks what a user expects:

* nobody else crashes (no process ends by SIGSEGV, SIGBUS, SIGABRT,
  SIGILL or SIGFPE) and nothing prints a traceback;
* nothing hangs: with a dead host every other program ends within
  HOST_GONE_SECONDS, and with a stopped host the userspace component
  does (it drives outputs from pins nobody updates); with any other
  target the session still answers
  ``halcmd show comp`` (a stopped holder of the lock gives an error
  after the lock timeout, not a wait for ever) and then ends normally
  when halrun's input closes (a stopped target is continued first);
* nothing is left: after the session (and ``halrun -U`` when the host
  was killed) no segment, socket or process of the run remains.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from typing import Any, Optional

#: what a dead host's programs get to notice it and end
HOST_GONE_SECONDS = 5.0
#: a command's longest honest wait: the lock timeout (5 s) and a margin
COMMAND_SECONDS = 20.0
CRASH_SIGNALS = {signal.SIGSEGV, signal.SIGBUS, signal.SIGABRT,
                 signal.SIGILL, signal.SIGFPE}

SESSION_HAL = """\
loadrt threads name1=servo period1=1000000
loadrt and2 count=2
loadrt siggen
addf siggen.0.update servo
addf and2.0 servo
addf and2.1 servo
net wave siggen.0.square
start
loadusr -Wn ucomp {python} {ucomp}
net wave => ucomp.in
net gate ucomp.out => and2.0.in0
"""

UCOMP = """\
import os
import time
import hal
c = hal.component("ucomp")
c.newpin("in", hal.HAL_FLOAT, hal.HAL_IN)
c.newpin("out", hal.HAL_BIT, hal.HAL_OUT)
c.newpin("count", hal.HAL_U32, hal.HAL_OUT)
c.ready()
c["count"] = 1
with open("ucomp.pid.tmp", "w") as f:     # the campaign waits for it
    f.write(str(os.getpid()))
os.rename("ucomp.pid.tmp", "ucomp.pid")
try:
    while True:
        c["out"] = c["in"] > 0
        c["count"] = (c["count"] + 1) & 0xffffffff
        time.sleep(0.002)
except KeyboardInterrupt:
    pass
"""

HALCMD_LOOP = """\
show pin
setp and2.1.in0 1
net t1 and2.1.out and2.1.in1
list sig
show comp
unlinkp and2.1.in1
delsig t1
getp and2.0.out
save
show thread
"""

CLIENT = """\
import halsdk
h = halsdk.Hal(create=False)
n = 0
while True:
    h.pins()
    h.signals()
    h.setp("and2.1.in0", n % 2 == 0)
    h.components()
    n += 1
"""


def _console(name: str) -> str:
    """The console script of the Python that runs the campaign."""
    return os.path.join(os.path.dirname(sys.executable), name)


class Run:
    """One session and its processes."""

    def __init__(self, folder: str, instance: str, target: str):
        self.folder = folder
        self.instance = instance
        self.target = target
        self.env = dict(os.environ, HALSDK_INSTANCE=instance)
        self.env.pop("PYTHONPATH", None)
        self.procs: dict[str, subprocess.Popen[str]] = {}
        self.findings: list[str] = []
        self.ucomp_pid: Optional[int] = None

    def path(self, name: str, text: str) -> str:
        p = os.path.join(self.folder, name)
        with open(p, "w") as f:
            f.write(text)
        return p

    def spawn(self, label: str, argv: list[str],
              stdin: Optional[int] = subprocess.DEVNULL) -> None:
        err = open(os.path.join(self.folder, f"{label}.err"), "w")
        self.procs[label] = subprocess.Popen(
            argv, cwd=self.folder, env=self.env, stdin=stdin,
            stdout=subprocess.DEVNULL, stderr=err, text=True)
        err.close()

    def start(self) -> bool:
        ucomp = self.path("ucomp.py", UCOMP)
        hal = self.path("session.hal", SESSION_HAL.format(
            python=sys.executable, ucomp=ucomp))
        self.spawn("host", [_console("halrun"), "-I", "-f", hal],
                   stdin=subprocess.PIPE)
        if not self._wait_for_component():
            code = self.procs["host"].poll()
            self.findings.append(
                "hang: the session did not come up (halrun "
                + ("still runs" if code is None else f"ended with {code}")
                + ")")
            return False
        self.ucomp_pid = self.component_pid()
        if self.target == "halcmd":
            cmds = self.path("loop.hal", HALCMD_LOOP * 200)
            self.spawn("halcmd", [_console("halcmd"), "-k", "-f", cmds])
        elif self.target == "client":
            self.spawn("client", [sys.executable,
                                  self.path("client.py", CLIENT)])
        return True

    def _wait_for_component(self) -> bool:
        """The component wrote its pid file (ready, counting); then the
        instance answers a halcmd (one program start, not a poll of
        them: the campaign's time goes to the tests, not to waiting)."""
        deadline = time.monotonic() + COMMAND_SECONDS
        pidfile = os.path.join(self.folder, "ucomp.pid")
        while not os.path.exists(pidfile):
            if self.procs["host"].poll() is not None or \
                    time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        r = self.halcmd("getp", "ucomp.count", timeout=COMMAND_SECONDS)
        return r is not None and r.returncode == 0 and \
            r.stdout.strip() not in ("", "0")

    def component_pid(self) -> Optional[int]:
        """The pid of the userspace component, from its pid file."""
        try:
            with open(os.path.join(self.folder, "ucomp.pid")) as f:
                return int(f.read())
        except (OSError, ValueError):
            return None

    def victim_pid(self) -> Optional[int]:
        if self.target == "host":
            return self.procs["host"].pid
        if self.target == "component":
            return self.ucomp_pid
        return self.procs[self.target].pid

    def wait_component_gone(self, seconds: float) -> None:
        """The userspace component (a child of halrun, not of the
        campaign) must end by itself when its host is gone."""
        pid = self.ucomp_pid
        deadline = time.monotonic() + seconds
        while pid is not None and _running(pid):
            if time.monotonic() > deadline:
                self.findings.append("hang: the userspace component "
                                     "outlives its host")
                os.kill(pid, signal.SIGKILL)
                return
            time.sleep(0.01)

    def halcmd(self, *args: str, timeout: float = COMMAND_SECONDS
               ) -> Optional[subprocess.CompletedProcess[str]]:
        """A halcmd command; None (and a finding) when it hangs."""
        try:
            r = subprocess.run([_console("halcmd"), *args], cwd=self.folder,
                               env=self.env, capture_output=True, text=True,
                               timeout=timeout)
        except subprocess.TimeoutExpired:
            self.findings.append(f"hang: halcmd {' '.join(args)}")
            return None
        self.check_output(f"halcmd {' '.join(args)}", r.returncode, r.stderr)
        return r

    def check_output(self, what: str, code: Optional[int],
                     stderr: str) -> None:
        if code is not None and code < 0 and -code in CRASH_SIGNALS:
            self.findings.append(f"crash: {what} died of signal {-code}")
        if "Traceback" in stderr:
            tail = stderr.strip().splitlines()[-1]
            self.findings.append(f"traceback: {what}: {tail}")

    def end_all(self, victim: str) -> None:
        """Wait for the session's processes to end; check each."""
        deadline = time.monotonic() + (HOST_GONE_SECONDS if victim == "host"
                                       else COMMAND_SECONDS)
        for label, proc in self.procs.items():
            try:
                proc.wait(max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                if label != victim:
                    self.findings.append(f"hang: {label} still runs")
                proc.kill()
                proc.wait()
            if label != victim:
                with open(os.path.join(self.folder, f"{label}.err")) as f:
                    self.check_output(label, proc.returncode, f.read())

    def leftovers(self) -> list[str]:
        name = f"halsdk-{os.getuid()}-{self.instance}"
        left = [n for n in os.listdir("/dev/shm") if n == name]
        for folder in _socket_folders():
            try:
                left += [n for n in os.listdir(folder)
                         if n.startswith(name + ".")]
            except OSError:
                pass
        return left


def _running(pid: int) -> bool:
    """Alive and not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False


def _socket_folders() -> list[str]:
    out = [f"/tmp/halsdk-{os.getuid()}"]
    xdg = os.environ.get("XDG_RUNTIME_DIR")
    if xdg:
        out.append(os.path.join(xdg, "halsdk"))
    return out


def one(target: str, signame: str, rng: random.Random,
        instance: str) -> list[str]:
    """One kill test; returns its findings ("crash: ...", "hang: ...",
    "traceback: ...", "leftover: ...")."""
    sig = getattr(signal, signame)
    with tempfile.TemporaryDirectory(prefix="halsdk-kill-") as folder:
        run = Run(folder, instance, target)
        try:
            if not run.start():
                return run.findings
            time.sleep(rng.uniform(0.0, 0.3))
            pid = run.victim_pid()
            if pid is None:
                run.findings.append("hang: the component's pid is unknown")
                return run.findings
            os.kill(pid, sig)
            stopped = sig == signal.SIGSTOP
            if target == "host" and not stopped:
                run.procs["host"].wait(5)
                run.end_all("host")
                run.wait_component_gone(HOST_GONE_SECONDS)
                # halrun -U (or the next host) tidies what a dead host left
                r = subprocess.run([_console("halrun"), "-U"], cwd=folder,
                                   env=run.env, capture_output=True,
                                   text=True, timeout=COMMAND_SECONDS)
                run.check_output("halrun -U", r.returncode, r.stderr)
            else:
                if target != "host":
                    run.halcmd("show", "comp")
                else:
                    # a stopped host: its userspace component ends as
                    # for a dead host; its clients get an answer or an
                    # error, never a wait for ever
                    run.wait_component_gone(HOST_GONE_SECONDS)
                    run.halcmd("show", "pin", "ucomp")
                if stopped:
                    os.kill(pid, signal.SIGCONT)
                victim = "" if stopped else target
                if target == "component" and not stopped:
                    victim = "component"
                host = run.procs["host"]
                if host.stdin is not None:
                    host.stdin.close()
                if target in ("halcmd", "client") and stopped:
                    run.procs[target].kill()
                    victim = target
                run.end_all(victim)
            left = run.leftovers()
            if left:
                run.findings.append(f"leftover: {', '.join(left)}")
        finally:
            if run.ucomp_pid is not None and _running(run.ucomp_pid):
                os.kill(run.ucomp_pid, signal.SIGKILL)
            for proc in run.procs.values():
                if proc.poll() is None:
                    try:
                        os.kill(proc.pid, signal.SIGCONT)
                    except ProcessLookupError:
                        pass
                    proc.kill()
                    proc.wait()
            if run.leftovers():     # tidy a run that went wrong
                subprocess.run([_console("halrun"), "-U"], cwd=folder,
                               env=run.env, capture_output=True, timeout=60)
        return run.findings


def campaign(target: str, signame: str, count: int, seed: int = 1,
             jobs: int = 1) -> dict[str, Any]:
    """``count`` kill tests of one target and signal, counted; ``jobs``
    sessions at a time (each has an instance of its own)."""
    from concurrent.futures import ThreadPoolExecutor

    def run_one(i: int) -> list[str]:
        rng = random.Random(f"{seed}-{target}-{signame}-{i}")
        return one(target, signame, rng,
                   f"kill{os.getpid()}-{target[:4]}-{signame[3:]}-{i}")

    result: dict[str, Any] = {"inputs": 0, "crashes": 0, "tracebacks": 0,
                              "hangs": 0, "leftovers": 0, "findings": []}
    began = time.monotonic()
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        outcomes = list(pool.map(run_one, range(count)))
    for i, findings in enumerate(outcomes):
        result["inputs"] += 1
        for finding in findings:
            kind = finding.split(":", 1)[0]
            key = {"crash": "crashes", "hang": "hangs",
                   "traceback": "tracebacks"}.get(kind, "leftovers")
            result[key] += 1
            if len(result["findings"]) < 5:
                result["findings"].append(f"run {i}: {finding}")
    result["seconds"] = time.monotonic() - began
    return result
