"""A process that hosts a HAL instance of its own, for the multi-process
tests.

Usage: ``host.py INSTANCE``

Creates INSTANCE (a small one), prints ``ready <pid>``, then waits until
stdin is closed, closes the instance (removing it) and prints ``closed``.
"""

import os
import sys

import halsdk


def main() -> int:
    hal = halsdk.Hal(sys.argv[1], create=True, size=2 * 1024 * 1024)
    print(f"ready {os.getpid()}", flush=True)
    sys.stdin.read()
    hal.close()
    print("closed", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
