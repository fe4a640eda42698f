"""Listings are consistent snapshots (issue 19).

While another process creates and removes components (pins, params,
signals and links) as fast as it can, ``halcmd show``/``list``/``save``
(the installed program) and the Python listings run over and over: none
may fail.  They used to list names and then look each one up, so an
object removed in between made them fail ("pin no longer exists",
``StaleError``).  A property test checks that a snapshot says what the
live handles say.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import halsdk
from halsdk.compat import hal as compat_hal

CHURN_SECONDS = 3.0

CHURN = """\
import sys, time
import halsdk
hal = halsdk.Hal(create=False)
deadline = time.monotonic() + float(sys.argv[1])
n = 0
print("churning", flush=True)
while time.monotonic() < deadline:
    c = halsdk.component(f"churn{n % 3}")
    for k in range(40):
        c.newpin(f"p{k}", "float", "out" if k % 2 else "in")
    c.newparam("par", "u32", "rw")
    c.ready()
    for k in range(0, 40, 2):
        hal.net(f"churn{n % 3}-s{k}", f"churn{n % 3}.p{k + 1}",
                f"churn{n % 3}.p{k}")
    for k in range(0, 40, 2):
        hal.delsig(f"churn{n % 3}-s{k}")
    c.exit()
    n += 1
print("done", n, flush=True)
"""


def _program(name: str) -> list[str]:
    path = os.path.join(os.path.dirname(sys.executable), name)
    if os.path.exists(path):
        return [path]
    return [sys.executable, "-m", "halsdk.halcmd.cli", name]


def _start_churn(cwd: Path) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", CHURN,
                             str(CHURN_SECONDS)], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "churning"
    return proc


def _stop_churn(proc: subprocess.Popen) -> int:
    try:
        out, err = proc.communicate(timeout=CHURN_SECONDS + 30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    return int(out.split()[-1])


def test_python_listings_never_fail_under_churn(hal, tmp_path):
    keep = halsdk.component("keep")
    for k in range(50):
        keep.newpin(f"k{k}", "s32", "in")
    keep.ready()
    churn = _start_churn(tmp_path)
    failures: list[str] = []
    listings = 0
    try:
        deadline = time.monotonic() + CHURN_SECONDS
        while time.monotonic() < deadline and churn.poll() is None:
            for call in (hal.pins, hal.params, hal.signals, hal.components,
                         lambda: hal.snapshot("pin"),
                         lambda: hal.snapshot("signal"),
                         lambda: hal.snapshot("param"),
                         lambda: hal.snapshot("component"),
                         compat_hal.get_info_pins,
                         compat_hal.get_info_signals,
                         compat_hal.get_info_params):
                try:
                    result = call()
                except halsdk.HalError as exc:
                    failures.append(f"{type(exc).__name__}: {exc}")
                    continue
                listings += 1
                if result and not isinstance(result[0], (dict, tuple)):
                    continue        # live handles: may go stale now
                names = [r["NAME"] if isinstance(r, dict) else r.name
                         for r in result]
                assert len(names) == len(set(names))
                assert names == sorted(names)
    finally:
        rounds = _stop_churn(churn)
    keep.exit()
    assert rounds > 0 and listings > 0
    assert failures == []
    hal.check()


def test_halcmd_listings_never_fail_under_churn(hal, tmp_path):
    keep = halsdk.component("keep")
    keep.newpin("k", "bit", "in")
    keep.ready()
    lines = ["show pin", "show sig", "show param", "show comp", "show all",
             "list pin", "list sig", "save all", "save allu", "status"] * 15
    script = tmp_path / "listings.hal"
    script.write_text("\n".join(lines) + "\n")
    churn = _start_churn(tmp_path)
    try:
        done = subprocess.run(_program("halcmd") + ["-k", "-f", str(script)],
                              cwd=tmp_path, capture_output=True, text=True,
                              timeout=120)
    finally:
        rounds = _stop_churn(churn)
    keep.exit()
    assert rounds > 0
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stderr == ""
    assert done.stdout.count("Component Pins:") == 30


# ---------------------------------------------------------------- property

names = st.lists(st.text("abcxyz", min_size=1, max_size=6), min_size=1,
                 max_size=8, unique=True)


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(pins=names, data=st.data())
def test_snapshot_agrees_with_the_handles(hal, pins, data):
    """Without concurrent changes a snapshot says what the handles say."""
    comp = halsdk.component("prop")
    try:
        for name in pins:
            direction = data.draw(st.sampled_from(["in", "out", "io"]))
            comp.newpin(name, data.draw(st.sampled_from(
                ["bit", "float", "s32", "u32", "s64", "u64"])), direction)
        comp.newparam("par", "float", "rw")
        comp.ready()
        linked = data.draw(st.lists(st.sampled_from(pins), unique=True))
        for name in linked:
            pin = hal.pin(f"prop.{name}")
            sig = f"sig-{name}"
            hal.newsig(sig, halsdk.HalType(pin.type).name.lower())
            if pin.direction != halsdk.OUT:
                hal.sets(sig, 1)
            hal.linkps(f"prop.{name}", sig)
        for rec in hal.snapshot("pin", "prop.*"):
            pin = hal.pin(rec.name)
            assert (rec.type, rec.direction, rec.value, rec.owner,
                    rec.owner_id, rec.alias_of) == \
                (pin.type, pin.direction, pin.value, pin.owner,
                 pin.owner_id, pin.alias_of)
            assert rec.signal == (pin.signal.name if pin.signal else None)
        assert [r.name for r in hal.snapshot("pin", "prop.*")] == \
            [p.name for p in hal.pins("prop.*")]
        for rec in hal.snapshot("signal", "sig-*"):
            sig = hal.signal(rec.name)
            assert (rec.type, rec.value, rec.readers, rec.writers,
                    rec.bidirs) == (sig.type, sig.value, sig.readers,
                                    sig.writers, sig.bidirs)
            assert [(p.name, p.direction) for p in rec.pins] == \
                [(p.name, p.direction) for p in sig.pins]
        (par,) = hal.snapshot("param", "prop.par")
        assert (par.value, par.owner) == (0.0, "prop")
        (crec,) = hal.snapshot("component", "prop")
        assert (crec.id, crec.ready, crec.pid, crec.alive,
                crec.realtime) == (comp.id, True, os.getpid(), True, False)
    finally:
        comp.exit()
        for sig in hal.signals("sig-*"):
            hal.delsig(sig.name)
    hal.check()


def test_thread_and_function_records(hal):
    hal.loadrt("tand2")
    hal.newthread("snap-t", 1_000_000)
    hal.addf("tand2.0", "snap-t")
    (th,) = hal.snapshot("thread", "snap-t")
    assert th.functions == ("tand2.0",)
    assert th.period == 1_000_000 and not th.running
    (fn,) = hal.snapshot("function", "tand2.0")
    assert (fn.owner, fn.users, fn.realtime) == ("tand2", 1, True)
    assert fn.owner_id == hal.component("tand2").id
    with pytest.raises(halsdk.InvalidError):
        hal.snapshot("gizmo")
