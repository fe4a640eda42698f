"""``python -m halsdk.halcmd halrun|halcmd [options]``: this halsdk's
programs, whatever ``halrun``/``halcmd`` comes first on ``PATH`` (a
machine with LinuxCNC installed has its own)."""

import sys

from halsdk.halcmd.cli import main

if __name__ == "__main__":
    sys.exit(main())
