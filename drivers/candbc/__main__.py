"""``can-dbc``: the userspace program (``loadusr -W can-dbc ...``)."""

from __future__ import annotations

import logging
import sys
from collections.abc import Sequence
from typing import Optional

from halsdk.driverkit import IOLoop

from .dbc import ConfigError
from .driver import CanDbcDriver
from .options import PROGRAM, parse_args


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Run the driver until SIGTERM/SIGINT/unloadusr; 1 on a bad config."""
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    try:
        config = parse_args(argv)
        driver = CanDbcDriver(config)
    except ConfigError as exc:
        print(f"{PROGRAM}: {exc}", file=sys.stderr)
        return 1
    IOLoop(driver, period=config.loop_period).run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
