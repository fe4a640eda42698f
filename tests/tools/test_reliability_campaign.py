"""bench/reliability.py: the campaign counts what it should, and a short
run of every kind and kill target finds nothing."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench"


@pytest.fixture
def campaign(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCH))
    import fuzzkinds
    import reliability
    return reliability, fuzzkinds


def test_crashes_tracebacks_and_hangs_are_counted(campaign, monkeypatch):
    """A kind whose inputs crash, raise or hang the worker: each is
    counted once, and the inputs after it still run (the workers are
    forked, so the fake kind reaches them)."""
    reliability, fuzzkinds = campaign

    def run(text: str, ws) -> None:
        n = int(text)
        if n == 3:
            os.kill(os.getpid(), signal.SIGSEGV)
        if n in (5, 11):
            raise ValueError(f"input {n}")
        if n == 7:
            time.sleep(60)

    fake = fuzzkinds.Kind("fake", ["x"], run,
                          lambda rng, corpus: str(next(counter)))
    counter = iter(range(10**6))

    def kinds():
        return {"fake": fake}

    def make_input(kind, seed, index):
        return str(index)

    monkeypatch.setattr(fuzzkinds, "kinds", kinds)
    monkeypatch.setattr(fuzzkinds, "make_input", make_input)
    monkeypatch.setattr(reliability, "HANG_SECONDS", 2.0)
    monkeypatch.setattr(reliability, "CHUNK", 4)
    tally = reliability.fuzz("fake", 14, seed=1, jobs=2)
    assert tally.inputs == 14
    assert (tally.crashes, tally.tracebacks, tally.hangs) == (1, 2, 1)
    assert tally.leftovers == 0
    assert any("input 3" in f and "signal 11" in f for f in tally.findings)
    assert any("input 7" in f for f in tally.findings if "hang" in f)


@pytest.mark.slow
def test_a_short_campaign_finds_nothing(tmp_path):
    """Every fuzzed kind and every kill target, a few of each: all
    counts zero (the full campaign's figures are in
    docs/reliability.md)."""
    env = {k: v for k, v in os.environ.items() if k != "HALSDK_INSTANCE"}
    proc = subprocess.run(
        [sys.executable, str(BENCH / "reliability.py"), "--count", "40",
         "--kills", "1", "--jobs", "2", "--markdown"], cwd=tmp_path,
        env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    rows = [line for line in proc.stdout.splitlines()
            if line.startswith("| ") and not line.startswith("| kind")]
    kinds = [row.split("|")[1].strip() for row in rows]
    assert kinds == ["hal", "comp", "gcode", "ini", "driver", "channel",
                     "shm"] + [f"kill {t} ({s})"
                               for t in ("host", "component", "halcmd",
                                         "client")
                               for s in ("SIGKILL", "SIGSTOP")]
    for row in rows:
        cells = [c.strip() for c in row.split("|")[2:7]]
        assert int(cells[0].replace(",", "")) > 0
        assert cells[1:] == ["0", "0", "0", "0"], row
