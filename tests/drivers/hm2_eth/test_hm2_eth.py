"""The realtime driver hm2_eth (drivers/hm2/) against the simulated card
hm2-sim: loading, names, the modules and the packet errors."""

from __future__ import annotations

import socket
import time

import pytest
from helpers.hm2 import load

from halsdk.core import _core
from halsdk.errors import HalError, InvalidError

CONFIG = "num_encoders=1 num_pwmgens=1 num_stepgens=5"


def kinds(items) -> dict:
    return {x.name: (x.type, x.direction) for x in items}


# ------------------------------------------------------------------ load

def test_names_types_directions(rig):
    hal, p = rig.hal, rig.p
    pins = kinds(hal.pins(p + "*"))
    assert pins[p + "gpio.000.in"] == (_core.BIT, _core.OUT)
    assert pins[p + "gpio.000.in_not"] == (_core.BIT, _core.OUT)
    assert pins[p + "gpio.000.out"] == (_core.BIT, _core.IN)
    assert pins[p + "watchdog.has_bit"] == (_core.BIT, _core.IO)
    assert pins[p + "stepgen.04.position-cmd"] == (_core.FLOAT, _core.IN)
    assert pins[p + "stepgen.00.position-fb"] == (_core.FLOAT, _core.OUT)
    assert pins[p + "stepgen.00.counts"] == (_core.S32, _core.OUT)
    assert pins[p + "stepgen.00.enable"] == (_core.BIT, _core.IN)
    assert pins[p + "encoder.00.count"] == (_core.S32, _core.OUT)
    assert pins[p + "encoder.00.index-enable"] == (_core.BIT, _core.IO)
    assert pins[p + "pwmgen.00.value"] == (_core.FLOAT, _core.IN)
    assert pins[p + "packet-error"] == (_core.BIT, _core.OUT)
    assert pins[p + "packet-error-level"] == (_core.S32, _core.OUT)
    assert pins[p + "packet-error-exceeded"] == (_core.BIT, _core.OUT)
    assert p + "stepgen.05.position-cmd" not in pins
    # pins a module drives have no in/out of their own; those it reads
    # keep in/in_not (GPIO 17: stepgen 0's step; 27: encoder A)
    assert p + "gpio.017.in" not in pins and p + "gpio.017.out" not in pins
    assert p + "gpio.027.in" in pins and p + "gpio.027.out" not in pins
    params = kinds(hal.params(p + "*"))
    assert params[p + "watchdog.timeout_ns"][0] == _core.U32
    assert params[p + "gpio.000.is_output"][0] == _core.BIT
    assert params[p + "stepgen.00.maxaccel"][0] == _core.FLOAT
    assert params[p + "packet-read-timeout"][0] == _core.S32
    assert hal.getp(p + "watchdog.timeout_ns") == 5_000_000
    functs = {f.name for f in hal.functions(p + "*")}
    assert {p + "read", p + "write", p + "read-request"} <= functs


def test_config_selects_instances(hal, sim):
    rig = load(hal, sim, "num_encoders=0 num_stepgens=2 num_pwmgens=0")
    names = {x.name for x in hal.pins(rig.p + "*")}
    assert rig.p + "stepgen.01.position-cmd" in names
    assert rig.p + "stepgen.02.position-cmd" not in names
    assert not any(".encoder." in n or ".pwmgen." in n for n in names)
    # the pins of the disabled instances are plain GPIO
    assert rig.p + "gpio.021.out" in names      # stepgen 2's step
    assert rig.p + "gpio.027.out" in names      # the encoder's A


@pytest.mark.parametrize("config, text", [
    ("num_encoders=2", "num_encoders=2, but the firmware has 1"),
    ("num_stepgens=6", "num_stepgens=6, but the firmware has 5"),
    ("num_frobs=1", 'invalid token in config string: "num_frobs=1"'),
    ("num_pwmgens=x", "num_pwmgens=x is not a number"),
])
def test_config_refused(hal, sim, config, text):
    with pytest.raises(InvalidError, match="hm2_eth") as exc:
        load(hal, sim, config)
    assert text in str(exc.value)
    assert not hal.components("hm2_eth")


