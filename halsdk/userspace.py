"""The runtime of userspace component programs built by halcompile.

A ``.comp`` with ``option userspace yes`` (or a C program built with
``halcompile --compile -u prog.c``) becomes two files: an extension module
built like a realtime C component, whose ``rtapi_app_main`` runs the
component's start-up and main loop, and an executable launcher script that
``loadusr`` starts.  The launcher calls :func:`run`; nothing of halcompile
is needed at run time.

Like the reference's programs, one ends on ``SIGTERM`` or ``SIGINT`` (the
default action: the process ends at once, whatever ``user_mainloop`` is
doing); ``halcmd unload NAME`` / ``Hal.unload(NAME)`` send ``SIGTERM``
and then remove the component of the dead process.  When
``user_mainloop`` returns, the component is removed and the program ends
with status 0.  When the instance's host ends, however it ends, the
program ends too: a line on stderr names the instance and the host's pid,
then SIGTERM ends it (``Hal.end_with_host``).

``python -m halsdk.userspace MODULE_FILE args...`` runs a module without a
launcher script.
"""

from __future__ import annotations

import importlib.util
import os
import signal
import sys
from collections.abc import Sequence
from typing import Optional

from halsdk.errors import HalError
from halsdk.hal import Hal
from halsdk.loader import USER_ARGV_PARAM

#: most command-line words a userspace program receives
MAX_ARGS = 256


def run(module_path: str, argv: Sequence[str]) -> int:
    """Run the userspace component module at ``module_path`` with the
    command line ``argv`` (``argv[0]``: the program name); returns the
    exit status."""
    name = os.path.basename(module_path).split(".")[0]
    prog = os.path.basename(argv[0]) if argv else name
    try:
        hal = Hal(create=False)
        # ends with the host: a line on stderr and SIGTERM (which ends
        # the program at once, see below) the moment the host ends
        hal.end_with_host(prog)
    except HalError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1
    spec = importlib.util.spec_from_file_location(name, module_path)
    if spec is None or spec.loader is None:
        print(f"{prog}: cannot load {module_path}", file=sys.stderr)
        return 1
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        print(f"{prog}: {module_path}: {exc}", file=sys.stderr)
        return 1
    # like a C program: SIGINT and SIGTERM end the process at once, even
    # while user_mainloop() runs (which never returns to Python)
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    words = [prog, *argv[1:]]
    try:
        module.setup(**{USER_ARGV_PARAM: words})
    except HalError as exc:
        code = getattr(exc, "status", None)
        if code is None:
            print(f"{prog}: {exc}", file=sys.stderr)
            return 1
        # a failed start-up (negative errno) is status 1, like the
        # reference's; a program's own main() status is kept
        return 1 if code < 0 else (code & 255 or 1)
    cleanup = getattr(module, "cleanup", None)
    if callable(cleanup):
        cleanup()
    hal.close()
    return 0


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python -m halsdk.userspace MODULE_FILE args...``."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not args:
        print("usage: python -m halsdk.userspace MODULE_FILE [ARGS...]",
              file=sys.stderr)
        return 2
    module_path = args[0]
    name = os.path.basename(module_path).split(".")[0]
    return run(module_path, [name, *args[1:]])


if __name__ == "__main__":      # pragma: no cover
    sys.exit(main())
