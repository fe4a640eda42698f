"""Fixtures of the hm2_eth tests: a simulated card on a free loopback
port, and a HAL with hm2_eth loaded against it."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from helpers.hm2 import Rig, hm2sim, load


@pytest.fixture
def sim() -> Iterator[object]:
    """A simulated 7i96S on a free loopback port, its clock stepped."""
    with hm2sim().Hm2Sim("7i96s", port=0, realtime=False) as s:
        yield s


@pytest.fixture
def sim_7i92() -> Iterator[object]:
    with hm2sim().Hm2Sim("7i92", port=0, realtime=False) as s:
        yield s


@pytest.fixture
def rig(hal, sim) -> Rig:
    """hm2_eth on the 7i96S with every module, read then write."""
    return load(hal, sim, "num_encoders=1 num_pwmgens=1 num_stepgens=5")
