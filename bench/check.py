"""Time of ``Hal.check()`` and of a full listing at 1k, 10k and 125k pins.

``Hal.check()`` verifies the invariants of an instance under its lock;
it was quadratic (67 s at 125,000 pins, the lock held throughout) and is
O(n log n) now.  For each size the script makes a private instance with
that many pins (half of them linked in pairs to signals, the other half
unlinked), then prints the best of ``--repeat`` runs of:

- ``check``: ``Hal.check()``;
- ``snapshot pin``: ``Hal.snapshot("pin")``, the consistent listing that
  ``halcmd show pin`` prints (one pass under the lock);
- ``pins``: ``Hal.pins()``, the handles sorted by name.

    python bench/check.py                 # 1k, 10k, 125k pins
    python bench/check.py --sizes 1000 200000 --repeat 5
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import halsdk


def _best(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def measure(npins: int, repeat: int) -> dict[str, float]:
    name = f"bench-check-{os.getpid()}-{npins}"
    size = max(64 << 20, npins * 2048)
    with halsdk.Hal(name, create=True, size=size) as hal:
        comp = halsdk.component("bench")
        for k in range(npins):
            comp.newpin(f"p{k}", "float", "out" if k % 2 == 0 else "in")
        comp.ready()
        for k in range(0, npins // 2 - 1, 2):
            hal.net(f"s{k}", f"bench.p{k}", f"bench.p{k + 1}")
        out = {
            "check": _best(hal.check, repeat),
            "snapshot pin": _best(lambda: hal.snapshot("pin"), repeat),
            "pins": _best(hal.pins, repeat),
        }
        comp.exit()
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=int, nargs="+",
                   default=[1_000, 10_000, 125_000])
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args(argv)
    print(f"{'pins':>8}  {'check':>9}  {'snapshot pin':>12}  {'pins':>9}")
    for n in args.sizes:
        t = measure(n, args.repeat)
        print(f"{n:>8}  {t['check']:>8.3f}s  {t['snapshot pin']:>11.3f}s  "
              f"{t['pins']:>8.3f}s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
