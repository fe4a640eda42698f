"""The ``halsdk`` command: ``halsdk run machine.ini`` starts a machine."""

from __future__ import annotations

import argparse
import sys
from typing import Optional


def main(argv: Optional[list[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="halsdk", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser(
        "run", help="start a machine from its INI file; Ctrl-C stops it")
    run.add_argument("ini", help="the machine's INI file")
    run.add_argument("--seconds", type=float, default=None,
                     help="stop after this many seconds (default: run "
                          "until Ctrl-C or SIGTERM)")
    a = p.parse_args(sys.argv[1:] if argv is None else argv)
    if a.command == "run":
        from halsdk.machine.launcher import run as run_machine
        return run_machine(a.ini, seconds=a.seconds)
    return 2


if __name__ == "__main__":
    sys.exit(main())
