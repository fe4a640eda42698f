"""The realtime driver hm2_eth (drivers/hm2/) against the simulated card
hm2-sim: loading, names, the modules and the packet errors."""

from __future__ import annotations

import math
import socket
import time

import pytest
from helpers.hm2 import PERIOD, load

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
    # every I/O pin shows its level; a pin a module uses has no out
    # (GPIO 17: stepgen 0's step; 27: encoder A) and, when the module
    # drives it, its settings under the module's name
    assert p + "gpio.017.in" in pins and p + "gpio.017.out" not in pins
    assert p + "gpio.027.in" in pins and p + "gpio.027.out" not in pins
    params = kinds(hal.params(p + "*"))
    assert p + "stepgen.00.step.invert_output" in params
    assert p + "gpio.027.invert_output" not in params
    assert params[p + "io_error"] == (_core.BIT, _core.RW)
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
    ("num_encoders=2", "num_encoders=2, but only 1 are available"),
    ("num_stepgens=6", "num_stepgens=6, but only 5 are available"),
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


def test_unloading_the_driver_bites_at_once(rig):
    """Unloaded, the driver leaves no output driven: the card's watchdog
    bites at once, not at the end of its timeout."""
    sim = rig.sim
    rig.set("watchdog.timeout_ns", 500_000_000)
    rig.set("gpio.040.is_output", 1)
    rig.cycle(5)
    assert sim.is_output(40)
    before = sim.stats.requests
    rig.hal.unloadrt("hm2_eth")
    assert sim.wait_requests(before + 1, 2.0)
    sim.step(0.001)                     # far less than the 500 ms
    assert sim.watchdog_bitten and not sim.is_output(40)


def test_loading_stops_a_watchdog_left_running(hal, sim):
    """A watchdog still counting from an earlier run (a driver that died)
    does not bite between the load and the first write function."""
    from halsdk.drivers.hm2sim import lbp16
    from halsdk.drivers.hm2sim.profiles import WATCHDOG_BASE
    before = sim.stats.requests
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        # the timer of a run that died: 1000 ticks, then a bite
        s.sendto(lbp16.encode([lbp16.write(0, WATCHDOG_BASE, [1000])]),
                 ("127.0.0.1", sim.port))
    assert sim.wait_requests(before + 1, 2.0)
    rig = load(hal, sim, "num_stepgens=1", functs=())
    sim.step(0.050)                     # no write function yet
    assert not sim.watchdog_bitten
    for f in ("read", "write"):
        hal.addf(rig.p + f, "servo")
    rig.cycle(3)
    assert not rig.get("watchdog.has_bit") and not sim.watchdog_bitten


def test_watchdog_timeout_param(rig):
    rig.set("watchdog.timeout_ns", 50_000_000)
    rig.cycle(3)
    rig.sim.step(0.030)
    rig.cycle(1)
    assert not rig.get("watchdog.has_bit")
    rig.sim.step(0.060)
    rig.cycle(1)
    assert rig.get("watchdog.has_bit")


# ------------------------------------------------------------------ stepgen

def setup_stepgen(rig, n=0, scale=100.0, maxvel=10.0, maxaccel=100.0):
    s = f"stepgen.{n:02d}."
    rig.set(s + "position-scale", scale)
    rig.set(s + "maxvel", maxvel)
    rig.set(s + "maxaccel", maxaccel)
    for t in ("steplen", "stepspace", "dirsetup", "dirhold"):
        rig.set(s + t, 2000)
    rig.set(s + "enable", 1)
    return s


def run_recording(rig, s, cycles):
    vels = []
    for _ in range(cycles):
        rig.cycle()
        vels.append(rig.get(s + "velocity-fb"))
    return vels


def assert_limited(vels, maxvel, maxaccel):
    dt = PERIOD * 1e-9
    assert max(abs(v) for v in vels) <= maxvel * (1 + 1e-9)
    steps = [abs(b - a) / dt for a, b in zip([0.0] + vels, vels)]
    assert max(steps) <= maxaccel * (1 + 1e-6)


