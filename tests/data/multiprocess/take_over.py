"""Open an instance whose host may be dead, for the take-over race test.

Usage: ``take_over.py INSTANCE``

Prints ``loaded``, waits for a line on stdin (so that several racers
start together), opens INSTANCE with ``create=None`` (attach, or create it when no live
host has it), prints one JSON line (``pid``, ``is_host``, ``host_pid``,
``inode`` of the segment it mapped), then waits until stdin is closed.
"""

import json
import os
import sys

import halsdk


def main() -> int:
    print("loaded", flush=True)
    sys.stdin.readline()
    hal = halsdk.Hal(sys.argv[1], size=2 * 1024 * 1024)
    shm = halsdk.core.instance.shm_name(sys.argv[1])
    print(json.dumps({"pid": os.getpid(), "is_host": hal.is_host,
                      "host_pid": hal.info()["host_pid"],
                      "inode": os.stat("/dev/shm" + shm).st_ino}),
          flush=True)
    sys.stdin.read()
    hal.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
