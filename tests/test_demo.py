"""The README demo: a PID loop on a simulated motor, run in real time."""

from __future__ import annotations

import io

import halsdk.demo


def test_demo_closes_the_loop(monkeypatch):
    monkeypatch.delenv("HALSDK_INSTANCE", raising=False)
    out = io.StringIO()
    figures = halsdk.demo.run(seconds=0.6, out=out)
    text = out.getvalue()
    assert "servo-thread: 1 kHz" in text
    assert "servo cycles" in text
    assert figures["cycles"] >= 300            # the thread really ran
    # 0.6 s after the first move to 1.0 the motor has arrived
    assert abs(figures["final_position"] - 1.0) < 0.01
    assert abs(figures["final_error"]) < 0.01
    assert figures["pid_tmax_ns"] > 0