@pytest.mark.parametrize("target", [2.0, -1.25])
def test_stepgen_moves_the_axis_within_limits(rig, target):
    s = setup_stepgen(rig)
    rig.set(s + "position-cmd", target)
    vels = run_recording(rig, s, 500)
    assert_limited(vels, 10.0, 100.0)
    assert max(abs(v) for v in vels) == pytest.approx(10.0)
    assert rig.sim.axis_position(0) == pytest.approx(target * 100, abs=1)
    assert rig.get(s + "position-fb") == pytest.approx(target, abs=0.01)
    assert rig.get(s + "counts") == pytest.approx(target * 100, abs=1)
    assert abs(rig.get(s + "velocity-fb")) < 1e-6
    # the other axes did not move
    assert rig.sim.axis_position(1) == 0


def test_stepgen_follows_a_moving_command(rig):
    s = setup_stepgen(rig, n=2)
    pos = 0.0
    for i in range(300):                # a ramp at 3 units/s
        pos = 3.0 * i * PERIOD * 1e-9
        rig.set(s + "position-cmd", pos)
        rig.cycle()
    assert rig.get(s + "velocity-fb") == pytest.approx(3.0, rel=1e-3)
    assert rig.get(s + "position-fb") == pytest.approx(pos, abs=0.02)


def test_stepgen_velocity_mode(rig):
    s = setup_stepgen(rig, n=1, maxaccel=50.0)
    rig.set(s + "control-type", 1)
    rig.set(s + "velocity-cmd", 20.0)       # above maxvel: clamped
    vels = run_recording(rig, s, 400)
    assert_limited(vels, 10.0, 50.0)
    assert vels[-1] == pytest.approx(10.0)
    before = rig.sim.axis_position(1)
    rig.cycle(100)                          # 0.1 s at 10 units/s
    assert rig.sim.axis_position(1) - before == pytest.approx(100, abs=2)


def test_stepgen_disable_stops_at_once(rig):
    s = setup_stepgen(rig)
    rig.set(s + "position-cmd", 100.0)
    rig.cycle(200)
    rig.set(s + "enable", 0)
    rig.cycle(2)
    at = rig.sim.axis_position(0)
    rig.cycle(20)
    assert rig.sim.axis_position(0) == at
    assert rig.get(s + "velocity-fb") == 0


@pytest.mark.parametrize("step_type, mode", [(0, 0), (1, 1), (2, 2),
                                              (3, 3), (6, 7), (16, 19)])
def test_stepgen_timings_and_step_type(rig, step_type, mode):
    s = "stepgen.03."
    rig.set(s + "steplen", 5000)            # ns; 100 MHz clock: 500 ticks
    rig.set(s + "stepspace", 1000)
    rig.set(s + "dirsetup", 30)             # rounded up to whole ticks
    rig.set(s + "dirhold", 0)
    rig.set(s + "step_type", step_type)     # 3 and more: table of that size
    rig.cycle(2)
    reg = rig.sim.stepgen(3)
    assert (reg["step_len"], reg["step_space"]) == (500, 100)
    assert (reg["dir_setup"], reg["dir_hold"]) == (3, 0)
    assert reg["mode"] == mode
    assert rig.sim.stepgen(2)["step_len"] == 0x3FFF     # the default


FULL_STEP = [0x3, 0x6, 0xC, 0x9]        # 4-phase full step, two coils on
WAVE = [0x1, 0x2, 0x4, 0x8]             # one coil at a time


