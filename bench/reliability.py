"""The reliability campaign: fuzzing and kill tests, counted.

    python bench/reliability.py                      # the whole campaign
    python bench/reliability.py --count 1000 --kills 20   # a short one
    python bench/reliability.py --kinds hal,gcode --kill-targets none

Fuzzing: for each kind of input (HAL files, ``.comp`` files, G-code, INI
files, driver configurations, task channel frames, shared-memory
corruption) ``--count`` inputs made by mutating the tree's own valid
files (bench/fuzzkinds.py, bench/segment_fuzz.py) go through the code a
user's input reaches.  Kill tests: ``--kills`` runs per target and signal
(SIGKILL, SIGSTOP) of a HAL session, each killing or stopping one process
at a random point (bench/killtests.py).

It prints, per kind, the counts of inputs, crashes (a process ended by a
signal it was not sent), tracebacks (an exception that is not the code's
documented error), hangs (no answer within the time limit) and leftovers
(segments, sockets or processes left behind), with the first few
findings of each, and with ``--markdown`` the table of
docs/reliability.md.  The exit status is 1 when any count but the inputs
is not zero.
"""

from __future__ import annotations

import argparse
import multiprocessing
import multiprocessing.connection
import os
import shutil
import sys
import time
import traceback
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Optional

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import fuzzkinds  # noqa: E402

#: an input that takes longer than this is a hang (the G-code runaway
#: guard ends a program after 5 s without a block)
HANG_SECONDS = 30.0
CHUNK = 200


@dataclass
class Tally:
    kind: str
    inputs: int = 0
    crashes: int = 0
    tracebacks: int = 0
    hangs: int = 0
    leftovers: int = 0
    seconds: float = 0.0
    findings: list[str] = field(default_factory=list)

    def note(self, what: str, detail: str) -> None:
        if len(self.findings) < 5:
            self.findings.append(f"{what}: {detail}")

    @property
    def bad(self) -> int:
        return self.crashes + self.tracebacks + self.hangs + self.leftovers


def _leftovers_of(pid: int) -> list[str]:
    """Instances a worker made (their names carry its pid) still in
    /dev/shm after it ended."""
    mark = f"-rel{pid}"
    return [n for n in os.listdir("/dev/shm") if n.endswith(mark)]


def _worker(kind_name: str, seed: int, start: int, stop: int,
            conn: multiprocessing.connection.Connection) -> None:
    """Run inputs start..stop-1 of a kind; tell the parent before and
    after each one, so that it can tell which input crashed or hung."""
    os.environ["HALSDK_INSTANCE"] = f"rel{os.getpid()}"
    # what the components and parsers print is not the campaign's output,
    # and a crash is counted by the parent (no faulthandler dump)
    import faulthandler
    faulthandler.disable()
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    kind = fuzzkinds.kinds()[kind_name]
    ws = fuzzkinds.new_workspace()
    try:
        if kind.setup:
            kind.setup(ws)
        for index in range(start, stop):
            text = fuzzkinds.make_input(kind, seed, index)
            conn.send(("start", index))
            try:
                kind.run(text, ws)
                conn.send(("ok", index, ""))
            except Exception as exc:
                tb = traceback.format_exception_only(type(exc), exc)
                conn.send(("traceback", index,
                           f"{type(exc).__name__}: {''.join(tb).strip()}"
                           [:300]))
    finally:
        shutil.rmtree(ws.folder, ignore_errors=True)
        hal = ws.state.get("hal")
        if hal is not None:
            hal.close()
        conn.send(("end", stop))


