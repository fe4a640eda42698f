"""The halsdk demo: a simulated three-axis servo mill runs a short program.

Run it with ``halsdk-demo`` (or ``python -m halsdk.demo``).  It starts the
example machine ``halsdk/demo/mill`` (package data of ``halsdk.demo``) from
its INI file, turns it on, homes it, runs ``demo.ngc`` (two tool changes,
feed lines, an arc and a probe), prints a summary and writes a plot.

By default the servo thread is stepped (simulated time, deterministic);
``--realtime`` runs it on a real thread instead.
"""

from __future__ import annotations

import argparse
import io
import os
import shutil
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional, TextIO

from halsdk import console
from halsdk.atomicfile import write_atomic

if TYPE_CHECKING:
    from halsdk.ini import IniFile

__all__ = ["Summary", "machine_folder", "main", "run"]

JOINTS = 3
PLOT_EVERY = 10                 # keep one trace sample every N cycles


@dataclass
class Summary:
    """What the demo measured."""
    program_time: float = 0.0           #: demo.ngc: servo cycles x period
    cycles: int = 0                     #: servo cycles of the program
    max_ferror: list[float] = field(default_factory=list)  #: per joint
    ferror_limit: list[float] = field(default_factory=list)  #: FERROR
    homed: bool = False
    tool_changes: int = 0
    tool_in_spindle: int = 0
    probe_tripped: bool = False
    probe_work: tuple = ()              #: probed X Y Z, work coordinates
    probe_machine: tuple = ()           #: probed X Y Z, machine coordinates
    workpiece_top: float = 0.0          #: machine Z of the workpiece top
    errors: list[str] = field(default_factory=list)
    plot: Optional[str] = None          #: the PNG written, if any


def machine_folder() -> Path:
    """The folder of mill.ini: ``mill`` next to this file (package data
    of ``halsdk.demo``, the same in a checkout and installed)."""
    folder = Path(__file__).resolve().parent / "mill"
    if not (folder / "mill.ini").is_file():
        raise FileNotFoundError(f"the demo's machine is missing: no "
                                f"{folder / 'mill.ini'}")
    return folder


def _ini_number(ini: IniFile, section: str, key: str) -> float:
    """A number that the demo's INI file must give."""
    text = ini.get(section, key)
    if text is None:
        raise ValueError(f"the demo's machine is broken: {ini.path} has no "
                         f"[{section}]{key}")
    return float(text)


class _Recorder:
    """A Python HAL function run every servo cycle: the largest
    |joint.N.f-error| and a thinned-out trace (time, X, Y and the tool
    tip's Z, all from the feedback) of the tool path."""

    def __init__(self, hal: Any) -> None:
        self.hal = hal
        self.cycles = 0
        self.worst = [0.0] * JOINTS
        self.recording = False
        self.trace: list[tuple[float, float, float, float]] = []

    def __call__(self, period: int) -> None:
        self.cycles += 1
        if not self.recording:
            return
        getp = self.hal.getp
        for n in range(JOINTS):
            e = abs(getp(f"joint.{n}.f-error"))
            if e > self.worst[n]:
                self.worst[n] = e
        if self.cycles % PLOT_EVERY == 0:
            self.trace.append((self.cycles * period * 1e-9,
                               getp("joint.0.pos-fb"), getp("joint.1.pos-fb"),
                               getp("joint.2.pos-fb")
                               - getp("motion.tooloffset.z")))


def _write_plot(trace: list, path: str, summary: Summary,
                out: TextIO) -> Optional[str]:
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("note: matplotlib is not installed; no plot "
              "(pip install matplotlib)", file=out)
        return None
    if not trace:
        return None
    t0 = trace[0][0]
    ts = [s[0] - t0 for s in trace]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    ax1.plot([s[1] for s in trace], [s[2] for s in trace], lw=1)
    ax1.set_xlabel("X [mm]")
    ax1.set_ylabel("Y [mm]")
    ax1.set_title("tool path (machine XY)")
    ax1.set_aspect("equal", adjustable="datalim")
    ax2.plot(ts, [s[3] for s in trace], lw=1, label="tool tip")
    ax2.axhline(summary.workpiece_top, color="grey", ls="--",
                label="workpiece top")
    ax2.set_xlabel("program time [s]")
    ax2.set_ylabel("machine Z [mm]")
    ax2.set_title("tool tip Z over time (Z feedback - tool length)")
    ax2.legend(loc="best")
    fig.tight_layout()
    image = io.BytesIO()
    try:
        fig.savefig(image, format="png", dpi=100)
    finally:
        plt.close(fig)
    write_atomic(path, image.getvalue())
    return path


