"""How fast a dead process is noticed (issue 19, DESIGN.md section 11).

Four latencies, each over ``--repeat`` runs (default 50), in private HAL
instances:

- **host SIGKILL -> loadusr program ends**: ``halrun -f x.hal`` starts a
  Python ``hal.component()`` program with ``loadusr -Wn``; halrun is
  SIGKILLed and the time until the program has ended is measured by a
  pidfd (the program gets SIGTERM from PR_SET_PDEATHSIG and from its own
  pidfd watch of the host, whichever comes first);
- **host SIGKILL -> program of an attached halcmd ends**: the same for a
  program that ``halcmd loadusr`` in another process started (not a child
  of the host: only its pidfd watch of the host ends it);
- **host SIGKILL -> watch fires**: a process that only attaches and calls
  ``Hal.end_with_host()``, with SIGTERM's default action: the detection
  itself (pidfd wake-up, the line on stderr, SIGTERM) without the
  program's own cleanup and Python's exit, which the two figures above
  include;
- **component SIGKILL -> marked dead**: this process hosts an instance, a
  child process owns a userspace component with an out pin linked to a
  signal; the child is SIGKILLed (0.3 s after the component appeared: the
  host's watch takes a new component up within 0.1 s) and the time until
  ``Component.dead`` (and the signal at zero) is measured, polling every
  0.5 ms.

Figures: median, 95th percentile and maximum, in milliseconds.  The
design asks for less than 100 ms.

    python bench/liveness.py [--repeat N]
"""

from __future__ import annotations

import argparse
import os
import select
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMP_PY = """\
import os, sys, time
import hal
h = hal.component(sys.argv[1])
h.newpin("enable", hal.HAL_BIT, hal.HAL_OUT)
h["enable"] = True
h.ready()
with open(sys.argv[2] + ".tmp", "w") as f:
    f.write(str(os.getpid()))
os.rename(sys.argv[2] + ".tmp", sys.argv[2])
try:
    while True:
        time.sleep(0.05)
except KeyboardInterrupt:
    raise SystemExit(0)
"""


def tool(name: str) -> str:
    return os.path.join(os.path.dirname(sys.executable), name)


def read_pid(path: Path, timeout: float = 30.0) -> int:
    deadline = time.monotonic() + timeout
    while not path.exists():
        if time.monotonic() > deadline:
            raise SystemExit(f"liveness: {path} was not written")
        time.sleep(0.005)
    return int(path.read_text())


def ended_after(fds: list[int], t0: float, timeout: float = 10.0
                ) -> list[float]:
    """Seconds from t0 until each pidfd of ``fds`` is readable (its
    process ended), all watched at once."""
    poller = select.poll()
    for fd in fds:
        poller.register(fd, select.POLLIN)
    when: dict[int, float] = {}
    while len(when) < len(fds):
        left = timeout - (time.monotonic() - t0)
        if left <= 0:
            raise SystemExit("liveness: a program did not end within 10 s")
        for fd, _ev in poller.poll(left * 1000):
            if fd not in when:
                when[fd] = time.monotonic() - t0
                poller.unregister(fd)
    return [when[fd] for fd in fds]


WATCHER = """\
import signal, sys, halsdk
hal = halsdk.Hal(create=False)
hal.end_with_host("watcher")
signal.signal(signal.SIGTERM, signal.SIG_DFL)
print("ready", flush=True)
sys.stdin.read()
"""