def test_reference_keys_accepted(hal, sim, capfd):
    load(hal, sim, "firmware=hm2/7i96s/x.bit num_dplls=-1 num_ssrs=0 "
         "sserial_port_0=0xxxxxxx num_encoders=-1 num_stepgens=-1")
    assert "smart serial is not supported" in capfd.readouterr().err
    assert hal.pins("hm2_7i96s.0.stepgen.04.*")


def test_no_card_is_a_clear_error(hal):
    # a port where nothing listens: refused at once on loopback
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    t0 = time.monotonic()
    with pytest.raises(HalError, match=r"^hm2_eth: .*no answer from the "
                       r"card") as exc:
        hal.loadrt("hm2_eth", f"board_ip=127.0.0.1:{port}")
    assert time.monotonic() - t0 < 10
    assert f"127.0.0.1:{port}" in str(exc.value)


def test_silent_card_times_out(hal, sim):
    sim.go_away()
    t0 = time.monotonic()
    with pytest.raises(HalError, match="no answer from the card"):
        hal.loadrt("hm2_eth", f"board_ip=127.0.0.1:{sim.port}")
    assert time.monotonic() - t0 < 10


@pytest.mark.parametrize("ip", ["10.0.0", "localhost", "1.2.3.4:99999", ""])
def test_bad_board_ip(hal, ip):
    with pytest.raises(InvalidError, match="hm2_eth"):
        hal.loadrt("hm2_eth", f'board_ip="{ip}"')


def test_hostmot2_loads_alone(hal):
    hal.loadrt("hostmot2", "debug_idrom=1", "use_serial_numbers=0")
    assert hal.components("hostmot2")
    hal.unloadrt("hostmot2")


# ------------------------------------------------------------------ GPIO

def test_gpio_output_and_input(rig):
    sim = rig.sim
    rig.set("gpio.040.is_output", 1)
    rig.set("gpio.040.out", 1)
    rig.cycle(2)
    assert sim.is_output(40) and sim.pin(40)
    rig.set("gpio.040.out", 0)
    rig.cycle(2)
    assert not sim.pin(40)
    rig.set("gpio.040.invert_output", 1)
    rig.cycle(2)
    assert sim.pin(40)
    rig.set("gpio.040.is_output", 0)
    rig.cycle(2)
    assert not sim.is_output(40)
    for level in (False, True, False):
        sim.set_input(3, level)
        rig.cycle(1)
        assert rig.get("gpio.003.in") == level
        assert rig.get("gpio.003.in_not") == (not level)


def test_gpio_open_drain(rig):
    sim = rig.sim
    rig.set("gpio.041.is_output", 1)
    rig.set("gpio.041.is_opendrain", 1)
    rig.set("gpio.041.out", 1)          # released: the outside decides
    sim.set_input(41, False)
    rig.cycle(2)
    assert not sim.pin(41)
    rig.set("gpio.041.out", 0)
    sim.set_input(41, True)
    rig.cycle(2)
    assert not sim.pin(41)              # driven low


# ------------------------------------------------------------------ watchdog

def test_watchdog_bites_when_the_thread_stops(rig):
    sim = rig.sim
    rig.set("gpio.040.is_output", 1)
    rig.set("gpio.040.out", 0)
    rig.set("stepgen.00.enable", 1)
    rig.cycle(20)
    assert sim.is_output(40) and not sim.watchdog_bitten
    sim.step(0.010)                     # 10 ms without a cycle: > 5 ms
    assert sim.watchdog_bitten
    assert not sim.is_output(40) and sim.pin(40)    # safe: input, pulled up
    rig.cycle(2)
    assert rig.get("watchdog.has_bit")
    rig.cycle(5)
    assert not sim.is_output(40)        # stays safe until the reset
    rig.set("watchdog.has_bit", 0)
    rig.cycle(3)
    assert not sim.watchdog_bitten and not rig.get("watchdog.has_bit")
    assert sim.is_output(40) and not sim.pin(40)


def test_watchdog_timeout_param(rig):
    rig.set("watchdog.timeout_ns", 50_000_000)
    rig.cycle(3)
    rig.sim.step(0.030)
    rig.cycle(1)
    assert not rig.get("watchdog.has_bit")
    rig.sim.step(0.060)
    rig.cycle(1)
    assert rig.get("watchdog.has_bit")
