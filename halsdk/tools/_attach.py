"""What the HAL tools (halsampler, halstreamer, halmeter) share: stopping
on SIGINT/SIGTERM between samples, and attaching to the instance."""

from __future__ import annotations

import signal
import sys
from typing import TYPE_CHECKING, Optional

if TYPE_CHECKING:
    from halsdk.hal import Hal


def stop_on_signals() -> list:
    """A list that SIGINT or SIGTERM append to; tools poll it and end
    cleanly instead of being killed mid-line."""
    stop: list = []

    def on_signal(signum, frame):  # noqa: ARG001
        stop.append(signum)

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_signal)
    return stop


def attach(prog: str) -> Optional[Hal]:
    """The running instance ($HALSDK_INSTANCE), or None after printing
    why not."""
    from halsdk import errors
    from halsdk.hal import Hal
    try:
        return Hal(create=False)
    except errors.HalError as e:
        print(f"{prog}: ERROR: cannot attach to the HAL instance: {e}",
              file=sys.stderr)
        return None
