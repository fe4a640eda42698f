#!/usr/bin/env python3
"""Throughput of the remote-I/O drivers: MQTT messages and Modbus
transactions per second.

MQTT: a Mosquitto broker started by this script on 127.0.0.1 (a free
port), a private HAL instance with one component of 1,000 float out pins,
and the MQTT bridge (``halsdk.drivers.mqtt.Bridge``, QoS 0) publishing all
of them.  Every cycle changes all 1,000 values, then runs one bridge scan,
as fast as it can for the measured time.  A subscriber in a separate
process counts what arrives; the figure is messages (and values) per
second at that subscriber.

=============  ===========================================================
case           what is published
=============  ===========================================================
on-change      one message per pin per cycle (all pins change)
batch          one message per cycle holding all 1,000 values (periodic
               publish with a period shorter than a cycle)
=============  ===========================================================

Modbus: ``bench/remote_modbus.py``: transactions per second of our engine
against a local simulator, then our mb2hal program and the reference's
(when LinuxCNC is installed) under halrun, counted at the server.

Run: ``python bench/remote.py [--seconds 3] [--pins 1000]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import halsdk
from halsdk.drivers.mqtt import Bridge, BridgeConfig
from halsdk.drivers.mqtt.broker import Mosquitto

HERE = os.path.dirname(os.path.abspath(__file__))

SUBSCRIBER = r"""
import sys, time
import paho.mqtt.client as mqtt
port, topic, seconds = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])
count = [0, 0]
def on_message(client, userdata, msg):
    if count[1]:
        count[0] += 1
c = mqtt.Client(mqtt.CallbackAPIVersion.VERSION2)
c.on_message = on_message
c.on_subscribe = lambda *a: print("ready", flush=True)
c.connect("127.0.0.1", port, 60)
c.subscribe(topic, 0)
c.loop_start()
sys.stdin.readline()                    # the publisher is running
count[1] = 1
t0 = time.monotonic()
time.sleep(seconds)
n = count[0]
print(n, time.monotonic() - t0, flush=True)
c.loop_stop()
"""


def mqtt_case(port: int, pins: int, seconds: float, batch: bool,
              instance: str) -> tuple[float, float, float]:
    """(messages/s at the subscriber, values/s, published/s)."""
    prefix = "bench/remote"
    topic = prefix if batch else f"{prefix}/#"
    sub = subprocess.Popen([sys.executable, "-c", SUBSCRIBER, str(port),
                            topic, str(seconds)], stdin=subprocess.PIPE,
                           stdout=subprocess.PIPE, text=True)
    bridge = None
    src = None
    try:
        if sub.stdout.readline().strip() != "ready":
            raise RuntimeError("the subscriber did not start")
        src = halsdk.component("bench-src")
        names = [f"v{i:04d}" for i in range(pins)]
        for name in names:
            src.newpin(name, "float", "out")
        src.ready()
        cfg = BridgeConfig(name="bench-bridge", port=port, prefix=prefix,
                           publish=[("", f"bench-src.{n}") for n in names],
                           on_change=not batch, period=1e-6 if batch else 0)
        bridge = Bridge(cfg)
        bridge.start()
        deadline = time.monotonic() + 10
        while not bridge.comp["connected"]:
            bridge.cycle()
            if time.monotonic() > deadline:
                raise RuntimeError("the bridge did not connect")
            time.sleep(0.01)
        pins_ = [src.item(n) for n in names]
        value = 0.0

        def one_cycle() -> None:
            nonlocal value
            value += 1.0
            for pin in pins_:
                pin.write(value)
            bridge.cycle()
        for _ in range(20):                 # warm up
            one_cycle()
        sub.stdin.write("go\n")
        sub.stdin.flush()
        published0 = bridge.comp["published"]
        t0 = time.monotonic()
        end = t0 + seconds + 0.2          # a little past the window
        while time.monotonic() < end:
            one_cycle()
        published = (bridge.comp["published"] - published0) / (
            time.monotonic() - t0)
        out, _ = sub.communicate(timeout=seconds + 20)
        count, elapsed = out.split()
        rate = int(count) / float(elapsed)
        return rate, rate * (pins if batch else 1), published
    finally:
        if sub.poll() is None:
            sub.kill()
            sub.wait(5)
        if bridge is not None:
            bridge.shutdown()
        if src is not None:
            src.exit()


def mqtt_bench(pins: int, seconds: float) -> None:
    instance = f"bench-remote-{os.getpid()}"
    with Mosquitto() as broker, halsdk.Hal(instance=instance):
        os.environ["HALSDK_INSTANCE"] = instance
        print(f"MQTT through a local mosquitto (127.0.0.1:{broker.port}), "
              f"{pins} float pins, all changing every cycle, QoS 0, "
              f"{seconds:g} s each:")
        print(f"  {'case':<10} {'msg/s at subscriber':>20} "
              f"{'values/s':>12} {'published/s':>12}")
        for batch in (False, True):
            rate, values, published = mqtt_case(
                broker.port, pins, seconds, batch, instance)
            name = "batch" if batch else "on-change"
            print(f"  {name:<10} {rate:>20,.0f} {values:>12,.0f} "
                  f"{published:>12,.0f}")


def modbus_bench(seconds: float, reference: bool) -> None:
    sys.path.insert(0, HERE)
    from remote_modbus import bench, compare  # type: ignore[import-not-found]
    print("\nModbus (bench/remote_modbus.py):")
    bench(seconds)
    compare(seconds, reference)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=3.0)
    p.add_argument("--pins", type=int, default=1000)
    p.add_argument("--no-modbus", action="store_true")
    p.add_argument("--no-reference", action="store_true",
                   help="do not run the reference's mb2hal")
    args = p.parse_args(argv)
    mqtt_bench(args.pins, args.seconds)
    if not args.no_modbus:
        modbus_bench(args.seconds, not args.no_reference)
    return 0


if __name__ == "__main__":
    sys.exit(main())
