"""The ``halsdk`` command: ``halsdk run machine.ini`` starts a machine,
``halsdk ctl ...`` operates it from another shell, ``halsdk runtests
DIR...`` runs HAL tests written in LinuxCNC's test-folder format,
``halsdk web [machine.ini]`` serves the HAL workbench in a browser
(starting the machine first when given its INI file), ``halsdk latency``
runs the latency test in a terminal."""

from __future__ import annotations

import argparse
import sys
from typing import Optional

from halsdk import console

#: ``halsdk --help``'s words: plain text (the docstring is reST)
_DESCRIPTION = """\
halsdk run machine.ini   starts a machine
halsdk ctl ...           operates it from another shell
halsdk runtests DIR...   runs HAL tests in LinuxCNC's test-folder format
halsdk web [machine.ini] serves the HAL workbench in a browser
halsdk latency           runs a latency test of this computer
halsdk rs274 prog.ngc    prints a G-code program's canonical commands
halsdk halrun|halcmd ... this halsdk's halrun and halcmd, whichever
                         halrun/halcmd comes first on PATH"""


def main(argv: Optional[list[str]] = None) -> int:
    """Console entry point: :func:`_main` under the broken-pipe rule
    of every halsdk program (:mod:`halsdk.console`)."""
    return console.run(_main, argv)


def _main(argv: Optional[list[str]] = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args and args[0] == "ctl":
        # its own parser: options before and after its commands
        from halsdk.machine.ctl import main as ctl_main
        return ctl_main(args[1:])
    if args and args[0] == "runtests":
        from halsdk.tools.runtests import main as runtests_main
        return runtests_main(args[1:])
    if args and args[0] == "web":
        from halsdk.web.server import main as web_main
        return web_main(args[1:])
    if args and args[0] == "latency":
        from halsdk.tools.latency_cli import main as latency_main
        return latency_main(args[1:])
    if args and args[0] == "rs274":
        from halsdk.gcode.rs274 import main as rs274_main
        return rs274_main(args[1:])
    if args and args[0] in ("halrun", "halcmd"):
        # this halsdk's, whichever halrun/halcmd comes first on PATH
        from halsdk.halcmd.cli import halcmd_main, halrun_main
        return (halrun_main if args[0] == "halrun" else halcmd_main)(
            args[1:])
    p = argparse.ArgumentParser(
        prog="halsdk", description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("ctl", add_help=False,
                   help="operate a running machine: status, estop, on, "
                        "home, mdi, run ... (halsdk ctl --help)")
    sub.add_parser("runtests", add_help=False,
                   help="run HAL tests in LinuxCNC's format (test.hal or "
                        "test.sh + expected or checkresult) "
                        "(halsdk runtests --help)")
    sub.add_parser("web", add_help=False,
                   help="serve the HAL workbench of the running instance, "
                        "or start machine.ini and serve its workbench, in "
                        "a browser (halsdk web --help)")
    sub.add_parser("rs274", add_help=False,
                   help="the standalone G-code interpreter: print a "
                        "program's canonical commands in the reference's "
                        "text format (halsdk rs274 --help)")
    sub.add_parser("halrun", add_help=False,
                   help="this halsdk's halrun, whatever comes first on "
                        "PATH (halsdk halrun --help)")
    sub.add_parser("halcmd", add_help=False,
                   help="this halsdk's halcmd, whatever comes first on "
                        "PATH (halsdk halcmd --help)")
    sub.add_parser("latency", add_help=False,
                   help="the latency test: how regularly this computer "
                        "runs a base and a servo thread; live figures, a "
                        "summary and histograms (halsdk latency --help)")
    run = sub.add_parser(
        "run", help="start a machine from its INI file; Ctrl-C stops it")
    run.add_argument("ini", help="the machine's INI file")
    run.add_argument("--seconds", type=float, default=None,
                     help="stop after this many seconds (default: run "
                          "until Ctrl-C or SIGTERM)")
    run.add_argument("--stepped", action="store_true",
                     help="do not start the realtime threads: the task "
                          "steps the servo thread every task cycle "
                          "(a simulation that runs the same on any "
                          "machine load)")
    run.add_argument("--strict", action="store_true",
                     help="refuse to start when the INI file has a problem "
                          "that is otherwise a warning: an unknown key of "
                          "a LinuxCNC section (a typo), a section or key "
                          "given twice, [KINS]JOINTS that disagrees with "
                          "the [JOINT_n] sections or the HAL files")
    run.add_argument("--simulate", action="store_true",
                     help="run a program (--program) in stepped, simulated "
                          "time as fast as possible: start the machine, "
                          "home it (unless [TRAJ]NO_FORCE_HOMING), run "
                          "the program, print the program time, the "
                          "largest following error per joint, limit hits "
                          "and errors; exit status 1 on any error")
    run.add_argument("--program", metavar="FILE",
                     help="with --simulate: the G-code program to run "
                          "(relative to the current folder, else to the "
                          "INI file's folder)")
    run.add_argument("--json", metavar="FILE",
                     help="with --simulate: also write the result as JSON")
    run.add_argument("--timeout", type=float, default=86400.0,
                     metavar="SECONDS",
                     help="with --simulate: machine time the program (and "
                          "homing) may take before it counts as an error "
                          "(default 86400)")
    a = p.parse_args(args)
    if a.command == "run" and (a.simulate or a.program or a.json):
        if not (a.simulate and a.program):
            p.error("--simulate needs --program FILE, and --program and "
                    "--json go with --simulate")
        if a.stepped or a.seconds is not None:
            p.error("--simulate is stepped and ends with the program: "
                    "no --stepped or --seconds")
        from halsdk.machine.simulate import main_simulate
        return main_simulate(a.ini, a.program, a.json, a.timeout,
                             strict=a.strict)
    if a.command == "run":
        from halsdk.machine.launcher import run as run_machine
        return run_machine(a.ini, seconds=a.seconds,
                           realtime=not a.stepped, strict=a.strict)
    return 2


if __name__ == "__main__":
    sys.exit(main())
