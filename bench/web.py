#!/usr/bin/env python3
"""The web workbench's Scope page under load: 8 channels sampled at
1 kHz, streamed to one websocket client in roll mode (every sample), for
60 seconds.

A private HAL instance (this script is its host) runs two siggen
instances in a 1 ms thread; ``halsdk web`` attaches to it as a separate
process, as a user runs it.  The client (the ``websockets`` library, in
this process) opens ``/ws/scope``, starts the scope on 8 siggen pins in
roll mode and counts the samples it receives.

=================  ======================================================
lost (client)      samples missing between two roll messages (gaps in
                   their sample numbers)
lost (server)      what the server counted: gaps in the stream's sample
                   numbers (its ring was full)
overruns           records the realtime function found no room for
server CPU         user + system time of the ``halsdk web`` process over
                   the measured time, in % of one core (the process CPU clock)
=================  ======================================================

It then runs the Show page's measurement (bench/web_show.py: 10,000
pins, the page in headless chromium); ``--pages scope`` or ``--pages
show`` runs one of them.

Run: ``python bench/web.py [--seconds 60] [--channels 8] [--pages ...]``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request

from websockets.sync.client import connect

import halsdk

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from thread_overhead import process_cpu  # noqa: E402

TOKEN = "bench-web-token-0123456789"
PINS = ["siggen.0.sine", "siggen.0.cosine", "siggen.0.square",
        "siggen.0.triangle", "siggen.0.sawtooth", "siggen.1.sine",
        "siggen.1.cosine", "siggen.1.square", "siggen.1.triangle",
        "siggen.1.sawtooth", "siggen.0.clock", "siggen.1.clock"]


def halsdk_program() -> list[str]:
    exe = os.path.join(os.path.dirname(sys.executable), "halsdk")
    if os.path.exists(exe):
        return [exe]
    found = shutil.which("halsdk")
    return [found] if found else [sys.executable, "-m", "halsdk.machine.cli"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def run(seconds: float, channels: int) -> dict:
    instance = f"bench-web-{os.getpid()}"
    hal = halsdk.Hal(instance, create=True)
    server = None
    try:
        hal.newthread("servo", 1_000_000)
        hal.loadrt("siggen", num_chan=2)
        hal.addf("siggen.0.update", "servo")
        hal.addf("siggen.1.update", "servo")
        hal.start()
        port = free_port()
        server = subprocess.Popen(
            halsdk_program() + ["web", "--instance", instance, "--token",
                                TOKEN, "--port", str(port)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert server.stdout is not None
        for _ in range(20):
            line = server.stdout.readline()
            if not line or "http://" in line:
                break
        if "http://" not in line:
            raise RuntimeError("halsdk web did not start: "
                               + (server.stderr.read() if server.stderr
                                  and server.poll() is not None else line))
        base = f"http://127.0.0.1:{port}"
        cookie = f"halsdk-web-{port}={TOKEN}"
        headers = {"Origin": base, "Cookie": cookie}
        with connect(f"ws://127.0.0.1:{port}/ws/scope",
                     additional_headers=headers) as ws:
            hello = json.loads(ws.recv(timeout=30))["hello"]
            body = json.dumps({"session": hello["session"],
                               "channels": PINS[:channels],
                               "thread": "servo", "mode": "roll",
                               "length": 1000}).encode()
            request = urllib.request.Request(
                base + "/api/scope/start", data=body, method="POST",
                headers={**headers, "Content-Type": "application/json"})
            with urllib.request.urlopen(request, timeout=30) as reply:
                json.loads(reply.read())
            received = lost = 0
            expected = None
            status: dict = {}
            cpu0 = process_cpu(server.pid)
            t0 = time.monotonic()
            while time.monotonic() - t0 < seconds:
                msg = json.loads(ws.recv(timeout=10))
                if "status" in msg:
                    status = msg["status"]
                roll = msg.get("roll")
                if roll is None:
                    continue
                n = len(roll["channels"][0])
                if expected is not None and roll["start"] > expected:
                    lost += roll["start"] - expected
                expected = roll["start"] + n
                received += n
            elapsed = time.monotonic() - t0
            cpu = process_cpu(server.pid) - cpu0
        return {"seconds": elapsed, "channels": channels,
                "received": received, "rate": received / elapsed,
                "lost_client": lost, "lost_server": status.get("lost", 0),
                "overruns": status.get("overruns", 0),
                "cpu": 100.0 * cpu / elapsed}
    finally:
        if server is not None:
            server.terminate()
            try:
                server.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                server.kill()
                server.communicate()
        hal.stop()
        hal.close()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=60.0,
                   help="measured time (default 60)")
    p.add_argument("--channels", type=int, default=8,
                   choices=range(1, len(PINS) + 1), metavar="N",
                   help="channels (default 8)")
    p.add_argument("--pages", default="scope,show",
                   help="the pages measured, comma separated (default "
                        "scope,show)")
    args = p.parse_args()
    pages = set(args.pages.split(","))
    if "show" in pages:
        import web_show
        web_show.main([])
    if "scope" not in pages:
        return 0
    r = run(args.seconds, args.channels)
    print("Scope page: channels at 1 kHz, roll mode, one websocket client")
    print(f"{'channels':>8} {'seconds':>8} {'samples':>9} {'rate/s':>8} "
          f"{'lost(cl)':>9} {'lost(srv)':>9} {'overruns':>9} "
          f"{'server CPU':>11}")
    print(f"{r['channels']:>8} {r['seconds']:>8.1f} {r['received']:>9} "
          f"{r['rate']:>8.1f} {r['lost_client']:>9} {r['lost_server']:>9} "
          f"{r['overruns']:>9} {r['cpu']:>10.1f}%")
    return 0


if __name__ == "__main__":
    sys.exit(main())