def host_run(folder: Path, n: int) -> tuple[float, float, float]:
    """One halrun; returns the three host-death latencies (s)."""
    env = dict(os.environ, HALSDK_INSTANCE=f"bench-live-{os.getpid()}-{n}")
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env["PATH"]
    script = folder / "comp.py"
    script.write_text(COMP_PY)
    pid1, pid2 = folder / f"a{n}.pid", folder / f"b{n}.pid"
    (folder / "x.hal").write_text(
        f"loadusr -Wn child{n} {sys.executable} {script} child{n} {pid1}\n"
        "loadusr -w sleep 120\n")
    host = subprocess.Popen([tool("halrun"), "-f", "x.hal"], cwd=folder,
                            env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        a = read_pid(pid1)
        subprocess.run([tool("halcmd"), "loadusr", "-Wn", f"other{n}",
                        sys.executable, str(script), f"other{n}",
                        str(pid2)], cwd=folder, env=env,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       check=True, timeout=60)
        b = read_pid(pid2)
        watcher = subprocess.Popen([sys.executable, "-c", WATCHER],
                                   cwd=folder, env=env,
                                   stdin=subprocess.PIPE,
                                   stdout=subprocess.PIPE,
                                   stderr=subprocess.DEVNULL, text=True)
        assert watcher.stdout is not None
        if watcher.stdout.readline() != "ready\n":
            raise SystemExit("liveness: the watcher did not start")
        fa, fb = os.pidfd_open(a), os.pidfd_open(b)
        fc = os.pidfd_open(watcher.pid)
        try:
            t0 = time.monotonic()
            host.kill()
            la, lb, lc = ended_after([fa, fb, fc], t0)
        finally:
            os.close(fa)
            os.close(fb)
            os.close(fc)
            if watcher.poll() is None:
                watcher.kill()
            watcher.wait()
    finally:
        if host.poll() is None:
            host.kill()
        host.wait()
        subprocess.run([tool("halrun"), "-U"], env=env, cwd=folder,
                       capture_output=True, timeout=60)
    return la, lb, lc


def comp_runs(repeat: int) -> list[float]:
    """Component SIGKILL -> marked dead, with this process as host."""
    import halsdk
    os.environ["HALSDK_INSTANCE"] = f"bench-dead-{os.getpid()}"
    code = ("import sys, halsdk\nc = halsdk.component(sys.argv[1])\n"
            "c.newpin('on', 'bit', 'out')\nc['on'] = True\nc.ready()\n"
            "print('ready', flush=True)\nsys.stdin.read()\n")
    out = []
    with halsdk.Hal() as hal:
        for n in range(repeat):
            name = f"victim{n}"
            child = subprocess.Popen([sys.executable, "-c", code, name],
                                     stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True)
            assert child.stdout is not None
            if child.stdout.readline() != "ready\n":
                raise SystemExit("liveness: the component did not start")
            hal.net(f"on{n}", f"{name}.on")
            comp = hal.find("component", name)
            # the host's watch takes up a new component within 0.1 s
            time.sleep(0.3)
            t0 = time.monotonic()
            child.kill()
            while not comp.dead:
                if time.monotonic() - t0 > 10:
                    raise SystemExit("liveness: not marked dead in 10 s")
                time.sleep(0.0005)
            out.append(time.monotonic() - t0)
            if hal.gets(f"on{n}") is not False:
                raise SystemExit("liveness: the signal was not reset")
            child.wait()
            hal.unload(name)
    return out


def show(what: str, values: list[float]) -> None:
    ms = sorted(v * 1000 for v in values)
    p95 = ms[min(len(ms) - 1, int(round(0.95 * (len(ms) - 1))))]
    print(f"{what:<48} median {statistics.median(ms):7.2f} ms   "
          f"p95 {p95:7.2f} ms   max {ms[-1]:7.2f} ms   (n={len(ms)})")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=50,
                   help="runs of each measurement (default 50)")
    args = p.parse_args()
    child, attached, bare = [], [], []
    with tempfile.TemporaryDirectory(prefix="halsdk-liveness-") as tmp:
        for n in range(args.repeat):
            la, lb, lc = host_run(Path(tmp), n)
            child.append(la)
            attached.append(lb)
            bare.append(lc)
    show("host SIGKILL -> loadusr program ends", child)
    show("host SIGKILL -> program of attached halcmd ends", attached)
    show("host SIGKILL -> watch fires (no cleanup)", bare)
    show("component SIGKILL -> marked dead, pins zero", comp_runs(args.repeat))


if __name__ == "__main__":
    main()