def _print_summary(s: Summary, out: TextIO) -> None:
    print("\nsummary", file=out)
    print(f"  homed:              {'yes' if s.homed else 'NO'}", file=out)
    print(f"  program time:       {s.program_time:.3f} s "
          f"({s.cycles} servo cycles)", file=out)
    for n, (e, lim) in enumerate(zip(s.max_ferror, s.ferror_limit)):
        print(f"  max following error joint {n} ({'XYZ'[n]}): "
              f"{e * 1000:7.3f} um (FERROR {lim:g} mm)", file=out)
    print(f"  tool changes:       {s.tool_changes} (tool in spindle: "
          f"T{s.tool_in_spindle})", file=out)
    if s.probe_tripped:
        x, y, z = s.probe_work
        print(f"  probe:              tripped at X{x:.4f} Y{y:.4f} Z{z:.4f} "
              f"(work; spindle at machine Z {s.probe_machine[2]:.4f})", file=out)
    else:
        print("  probe:              did not trip", file=out)
    print(f"  errors:             {len(s.errors) or 'none'}", file=out)
    for text in s.errors:
        print(f"    {text}", file=out)
    if s.plot:
        print(f"  plot:               {s.plot}", file=out)


def run(out_png: Optional[str] = "demo.png", realtime: bool = False,
        out: TextIO = sys.stdout) -> Summary:
    """Run the demo; returns its :class:`Summary` (also printed to
    ``out``).  ``out_png`` None: no plot."""
    from halsdk.machine import Machine, TaskMode, TaskState
    from halsdk.machine.launcher import Launcher

    folder = machine_folder()
    ini = folder / "mill.ini"
    summary = Summary()
    own_instance = "HALSDK_INSTANCE" not in os.environ
    if own_instance:
        os.environ["HALSDK_INSTANCE"] = f"halsdk-demo-{os.getpid()}"
    work = tempfile.mkdtemp(prefix="halsdk-demo-")
    launcher = Launcher(str(ini), out=out, err=out)
    try:
        # the machine writes its tool table back: work on a copy
        shutil.copy(folder / "tool.tbl", os.path.join(work, "tool.tbl"))
        launcher.start(realtime=realtime)
        hal = launcher.hal
        ini_file = launcher.ini
        summary.workpiece_top = _ini_number(ini_file, "SIM", "WORKPIECE_TOP")
        summary.ferror_limit = [_ini_number(ini_file, f"JOINT_{n}", "FERROR")
                                for n in range(JOINTS)]
        print(f"mill started from {ini} "
              f"({'real time' if realtime else 'stepped, simulated time'})",
              file=out)
        # the launcher made iocontrol.0 from [EMCIO]; its table is saved
        # to the copy, never to the shipped file
        launcher.io.table.path = os.path.join(work, "tool.tbl")
        machine = Machine.from_launcher(launcher)
        recorder = _Recorder(hal)
        hal.add_python_function("demo-recorder", recorder,
                                thread="servo-thread")

        machine.state(TaskState.ESTOP_RESET)
        machine.state(TaskState.ON)
        print("machine on; homing (Z first, then X and Y)", file=out)
        # the switches are far away (X travels about 200 mm): up to a
        # minute of machine time
        machine.home(timeout=60)
        summary.homed = all(machine.status().homed[:JOINTS])

        print("running demo.ngc", file=out)
        machine.mode(TaskMode.AUTO)
        machine.program_open(str(folder / "demo.ngc"))
        start = recorder.cycles
        recorder.recording = True
        machine.program_run()
        try:
            machine.wait_program(timeout=300)
        except Exception as e:            # reported in the summary
            summary.errors.append(str(e))
        recorder.recording = False
        period = (machine.motion.status().servo_period or 0.001)
        summary.cycles = recorder.cycles - start
        summary.program_time = summary.cycles * period
        summary.max_ferror = list(recorder.worst)
        st = machine.status()
        summary.tool_changes = st.tool_changes
        summary.tool_in_spindle = st.tool_in_spindle
        summary.probe_tripped = machine.params.get(5070) == 1
        summary.probe_work = tuple(machine.params.get(5061 + i)
                                   for i in range(3))
        summary.probe_machine = tuple(st.motion.probed_pos)[:3]
        summary.errors += [t for kind, t in machine.errors()
                           if kind == "error" and t not in summary.errors]
        if out_png:
            summary.plot = _write_plot(recorder.trace, out_png, summary, out)
        for function in ("demo-recorder", "iocontrol.0.poll"):
            hal.delf(function, "servo-thread")
        machine.io.close()
    finally:
        launcher.shutdown()
        shutil.rmtree(work, ignore_errors=True)
        if own_instance:
            os.environ.pop("HALSDK_INSTANCE", None)
    _print_summary(summary, out)
    return summary


def main(argv: Optional[list[str]] = None) -> int:
    """Console entry point: :func:`_main` under the broken-pipe rule
    of every halsdk program (:mod:`halsdk.console`)."""
    return console.run(_main, argv)


def _main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="halsdk-demo",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--realtime", action="store_true",
                        help="run the servo thread in real time (default: "
                        "stepped, simulated time)")
    parser.add_argument("--out", default="demo.png", metavar="FILE",
                        help="the plot to write (default demo.png)")
    args = parser.parse_args(argv)
    from halsdk.errors import HalError
    try:
        summary = run(args.out, realtime=args.realtime)
    except (HalError, OSError) as e:
        print(f"halsdk-demo: {e}", file=sys.stderr)
        return 1
    return 1 if summary.errors else 0
