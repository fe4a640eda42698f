"""``mb2hal config=FILE.ini`` -- the userspace Modbus component."""

from __future__ import annotations

import argparse
import logging
import re
import sys
from collections.abc import Sequence
from typing import NoReturn, Optional

from halsdk.errors import HalError

from .config import ConfigError, load_config
from .engine import Mb2hal

LEVELS = {0: logging.CRITICAL + 1, 1: logging.WARNING, 2: logging.INFO,
          3: logging.DEBUG, 4: logging.DEBUG}


class _Parser(argparse.ArgumentParser):
    """Usage errors give one line and exit status 1, as bad configs do."""

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: {message} (see {self.prog} --help)",
              file=sys.stderr)
        sys.exit(1)


def _args(argv: Sequence[str]) -> argparse.Namespace:
    parser = _Parser(
        prog="mb2hal", description="Modbus (TCP/RTU) to HAL component.")
    parser.add_argument("-n", "--name", help="component name (overrides "
                        "HAL_MODULE_NAME)")
    parser.add_argument(
        "--strict", action="store_true",
        help="refuse the configuration when it has warnings (unknown or "
        "repeated keys, values that are ignored or corrected, "
        "transactions that cannot be sent ...) instead of running it "
        "as LinuxCNC's mb2hal does")
    parser.add_argument("setting", nargs="*", help="config=FILE.ini")
    args = parser.parse_args(argv)
    args.config = None
    for item in args.setting:
        key, sep, value = item.partition("=")
        if key != "config" or not sep or not value:
            parser.error(f"unknown argument '{item}' (use config=FILE.ini)")
        args.config = value
    if args.config is None:
        parser.error("missing config=FILE.ini")
    if args.name is not None and not re.fullmatch(r"[A-Za-z0-9_.\-]+",
                                                  args.name):
        parser.error(f"-n/--name: '{args.name}' is not a HAL name")
    return args


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _args(sys.argv[1:] if argv is None else argv)
    logging.basicConfig(format="mb2hal: %(message)s", stream=sys.stderr)
    try:
        config = load_config(args.config, strict=args.strict)
    except ConfigError as exc:
        for text in exc.warnings:
            print(f"mb2hal: warning: {text}", file=sys.stderr)
        for line in str(exc).splitlines():
            print(f"mb2hal: {line}", file=sys.stderr)
        return 1
    if config.init_debug >= 1:
        for text in config.warnings:
            print(f"mb2hal: warning: {text}", file=sys.stderr)
    level = max([config.init_debug] + [t.debug for t in config.transactions])
    logging.getLogger("halsdk.mb2hal").setLevel(LEVELS[level])
    if level >= 4:
        logging.getLogger("pymodbus").setLevel(logging.DEBUG)
    if config.init_debug >= 2:
        logging.getLogger("halsdk.mb2hal").info(
            "%s: %d transaction(s) on %d link(s)", config.path,
            len(config.transactions), len(config.links))
    try:
        Mb2hal(config, args.name).run()
    except HalError as exc:
        print(f"mb2hal: cannot create the component: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