def table_words(table):
    """The table-data-N params of ``table``: four entries a word, the
    first in the low byte."""
    words = [0, 0, 0, 0]
    for k, entry in enumerate(table):
        words[k // 4] |= entry << (8 * (k % 4))
    return words


def set_table(rig, s, table):
    for k, word in enumerate(table_words(table)):
        rig.set(s + f"table-data-{k}", word)


def move_recording_phases(rig, s, n, target, cycles=100):
    rig.set(s + "position-cmd", target)
    seen = []
    for _ in range(cycles):
        rig.cycle()
        reg = rig.sim.stepgen(n)
        seen.append((math.floor(reg["position"]), reg["table_index"],
                     reg["table_output"]))
    return seen


def test_stepgen_table_mode_follows_the_table(rig):
    n = 1
    s = setup_stepgen(rig, n=n, scale=1.0, maxvel=200.0, maxaccel=0.0)
    rig.set(s + "step_type", len(FULL_STEP))
    set_table(rig, s, FULL_STEP)
    rig.cycle(2)
    reg = rig.sim.stepgen(n)
    # the reference's registers: mode = step type | 3, width = length - 1
    assert (reg["mode"], reg["table_length"]) == (7, 4)
    assert rig.sim.step_table(n) == FULL_STEP
    assert (reg["table_index"], reg["table_output"]) == (0, 0x3)
    for target, way in ((6.0, 1), (-3.0, -1)):
        seen = move_recording_phases(rig, s, n, target)
        # at most one step a cycle (200 steps/s, 1 ms): every phase in
        # order, forward then back, and the pins show the table
        for (p0, i0, _), (p1, i1, _) in zip(seen, seen[1:]):
            assert p1 - p0 in (0, way)
            assert (i1 - i0) % 4 == (p1 - p0) % 4
        for step, index, output in seen:
            assert index == step % 4 and output == FULL_STEP[index]
        assert {index for _, index, _ in seen} == {0, 1, 2, 3}
        # the position still counts steps
        assert rig.sim.axis_position(n) == pytest.approx(target, abs=0.5)
        assert rig.get(s + "counts") == pytest.approx(target, abs=1)
    # another table, loaded while running, drives the same phase index
    set_table(rig, s, WAVE)
    rig.cycle(2)
    assert rig.sim.step_table(n) == WAVE
    reg = rig.sim.stepgen(n)
    assert reg["table_output"] == WAVE[reg["table_index"]]
    # the other stepgens are not in table mode and got no table
    assert rig.sim.stepgen(0)["mode"] == 0
    assert rig.sim.step_table(0) == [0] * 16


def test_stepgen_table_length_follows_step_type(rig):
    s = "stepgen.00."
    table = [0x1, 0x3, 0x2, 0x6, 0x4, 0xC, 0x8, 0x9]    # 4-phase half step
    set_table(rig, s, table)
    rig.cycle(1)
    assert rig.sim.step_table(0) == [0] * 16    # not in table mode: unsent
    rig.set(s + "step_type", 8)
    rig.cycle(2)
    assert rig.sim.stepgen(0)["table_length"] == 8
    assert rig.sim.step_table(0) == table
    rig.set(s + "step_type", 5)                 # a shorter table: resent
    rig.cycle(2)
    assert rig.sim.stepgen(0)["table_length"] == 5
    assert rig.sim.step_table(0) == table[:5]


def test_stepgen_position_reset(rig):
    s = setup_stepgen(rig)
    rig.set(s + "position-cmd", 0.5)
    rig.cycle(300)
    rig.set(s + "position-reset", 1)
    rig.cycle(1)
    assert rig.get(s + "position-fb") == 0 and rig.get(s + "counts") == 0


# ------------------------------------------------------------------ encoder

def test_encoder_follows_the_position(rig):
    e = "encoder.00."
    rig.set(e + "scale", 4.0)
    # the card's counter has 16 bits: it wraps, and is followed while it
    # moves less than 32767 counts between two reads
    for counts in (10, 1000, 30000, 60000, 65636, 90000, 60000, 30000, -5):
        rig.sim.set_encoder(0, counts)
        rig.cycle(1)
        assert rig.get(e + "count") == counts
        assert rig.get(e + "rawcounts") == counts
        assert rig.get(e + "position") == pytest.approx(counts / 4.0)


def test_encoder_velocity_and_inputs(rig):
    e = "encoder.00."
    rig.cycle(1)
    rig.sim.set_encoder_velocity(0, 2000.0)         # counts/s
    rig.cycle(50)
    assert rig.get(e + "velocity") == pytest.approx(2000.0, rel=0.01)
    assert rig.get(e + "velocity-rpm") == pytest.approx(120000.0, rel=0.01)
    rig.sim.set_encoder_velocity(0, 0.0)
    for counts, a, b in ((0, False, False), (1, True, False),
                         (2, True, True), (3, False, True)):
        rig.sim.set_encoder(0, counts)
        rig.cycle(1)
        assert (rig.get(e + "input-a"), rig.get(e + "input-b")) == (a, b)
        assert rig.get("gpio.027.in") == a          # encoder A's pin


def test_encoder_reset(rig):
    e = "encoder.00."
    rig.sim.set_encoder(0, 300)
    rig.cycle(1)
    rig.set(e + "reset", 1)
    rig.cycle(1)
    assert rig.get(e + "count") == 0
    rig.set(e + "reset", 0)
    rig.sim.set_encoder(0, 310)
    rig.cycle(1)
    assert rig.get(e + "count") == 10 and rig.get(e + "rawcounts") == 310


def test_encoder_index_enable_resets_on_index(rig):
    e = "encoder.00."
    rig.sim.set_encoder(0, 500)
    rig.cycle(2)
    rig.sim.pulse_index(0)                  # not armed: no effect
    rig.cycle(2)
    assert rig.get(e + "count") == 500
    rig.set(e + "index-enable", 1)
    rig.cycle(2)
    assert rig.get(e + "index-enable")      # waiting for the index
    rig.sim.set_encoder(0, 700)
    rig.sim.pulse_index(0)                  # the index at count 700
    rig.sim.set_encoder(0, 720)
    rig.cycle(1)
    assert not rig.get(e + "index-enable")
    assert rig.get(e + "count") == 20
    assert rig.get(e + "count-latched") == 700
    assert rig.get(e + "rawcounts") == 720
    rig.sim.pulse_index(0)                  # once only
    rig.cycle(2)
    assert rig.get(e + "count") == 20


def test_encoder_follows_a_stepgen_axis(rig):
    rig.sim.couple(0, 0, counts_per_step=2.0)
    s = setup_stepgen(rig)
    rig.set(s + "position-cmd", 1.0)        # 100 steps
    rig.cycle(400)
    assert rig.get("encoder.00.count") == pytest.approx(200, abs=2)


# ------------------------------------------------------------------ pwm, LEDs

def test_pwmgen_duty(rig):
    p = "pwmgen.00."
    rig.set(p + "scale", 10.0)
    rig.set(p + "value", 5.0)
    rig.cycle(2)
    assert rig.sim.pwm_duty(0) == 0         # not enabled
    rig.set(p + "enable", 1)
    rig.cycle(2)
    assert rig.sim.pwm_duty(0) == pytest.approx(0.5, abs=1e-3)
    rig.set(p + "value", 20.0)              # clamped to 100 %
    rig.cycle(2)
    assert rig.sim.pwm_duty(0) == pytest.approx(1.0)
    rig.set(p + "value", -2.5)              # magnitude, direction apart
    rig.cycle(2)
    assert rig.sim.pwm_duty(0) == pytest.approx(0.25, abs=1e-3)


def test_leds(rig):
    rig.set("led.CR01", 1)
    rig.set("led.CR03", 1)
    rig.cycle(2)
    assert rig.sim.leds == (1 << 31) | (1 << 29)


# ------------------------------------------------------------------ packets

def test_lost_replies_raise_packet_error(rig):
    rig.set("packet-read-timeout", 20_000_000)
    rig.cycle(3)
    assert not rig.get("packet-error") and rig.get("packet-error-level") == 0
    rig.sim.faults.drop(next=2)
    rig.cycle(1)
    assert rig.get("packet-error") and rig.get("packet-error-level") == 2
    rig.cycle(1)
    assert rig.get("packet-error-level") == 4
    assert rig.get("packet-error-total") == 2
    rig.cycle(1)                            # good again: decreases by 1
    assert not rig.get("packet-error") and rig.get("packet-error-level") == 3
    rig.cycle(5)
    assert rig.get("packet-error-level") == 0
    assert not rig.get("packet-error-exceeded") and not rig.get("io_error")


def test_late_and_short_replies_are_errors(rig):
    rig.set("packet-read-timeout", 20_000_000)
    rig.cycle(2)
    rig.sim.faults.truncate(next=1)
    rig.cycle(1)
    assert rig.get("packet-error")
    rig.sim.faults.delay(0.05, next=1)      # later than the timeout
    rig.cycle(1)
    assert rig.get("packet-error")
    time.sleep(0.1)                         # the late reply arrives...
    rig.sim.set_encoder(0, 42)
    rig.cycle(1)                            # ...and is not taken for this one
    assert not rig.get("packet-error")
    assert rig.get("encoder.00.count") == 42


def test_past_the_limit_the_board_stops(rig, capfd):
    rig.set("packet-read-timeout", 10_000_000)
    rig.set("gpio.040.is_output", 1)
    rig.cycle(2)
    rig.sim.faults.drop(probability=1.0)
    for _ in range(5):                      # 5 x 2 reaches the limit 10
        rig.cycle(1)
    assert rig.get("packet-error-exceeded") and rig.get("io_error")
    assert "reached the limit 10" in capfd.readouterr().err
    before = rig.sim.stats.requests
    rig.cycle(8)                            # stopped: no traffic at all
    assert rig.sim.stats.requests == before
    rig.sim.faults.clear()
    assert rig.sim.watchdog_bitten          # no writes: the card bit
    assert not rig.sim.is_output(40)
    rig.set("io_error", 0)                  # the user resets it
    rig.cycle(2)
    assert rig.get("packet-error-level") == 0 and not rig.get("io_error")
    assert rig.sim.stats.requests > before
    # resuming resets the watchdog too and sets the card up again
    assert not rig.get("watchdog.has_bit") and not rig.sim.watchdog_bitten
    assert rig.sim.is_output(40)


def test_card_unplugged_and_back(rig):
    rig.set("packet-read-timeout", 10_000_000)
    rig.set("gpio.040.is_output", 1)
    rig.set("gpio.040.out", 0)
    s = setup_stepgen(rig)
    rig.set(s + "position-cmd", 0.2)
    rig.cycle(100)
    assert rig.sim.is_output(40) and not rig.sim.pin(40)
    rig.sim.go_away()                       # comes back in power-on state
    rig.cycle(6)
    assert rig.get("io_error")
    rig.sim.come_back()
    rig.cycle(2)
    assert rig.get("io_error")              # stays stopped until reset
    assert not rig.sim.is_output(40)
    rig.set("io_error", 0)
    rig.cycle(3)
    assert rig.sim.is_output(40) and not rig.sim.pin(40)    # set up again
    rig.set(s + "position-cmd", 0.5)
    rig.cycle(200)
    assert rig.get(s + "position-fb") == pytest.approx(0.5, abs=0.01)


def test_read_request_then_read(hal, sim):
    rig = load(hal, sim, CONFIG, functs=("read-request", "read", "write"))
    rig.cycle(3)
    sim.set_encoder(0, 77)
    rig.cycle(1)
    assert rig.get("encoder.00.count") == 77
    assert rig.get("packet-error-level") == 0


def test_the_7i92(hal, sim_7i92):
    rig = load(hal, sim_7i92, "num_encoders=1 num_stepgens=5", board="7i92")
    s = setup_stepgen(rig, n=4)
    rig.set(s + "position-cmd", 0.3)
    rig.cycle(300)
    assert sim_7i92.axis_position(4) == pytest.approx(30, abs=1)
    assert not hal.pins("hm2_7i92.0.pwmgen.*")


def test_a_lost_datagram_shows_in_the_card_count(rig):
    """The read answer ends with the card's count of datagrams received;
    one the driver did not send (or one it sent that was lost) makes the
    counts differ: a packet error, then the counts agree again."""
    rig.cycle(3)
    assert rig.get("packet-error-total") == 0
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        # a write of the LED register: no answer, but counted
        s.sendto(bytes.fromhex("81c2000200000000"), ("127.0.0.1",
                                                      rig.sim.port))
    finally:
        s.close()
    time.sleep(0.05)
    rig.cycle(1)
    assert rig.get("packet-error") and rig.get("packet-error-total") == 1
    rig.cycle(2)
    assert not rig.get("packet-error") and rig.get("packet-error-total") == 1


def test_a_hal_file_as_the_reference_configs_write_it(hal, sim, tmp_path):
    from halsdk import halcmd
    path = tmp_path / "mesa.hal"
    path.write_text(
        "loadrt hostmot2\n"
        f'loadrt hm2_eth board_ip="127.0.0.1:{sim.port}" '
        'config="num_encoders=1 num_pwmgens=1 num_stepgens=3"\n'
        "loadrt threads name1=servo-thread period1=1000000\n"
        "addf hm2_7i96s.0.read servo-thread\n"
        "addf hm2_7i96s.0.write servo-thread\n"
        "setp hm2_7i96s.0.watchdog.timeout_ns 20000000\n"
        "setp hm2_7i96s.0.stepgen.00.position-scale 200\n"
        "net x-pos-cmd hm2_7i96s.0.stepgen.00.position-cmd\n",
        encoding="utf-8")
    assert halcmd.source(hal, str(path)) == 0
    assert hal.getp("hm2_7i96s.0.stepgen.00.position-scale") == 200
    assert hal.pins("hm2_7i96s.0.stepgen.02.*")
    assert not hal.pins("hm2_7i96s.0.stepgen.03.*")


def test_a_real_time_thread(hal):
    """The servo thread running on its own against the card on the wall
    clock: the exchange works outside of stepped time too."""
    from helpers.hm2 import hm2sim
    with hm2sim().Hm2Sim("7i96s", port=0) as sim:
        hal.loadrt("hostmot2")
        hal.loadrt("hm2_eth", f"board_ip=127.0.0.1:{sim.port}",
                   'config="num_encoders=0 num_pwmgens=0 num_stepgens=1"')
        hal.newthread("servo", 2_000_000)
        p = "hm2_7i96s.0."
        hal.addf(p + "read", "servo")
        hal.addf(p + "write", "servo")
        # a shared test machine is no realtime system: generous limits
        hal.setp(p + "packet-read-timeout", 90)
        hal.setp(p + "packet-error-limit", 100_000)
        hal.setp(p + "watchdog.timeout_ns", 200_000_000)
        s = p + "stepgen.00."
        hal.setp(s + "position-scale", 100.0)
        hal.setp(s + "maxvel", 10.0)
        hal.setp(s + "maxaccel", 100.0)
        for t in ("steplen", "stepspace", "dirsetup", "dirhold"):
            hal.setp(s + t, 1000)
        hal.setp(s + "enable", 1)
        hal.setp(s + "position-cmd", 0.5)
        hal.start(realtime=False)
        try:
            deadline = time.monotonic() + 10
            # at rest there: the card keeps its last rate after the stop
            # until the watchdog bites
            while ((abs(hal.getp(s + "position-fb") - 0.5) > 0.01
                    or abs(hal.getp(s + "velocity-fb")) > 1e-6)
                   and time.monotonic() < deadline):
                time.sleep(0.02)
        finally:
            hal.stop()
        assert hal.getp(s + "position-fb") == pytest.approx(0.5, abs=0.01)
        assert sim.axis_position(0) == pytest.approx(50, abs=1)
        assert not hal.getp(p + "io_error")


def test_two_boards(hal, sim, sim_7i92):
    from helpers.hm2 import hm2sim
    with hm2sim().Hm2Sim("7i96s", port=0, realtime=False) as sim2:
        hal.loadrt("hm2_eth",
                   f"board_ip=127.0.0.1:{sim.port},127.0.0.1:{sim_7i92.port},"
                   f"127.0.0.1:{sim2.port}",
                   'config="num_stepgens=1,num_stepgens=2,num_stepgens=3"')
        counts = {b: len(hal.pins(f"{b}.stepgen.*.position-cmd"))
                  for b in ("hm2_7i96s.0", "hm2_7i92.0", "hm2_7i96s.1")}
        assert counts == {"hm2_7i96s.0": 1, "hm2_7i92.0": 2, "hm2_7i96s.1": 3}
        hal.newthread("servo", PERIOD)
        hal.addf("hm2_7i96s.1.read", "servo")
        hal.addf("hm2_7i96s.1.write", "servo")
        hal.setp("hm2_7i96s.1.packet-read-timeout", 200_000_000)
        hal.setp("hm2_7i96s.1.gpio.040.is_output", 1)
        hal.setp("hm2_7i96s.1.gpio.040.out", 0)
        hal.step(2)
        assert sim2.is_output(40) and not sim.is_output(40)


def test_module_output_inverted(rig):
    """A module's output is inverted by the card (its output invert
    register), through the param named after the module's pin."""
    rig.cycle(2)
    assert rig.sim.is_output(18) and not rig.sim.pin(18)    # direction
    rig.set("stepgen.00.direction.invert_output", 1)
    rig.cycle(2)
    assert rig.sim.pin(18)
    assert rig.hal.getp("hm2_7i96s.0.gpio.018.invert_output")   # the same


def test_debug_prints_the_idrom(hal, sim, capfd):
    hal.loadrt("hm2_eth", f"board_ip=127.0.0.1:{sim.port}", "debug=1",
               'config="num_stepgens=2"')
    err = capfd.readouterr().err
    assert "IDROM type 3, MESA7I96" in err
    assert "I/O pin 017: gtag 5 instance 0" in err


def test_encoder_velocity_at_low_speed(rig):
    """50 counts/s is one count every 20 periods: from the card's
    timestamps the velocity stays near 50 between counts, then decays as
    1 / time since the last count once it stops, and is 0 after
    vel-timeout."""
    e = "encoder.00."
    rig.cycle(2)
    rig.sim.set_encoder_velocity(0, 50.0)
    rig.cycle(100)
    vels = []
    for _ in range(200):
        rig.cycle(1)
        vels.append(rig.get(e + "velocity"))
    assert min(vels) > 40 and max(vels) < 51
    rig.sim.set_encoder_velocity(0, 0.0)
    rig.cycle(100)                          # 0.1 s after the last count
    assert 5 < rig.get(e + "velocity") <= 10.5
    rig.set(e + "vel-timeout", 0.2)
    rig.cycle(150)
    assert rig.get(e + "velocity") == 0


def test_encoder_hires_timestamp(rig):
    rig.cycle(2)
    rig.sim.set_encoder_velocity(0, -3000.0)
    rig.cycle(20)
    assert rig.get("encoder.00.velocity") == pytest.approx(-3000, rel=0.01)
    rig.set("encoder.hires-timestamp", 1)   # 10 MHz: the divider changes
    rig.cycle(20)
    assert rig.get("encoder.00.velocity") == pytest.approx(-3000, rel=0.01)


def test_lost_datagrams_on_the_way_to_the_card(rig):
    """A lost read request times out; a lost write is seen in the next
    cycle, from the card's count of datagrams: two errors."""
    rig.set("packet-read-timeout", 20_000_000)
    rig.cycle(3)
    rig.sim.faults.lose(next=2)             # this cycle's request and write
    rig.cycle(1)
    assert rig.get("packet-error") and rig.get("packet-error-total") == 1
    rig.cycle(1)
    assert rig.get("packet-error") and rig.get("packet-error-total") == 2
    rig.cycle(1)
    assert not rig.get("packet-error") and rig.get("packet-error-total") == 2


def test_a_card_left_bitten_starts_clean(hal, sim):
    rig = load(hal, sim, CONFIG)
    rig.cycle(5)
    sim.step(0.02)                          # the HAL stops: the card bites
    assert sim.watchdog_bitten
    hal.unloadrt("hm2_eth")                 # ... and a new run loads
    hal.loadrt("hm2_eth", f"board_ip=127.0.0.1:{sim.port}",
               f'config="{CONFIG}"')
    assert not sim.watchdog_bitten
    hal.addf(rig.p + "read", "servo")
    hal.addf(rig.p + "write", "servo")
    rig.set("packet-read-timeout", 200_000_000)
    rig.set("gpio.040.is_output", 1)
    rig.cycle(3)
    assert not rig.get("watchdog.has_bit") and sim.is_output(40)


def test_duplicated_replies_are_not_taken_twice(rig):
    rig.cycle(2)
    rig.sim.faults.duplicate(next=3)
    for counts in (5, 9, 14, 20):
        rig.sim.set_encoder(0, counts)
        rig.cycle(1)
        assert rig.get("encoder.00.count") == counts
    assert rig.get("packet-error-total") == 0