def fuzz(kind_name: str, count: int, seed: int, jobs: int) -> Tally:
    """Run ``count`` inputs of a kind in ``jobs`` worker processes,
    restarting a worker after the input that crashed or hung it."""
    tally = Tally(kind_name)
    ctx = multiprocessing.get_context("fork")
    todo = [(a, min(a + CHUNK, count)) for a in range(0, count, CHUNK)]
    running: dict[Any, tuple[Any, int, int, int, float]] = {}
    began = time.monotonic()

    def launch(start: int, stop: int) -> None:
        parent, child = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_worker, args=(kind_name, seed, start,
                                                 stop, child), daemon=True)
        proc.start()
        child.close()
        running[parent] = (proc, start, stop, start, time.monotonic())

    while todo or running:
        while todo and len(running) < jobs:
            launch(*todo.pop(0))
        ready = multiprocessing.connection.wait(list(running), timeout=1.0)
        now = time.monotonic()
        for conn in ready:
            proc, start, stop, current, since = running[conn]
            try:
                msg = conn.recv()
            except EOFError:
                proc.join(5)
                del running[conn]
                code = proc.exitcode
                tally.inputs += 1
                if code is not None and code < 0:
                    tally.crashes += 1
                    tally.note("crash", f"input {current} ended the worker "
                               f"with signal {-code}")
                else:
                    tally.tracebacks += 1
                    tally.note("traceback", f"input {current}: worker "
                               f"ended with status {code}")
                for name in _leftovers_of(proc.pid):
                    os.unlink("/dev/shm/" + name)
                if current + 1 < stop:
                    todo.insert(0, (current + 1, stop))
                continue
            if msg[0] == "start":
                running[conn] = (proc, start, stop, msg[1], now)
            elif msg[0] in ("ok", "traceback"):
                tally.inputs += 1
                if msg[0] == "traceback":
                    tally.tracebacks += 1
                    tally.note("traceback", f"input {msg[1]}: {msg[2]}")
                running[conn] = (proc, start, stop, msg[1] + 1, now)
            elif msg[0] == "end":
                proc.join(10)
                del running[conn]
                left = _leftovers_of(proc.pid)
                if proc.is_alive() or left:
                    tally.leftovers += 1
                    tally.note("leftover", f"worker of inputs {start}.."
                               f"{stop - 1}: {left or 'still running'}")
                    for name in left:
                        os.unlink("/dev/shm/" + name)
        for conn, (proc, _start, stop, current, since) in list(
                running.items()):
            if now - since > HANG_SECONDS:
                proc.kill()
                proc.join(5)
                del running[conn]
                tally.inputs += 1
                tally.hangs += 1
                tally.note("hang", f"input {current}: no answer in "
                           f"{HANG_SECONDS:.0f} s")
                for name in _leftovers_of(proc.pid):
                    os.unlink("/dev/shm/" + name)
                if current + 1 < stop:
                    todo.insert(0, (current + 1, stop))
    tally.seconds = time.monotonic() - began
    return tally


def _tally_of(kind: str, result: dict[str, Any]) -> Tally:
    """A Tally from the counts that segment_fuzz and killtests return."""
    return Tally(kind, result["inputs"], result["crashes"],
                 result["tracebacks"], result["hangs"], result["leftovers"],
                 result["seconds"], list(result.get("findings", []))[:5])


def _report(tally: Tally, unit: str) -> None:
    print(f"{tally.kind}: {tally.inputs} {unit}, {tally.crashes} crashes, "
          f"{tally.tracebacks} tracebacks, {tally.hangs} hangs, "
          f"{tally.leftovers} leftovers in {tally.seconds:.0f} s",
          flush=True)
    for finding in tally.findings:
        print(f"    {finding}", flush=True)


def _table(tallies: Sequence[Tally]) -> str:
    rows = ["| kind | inputs | crashes | tracebacks | hangs | leftovers "
            "| time |", "|---|---:|---:|---:|---:|---:|---:|"]
    for t in tallies:
        rows.append(f"| {t.kind} | {t.inputs:,} | {t.crashes} | "
                    f"{t.tracebacks} | {t.hangs} | {t.leftovers} | "
                    f"{t.seconds:.0f} s |")
    return "\n".join(rows)


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0] if __doc__ else None)
    p.add_argument("--count", type=int, default=100_000,
                   help="inputs per fuzzed kind (default 100000)")
    p.add_argument("--kills", type=int, default=1000,
                   help="kill tests per target and signal (default 1000)")
    p.add_argument("--kinds", default="hal,comp,gcode,ini,driver,channel,"
                   "shm", help="fuzzed kinds, comma separated, or none")
    p.add_argument("--kill-targets", default="host,component,halcmd,client",
                   help="kill test targets, comma separated, or none")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    p.add_argument("--markdown", action="store_true",
                   help="print the table of docs/reliability.md")
    args = p.parse_args(argv)
    tallies: list[Tally] = []
    names = [k for k in args.kinds.split(",") if k and k != "none"]
    known = set(fuzzkinds.kinds()) | {"shm"}
    for name in names:
        if name not in known:
            p.error(f"--kinds: unknown kind {name!r} "
                    f"(known: {', '.join(sorted(known))})")
    for name in names:
        if name == "shm":
            import segment_fuzz
            tally = _tally_of("shm", segment_fuzz.campaign(
                args.count, seed=args.seed, jobs=args.jobs))
        else:
            tally = fuzz(name, args.count, args.seed, args.jobs)
        tallies.append(tally)
        _report(tally, "inputs")
    targets = [t for t in args.kill_targets.split(",") if t and t != "none"]
    for target in targets:
        if target not in ("host", "component", "halcmd", "client"):
            p.error(f"--kill-targets: unknown target {target!r} (known: "
                    "host, component, halcmd, client)")
    if targets:
        import killtests
        for target in targets:
            for signame in ("SIGKILL", "SIGSTOP"):
                tally = _tally_of(
                    f"kill {target} ({signame})",
                    killtests.campaign(target, signame, args.kills,
                                       seed=args.seed, jobs=args.jobs))
                tallies.append(tally)
                _report(tally, "runs")
    if args.markdown:
        print()
        print(_table(tallies))
    return 1 if any(t.bad for t in tallies) else 0


if __name__ == "__main__":
    sys.exit(main())
