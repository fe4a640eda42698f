"""``cia402 [-n NAME] [--simulate] drives.ini``: CiA 402 drives on CAN."""

from __future__ import annotations

import argparse
import logging
import sys
from typing import Optional

from halsdk.driver import IOLoop
from halsdk.drivers.cia402.config import ConfigError, load
from halsdk.drivers.cia402.driver import Cia402Driver


def main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="cia402", description="CANopen CiA 402 drives as HAL pins")
    parser.add_argument("-n", "--name", default="cia402",
                        help="component name and pin prefix")
    parser.add_argument("--simulate", action="store_true",
                        help="run simulated drives on a virtual bus")
    parser.add_argument("-v", "--verbose", action="store_true")
    parser.add_argument("config", help="drive configuration INI file")
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.INFO,
        format="%(name)s: %(levelname)s: %(message)s", stream=sys.stderr)
    logging.getLogger("can").setLevel(logging.WARNING)
    logging.getLogger("canopen").setLevel(logging.WARNING)
    try:
        config = load(args.config)
    except ConfigError as exc:
        print(f"cia402: {exc}", file=sys.stderr)
        return 1
    driver = Cia402Driver(config, args.name, args.simulate)
    IOLoop(driver, period=config.period).run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
