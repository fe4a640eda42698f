"""Properties of hm2_eth against the simulated card: the encoder follows
any motion its 16-bit counter can show, and the stepgen reaches any
target within any velocity and acceleration limits."""

from __future__ import annotations

import pytest
from helpers.hm2 import PERIOD
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

SETTINGS = dict(deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.function_scoped_fixture])


@settings(max_examples=25, **SETTINGS)
@given(moves=st.lists(st.integers(-32000, 32000), min_size=1, max_size=8))
def test_encoder_count_follows_any_motion(rig, moves):
    """Moves of less than half the counter's range between two reads:
    count and position follow exactly, across any number of wraps."""
    rig.cycle(1)
    start_pos = rig.sim.encoder(0)["position"]
    start_count = rig.get("encoder.00.count")
    pos = start_pos
    for move in moves:
        pos += move
        rig.sim.set_encoder(0, pos)
        rig.cycle(1)
        assert rig.get("encoder.00.count") - start_count == pos - start_pos


@settings(max_examples=6, **SETTINGS)
@given(target=st.floats(-3.0, 3.0).filter(lambda x: abs(x) > 0.01),
       maxvel=st.floats(2.0, 20.0), maxaccel=st.floats(20.0, 400.0))
def test_stepgen_reaches_any_target_within_limits(rig, target, maxvel,
                                                  maxaccel):
    s = "stepgen.01."
    rig.set(s + "position-scale", 100.0)
    rig.set(s + "maxvel", maxvel)
    rig.set(s + "maxaccel", maxaccel)
    for t in ("steplen", "stepspace", "dirsetup", "dirhold"):
        rig.set(s + t, 1000)
    rig.set(s + "enable", 1)
    start = rig.get(s + "position-fb")
    goal = start + target
    rig.set(s + "position-cmd", goal)
    dt = PERIOD * 1e-9
    # long enough for any of these moves: accelerate, cruise, stop
    cycles = int((abs(target) / maxvel + 2 * maxvel / maxaccel) / dt) + 50
    last = rig.get(s + "velocity-fb")
    for _ in range(cycles):
        rig.cycle(1)
        v = rig.get(s + "velocity-fb")
        assert abs(v) <= maxvel * (1 + 1e-9)
        assert abs(v - last) <= maxaccel * dt * (1 + 1e-6)
        last = v
    assert rig.get(s + "position-fb") == pytest.approx(goal, abs=0.011)
    assert abs(last) < 1e-6


#: the 7i96S's firmware: instances of each module the config names
AVAILABLE = {"num_encoders": 1, "num_stepgens": 5, "num_pwmgens": 1,
             "num_leds": 4}


@settings(max_examples=20, **SETTINGS)
@given(counts=st.dictionaries(st.sampled_from(sorted(AVAILABLE)),
                              st.integers(-1, 7), max_size=4),
       extra=st.sampled_from(["", "enable_raw", "sserial_port_0=xxxx",
                              "num_dplls=-1", "firmware=x.bit"]))
def test_config_counts(hal, sim, counts, extra):
    """Any counts of the supported modules: the load succeeds exactly
    when none asks for more than the card has, and makes that many."""
    from halsdk.errors import InvalidError
    config = " ".join([f"{k}={v}" for k, v in counts.items()] + [extra])
    ok = all(v <= AVAILABLE[k] for k, v in counts.items())
    try:
        hal.loadrt("hm2_eth", f"board_ip=127.0.0.1:{sim.port}",
                   f'config="{config}"')
    except InvalidError as exc:
        assert not ok, f"{config!r}: {exc}"
        return
    assert ok, f"{config!r} loaded"
    try:
        for key, pattern in (("num_encoders", "encoder.*.count"),
                             ("num_stepgens", "stepgen.*.counts"),
                             ("num_pwmgens", "pwmgen.*.value"),
                             ("num_leds", "led.*")):
            want = counts.get(key, -1)
            want = AVAILABLE[key] if want < 0 else want
            assert len(hal.pins(f"hm2_7i96s.0.{pattern}")) == want, key
    finally:
        hal.unloadrt("hm2_eth")
