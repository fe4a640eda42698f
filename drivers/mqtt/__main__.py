"""Entry points: ``mqtt-bridge`` (:func:`main`) and ``mqtt-publisher``
(:func:`publisher_main`)."""

from __future__ import annotations

import logging
import sys
from collections.abc import Sequence
from typing import Optional

from halsdk.errors import HalError

from .bridge import Bridge
from .config import ConfigError, parse_args


def _named(prog: str, exc: Exception) -> str:
    """The error as one line that starts with the program's name."""
    text = str(exc).replace("\n", " ")
    return text if text.startswith(f"{prog}: ") else f"{prog}: {text}"


def _run(argv: Optional[Sequence[str]], publisher: bool) -> int:
    prog = "mqtt-publisher" if publisher else "mqtt-bridge"
    argv = sys.argv[1:] if argv is None else argv
    try:
        cfg, verbose = parse_args(argv, publisher)
    except ConfigError as exc:
        print(_named(prog, exc), file=sys.stderr)
        return 1
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING,
                        format="%(message)s")
    bridge = Bridge(cfg)
    try:
        bridge.start()
    except (ConfigError, HalError) as exc:
        print(_named(prog, exc), file=sys.stderr)
        return 1
    bridge.run()
    return 0


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``mqtt-bridge``: publish and subscribe."""
    return _run(argv, publisher=False)


def publisher_main(argv: Optional[Sequence[str]] = None) -> int:
    """``mqtt-publisher``: the reference program's options and pins."""
    return _run(argv, publisher=True)


if __name__ == "__main__":
    sys.exit(main())
