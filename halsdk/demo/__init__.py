"""The halsdk demo: a PID loop closing on a simulated motor, in realtime.

Run it with ``python -m halsdk.demo`` (or ``halsdk-demo``).  It builds two
small Cython components (a PID controller and a DC-motor model; compiled
once, then cached), wires them in a 1 kHz servo thread, runs the machine
in real time for a few seconds while it steps the position command, and
prints what happened.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from typing import Optional

HERE = os.path.dirname(os.path.abspath(__file__))
MOVES = [(0.0, 1.0), (0.8, -0.5), (1.6, 0.25), (2.4, 0.0)]   # (s, target)


def build_components() -> str:
    """Compile the demo components into a folder for HALSDK_PATH."""
    from halsdk.build import build_component
    folder = os.path.join(tempfile.gettempdir(),
                          f"halsdk-demo-{os.getuid()}")
    for name in ("demopid", "demomotor"):
        build_component(os.path.join(HERE, name + ".pyx"), out_dir=folder)
    return folder


def wire(hal) -> None:
    """The machine: command -> PID -> motor voltage; encoder -> feedback."""
    hal.newthread("servo-thread", 1_000_000)
    hal.loadrt("demopid")
    hal.loadrt("demomotor")
    hal.addf("demomotor.0.update", "servo-thread")
    hal.addf("demopid.0.do-pid-calcs", "servo-thread")
    hal.newsig("position-cmd", "float")
    hal.net("position-cmd", "demopid.0.command")
    hal.net("position-fb", "demomotor.0.encoder", "demopid.0.feedback")
    hal.net("motor-voltage", "demopid.0.output", "demomotor.0.voltage")
    hal.net("following-error", "demopid.0.error")
    for name, value in {"Pgain": 60.0, "Igain": 400.0, "Dgain": 1.5,
                        "FF1": 0.05, "maxoutput": 12.0}.items():
        hal.setp(f"demopid.0.{name}", value)
    hal.setp("demopid.0.enable", True)


def run(seconds: float = 3.2, out=sys.stdout) -> dict:
    """Run the demo; returns the figures it printed."""
    import halsdk

    os.environ["HALSDK_PATH"] = build_components() + os.pathsep + \
        os.environ.get("HALSDK_PATH", "")
    instance = f"demo-{os.getpid()}"
    with halsdk.Hal(instance, create=True, size=8 << 20) as hal:
        wire(hal)
        note = hal.start()
        print(f"servo-thread: 1 kHz, "
              f"{'SCHED_FIFO realtime' if not note else 'normal scheduling'}"
              f"; PID on a simulated motor, {seconds:g} s", file=out)
        print(f"{'t [s]':>6} {'command':>8} {'position':>9} {'error':>9} "
              f"{'voltage':>8}", file=out)
        start = time.monotonic()
        moves = list(MOVES)
        settle: list[tuple[float, float]] = []
        worst_tail = 0.0
        next_print = 0.0
        while (now := time.monotonic() - start) < seconds:
            if moves and now >= moves[0][0]:
                if settle or moves[0][0] > 0:
                    settle.append((moves[0][0], hal.gets("following-error")))
                hal.sets("position-cmd", moves.pop(0)[1])
            if now >= next_print:
                print(f"{now:6.2f} {hal.gets('position-cmd'):8.3f} "
                      f"{hal.getp('demomotor.0.position'):9.4f} "
                      f"{hal.gets('following-error'):9.5f} "
                      f"{hal.gets('motor-voltage'):8.3f}", file=out)
                next_print += 0.2
            time.sleep(0.005)
        final_error = hal.gets("following-error")
        worst_tail = max(abs(e) for _, e in settle + [(0, final_error)])
        thread = hal.thread("servo-thread")
        figures = {
            "cycles": thread.cycles,
            "overruns": thread.overruns,
            "thread_tmax_us": thread.tmax / 1000,
            "pid_tmax_ns": hal.function("demopid.0.do-pid-calcs").tmax,
            "final_position": hal.getp("demomotor.0.position"),
            "final_error": final_error,
            "settled_error": worst_tail,
            "realtime": note is None,
        }
        hal.stop()
    print(f"\n{figures['cycles']} servo cycles in {seconds:g} s, "
          f"{figures['overruns']} overruns; thread max time "
          f"{figures['thread_tmax_us']:.1f} us, PID function max "
          f"{figures['pid_tmax_ns']} ns", file=out)
    print(f"largest error 0.8 s after each move: "
          f"{figures['settled_error']:.5f}; final position "
          f"{figures['final_position']:.4f} (command 0.0)", file=out)
    return figures


def main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="halsdk-demo",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3.2,
                        help="how long to run (default 3.2)")
    args = parser.parse_args(argv)
    run(args.seconds)
    return 0
