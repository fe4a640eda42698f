"""``whb04b``: the pendant driver as a ``loadusr`` program."""

from __future__ import annotations

import argparse
import logging
import math
import sys
from collections.abc import Sequence
from importlib import resources
from typing import Optional

from halsdk.driverkit import IOLoop

from .driver import Whb04bDriver
from .fake import FakeBackend, ScriptError, load_script
from .protocol import PRODUCT_ID

DEMO = "demo"
#: longest loop period: USB reads wait up to a quarter of it, and a stop
#: request is seen between reads
MAX_PERIOD = 1.0


class UsageError(Exception):
    """A bad command line (one line, exit status 1)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:     # type: ignore[override]
        raise UsageError(message)


def _hex(text: str) -> int:
    try:
        value = int(text, 16)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a hex number: {text!r}"
                                         ) from None
    if not 0 <= value <= 0xFFFF:
        raise argparse.ArgumentTypeError(f"product id out of range: {text}")
    return value


def _period(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0 < value <= MAX_PERIOD):
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected seconds > 0 and at most {MAX_PERIOD:g}")
    return value


def _name(text: str) -> str:
    if not text.strip():
        raise argparse.ArgumentTypeError("the component name is empty")
    return text


def parse_args(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    p = _Parser(
        prog="whb04b",
        description="HAL driver for the XHC WHB04B wireless jog pendant.")
    p.add_argument("-n", "--name", default="whb04b", type=_name,
                   help="HAL component name (default whb04b)")
    p.add_argument("--replay", metavar="FILE",
                   help="play a recorded session instead of using USB "
                        f"('{DEMO}' plays the shipped demo)")
    p.add_argument("--product-id", type=_hex, default=PRODUCT_ID,
                   metavar="HEX", help="USB product id (default eb93)")
    p.add_argument("--period", type=_period, default=0.02,
                   help="loop period in seconds (default 0.02)")
    p.add_argument("-v", "--verbose", action="store_true",
                   help="log reconnect attempts")
    return p.parse_args(argv)


def main(argv: Optional[Sequence[str]] = None) -> int:
    try:
        args = parse_args(argv)
    except UsageError as exc:
        print(f"whb04b: {exc}", file=sys.stderr)
        return 1
    logging.basicConfig(level=logging.INFO if args.verbose
                        else logging.WARNING, format="%(message)s")
    backend = None
    if args.replay is not None:
        try:
            if args.replay == DEMO:
                path = resources.files(__package__) / "demo.txt"
                with resources.as_file(path) as demo:
                    steps = load_script(demo)
            else:
                steps = load_script(args.replay)
        except ScriptError as exc:
            print(f"whb04b: {exc}", file=sys.stderr)
            return 1
        backend = FakeBackend(steps, product_id=args.product_id)
    driver = Whb04bDriver(comp_name=args.name, backend=backend,
                          product_id=args.product_id,
                          read_timeout_ms=max(1, int(args.period * 250)))
    IOLoop(driver, period=args.period).run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
