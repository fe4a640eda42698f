"""Helpers of the hm2_eth tests (tests/drivers/hm2_eth): the simulated
card (hm2-sim) with its clock stepped by the test, and hm2_eth loaded
against it."""

from __future__ import annotations

import importlib
import os
from types import ModuleType

import pytest

#: where to find the simulator while it lives on another branch
#: (HM2SIM_DRIVERS: a folder holding the hm2sim package)
_SIM_FOLDERS = [os.environ.get("HM2SIM_DRIVERS", ""), "/work/wt-hm2sim/drivers"]

PERIOD = 1_000_000                  # ns: the servo thread of the tests
#: packet-read-timeout of the tests (ns): the simulated card is a Python
#: thread on a shared machine, slower to answer than a card
READ_TIMEOUT = 200_000_000


def hm2sim() -> ModuleType:
    """The simulator package, halsdk.drivers.hm2sim."""
    try:
        return importlib.import_module("halsdk.drivers.hm2sim")
    except ImportError:
        pass
    import halsdk.drivers
    for folder in _SIM_FOLDERS:
        if folder and os.path.isfile(os.path.join(folder, "hm2sim",
                                                  "__init__.py")):
            halsdk.drivers.__path__.append(folder)
            return importlib.import_module("halsdk.drivers.hm2sim")
    pytest.skip("the simulated card (halsdk.drivers.hm2sim) is missing")


#: the longest a cycle waits for the card to take the driver's packets
SYNC_TIMEOUT = 0.02


class Rig:
    """hm2_eth on a HAL thread against a simulated card whose clock moves
    one period per cycle: :meth:`cycle` runs the thread once.

    The card serves its socket in a thread of its own, so a cycle waits
    until the card has taken the cycle's two datagrams (the read request
    and the write) before its clock moves on: the rates written in a cycle
    then act during the next period, as on a card.  A cycle that sends
    less (the board stopped, the watchdog bitten) waits SYNC_TIMEOUT."""

    def __init__(self, hal, sim, board: str) -> None:
        self.hal = hal
        self.sim = sim
        self.p = f"hm2_{board}.0."

    def cycle(self, n: int = 1) -> None:
        for _ in range(n):
            self.sim.step(PERIOD * 1e-9)
            before = self.sim.stats.requests
            self.hal.step(1)
            self.sim.wait_requests(before + 2, SYNC_TIMEOUT)

    def get(self, name: str):
        return self.hal.getp(self.p + name)

    def set(self, name: str, value) -> None:
        self.hal.setp(self.p + name, value)


def load(hal, sim, config: str = "", board: str = "7i96s",
         functs: tuple[str, ...] = ("read", "write")) -> Rig:
    hal.loadrt("hostmot2")
    words = [f"board_ip=127.0.0.1:{sim.port}"]
    if config:
        words.append(f'config="{config}"')
    hal.loadrt("hm2_eth", *words)
    hal.newthread("servo", PERIOD)
    rig = Rig(hal, sim, board)
    for f in functs:
        hal.addf(rig.p + f, "servo")
    rig.set("packet-read-timeout", READ_TIMEOUT)
    return rig


# --------------------------------------------------------------- listings

#: the goldens while they live on another branch (HM2_GOLDENS: a folder
#: holding <board>/show-pin.txt ...)
_GOLDEN_FOLDERS = [os.environ.get("HM2_GOLDENS", ""),
                   "/work/wt-hm2sim/tests/data/hm2"]


def golden_folder(board: str) -> str:
    """tests/data/hm2/<board>: the reference's listings against hm2-sim."""
    from helpers import repo_path
    here = str(repo_path("tests", "data", "hm2"))
    for folder in [here] + _GOLDEN_FOLDERS:
        path = os.path.join(folder, board)
        if folder and os.path.isfile(os.path.join(path, "show-pin.txt")):
            return path
    pytest.skip(f"the reference's listings of the {board} are missing")


#: values that depend on the run, not on the driver: the functions' and
#: the thread's times, and the I/O error state of the reference's run
RUNTIME_PARAMS = (".tmax", ".io_error")


def listing(lines: list[str]) -> dict[tuple[str, str], tuple[str, ...]]:
    """A ``show pin``/``show param``/``show funct`` listing, normalised:
    (section, name) -> the columns that describe the object.  Dropped:
    the owner column (component ids differ), pin values (the state of a
    run), the values of RUNTIME_PARAMS, and the code and argument
    addresses of functions."""
    out: dict[tuple[str, str], tuple[str, ...]] = {}
    section = None
    for line in lines:
        if line.startswith("Component Pins"):
            section = "pin"
        elif line.startswith("Parameters"):
            section = "param"
        elif line.startswith("Exported Functions"):
            section = "funct"
        elif not line.strip() or line.startswith("Owner") or not section:
            continue
        else:
            f = line.split()
            name = f[-1]
            if section == "funct":
                out[(section, name)] = (f[3], f[4])         # FP, users
            elif section == "pin":
                out[(section, name)] = (f[1], f[2])         # type, dir
            else:
                value = "" if name.endswith(RUNTIME_PARAMS) else f[3]
                out[(section, name)] = (f[1], f[2], value)
    return out
