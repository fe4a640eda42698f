"""``cia402 [-n NAME] [--simulate] [-v] drives.ini``: CiA 402 drives on
CAN."""

from __future__ import annotations

import argparse
import logging
import sys
from typing import NoReturn, Optional

from halsdk.driverkit import IOLoop

from .config import ConfigError, load
from .driver import Cia402Driver

PROGRAM = "cia402"


class UsageError(Exception):
    """A bad command line; the message is one line."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, status 1
        raise UsageError(message)


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog=PROGRAM,
                     description="CANopen CiA 402 drives as HAL pins")
    parser.add_argument("-n", "--name", default=PROGRAM,
                        help="component name and pin prefix")
    parser.add_argument("--simulate", action="store_true",
                        help="run simulated drives on a virtual bus")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="log progress (-vv: debug messages)")
    parser.add_argument("config", nargs="?",
                        help="drive configuration INI file")
    return parser


def parse_args(argv: Optional[list[str]] = None) -> argparse.Namespace:
    """The options; UsageError names an unknown option before a missing
    configuration file."""
    args, extra = _parser().parse_known_args(argv)
    if extra:
        raise UsageError(f"unrecognized arguments: {' '.join(extra)}")
    if args.config is None:
        raise UsageError("missing the drive configuration file (cia402 "
                         "[-n NAME] [--simulate] [-v] drives.ini)")
    if not args.name:
        raise UsageError("-n/--name must not be empty")
    return args


def main(argv: Optional[list[str]] = None) -> int:
    """Run the drives until SIGTERM/SIGINT/unloadusr; 1 on a bad config."""
    try:
        args = parse_args(argv)
        config = load(args.config)
    except (UsageError, ConfigError) as exc:
        print(f"{PROGRAM}: {exc}", file=sys.stderr)
        return 1
    level = (logging.WARNING, logging.INFO)[args.verbose] \
        if args.verbose < 2 else logging.DEBUG
    logging.basicConfig(level=level, format="%(message)s", stream=sys.stderr)
    logging.getLogger("can").setLevel(logging.WARNING)
    logging.getLogger("canopen").setLevel(logging.WARNING)
    driver = Cia402Driver(config, args.name, args.simulate)
    IOLoop(driver, period=config.period).run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
