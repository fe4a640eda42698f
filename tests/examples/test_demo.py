"""The README demo (``halsdk-demo``): the simulated mill of halsdk/demo/mill is
turned on, homed and runs demo.ngc (two tool changes, an arc, a probe),
stepped and deterministic; the summary's numbers and the plot are checked."""

from __future__ import annotations

import io
import re

import pytest
from helpers import repo_path

import halsdk.demo
from halsdk.ini import IniFile
from halsdk.testing import private_instance_name

MILL = repo_path("halsdk", "demo", "mill")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """Run the demo once for the whole module."""
    mp = pytest.MonkeyPatch()
    mp.setenv("HALSDK_INSTANCE", private_instance_name())
    png = tmp_path_factory.mktemp("demo") / "plot.png"
    out = io.StringIO()
    try:
        summary = halsdk.demo.run(str(png), realtime=False, out=out)
    finally:
        mp.undo()
    return summary, out.getvalue(), png


def test_the_demo_finds_its_machine():
    folder = halsdk.demo.machine_folder()
    for name in ("mill.ini", "mill.hal", "toolchange.hal", "tool.tbl",
                 "demo.ngc"):
        assert (folder / name).is_file(), name


def test_homed_two_tool_changes_no_errors(demo):
    summary, text, _ = demo
    assert summary.homed
    assert summary.tool_changes == 2
    assert summary.tool_in_spindle == 2
    assert summary.errors == []
    assert "tool changes:       2 (tool in spindle: T2)" in text
    assert "errors:             none" in text


def test_program_time_is_simulated_and_plausible(demo):
    summary, text, _ = demo
    # the outline alone is 60 + 40 + 31.4 + 40 + 60 mm at 25 mm/s: > 9 s;
    # with the rapids, the tool changes and the 15 mm probe at 1 mm/s
    # (the probe stops after 5 mm) it stays well under a minute
    assert 15 < summary.program_time < 60
    assert summary.program_time == pytest.approx(summary.cycles * 0.001)
    assert re.search(rf"program time: +{summary.program_time:.3f} s", text)


def test_following_error_far_below_ferror(demo):
    summary, text, _ = demo
    ini = IniFile(str(MILL / "mill.ini"))
    assert len(summary.max_ferror) == 3
    for n, worst in enumerate(summary.max_ferror):
        ferror = float(ini.get(f"JOINT_{n}", "FERROR"))
        assert summary.ferror_limit[n] == ferror
        # sampled every cycle: the loops did work (nonzero) and stayed
        # far below the limit
        assert 0 < worst < ferror / 10, (n, worst)
    assert "max following error joint 2 (Z)" in text


def test_probe_stops_at_the_workpiece_top(demo):
    summary, text, _ = demo
    assert summary.probe_tripped
    x, y, z = summary.probe_work
    # demo.ngc's work origin is the workpiece top (G10 L2 P1 Z-80 =
    # [SIM]WORKPIECE_TOP); G38.2 at F60 moves 0.001 mm per 1 ms period
    assert summary.workpiece_top == -80
    assert (x, y) == pytest.approx((30, 30), abs=1e-9)
    assert abs(z) <= 60 / 60 * 0.001 + 1e-9
    # the spindle is the tool length (T2: 32.5 mm) above the tip
    assert summary.probe_machine[2] == pytest.approx(-80 + 32.5, abs=0.002)
    assert "probe:              tripped at X30.0000 Y30.0000" in text


def test_the_plot_is_written(demo):
    summary, text, png = demo
    assert summary.plot == str(png)
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > 10_000           # two panels with curves, not blank
    assert f"plot:               {png}" in text
    assert not [p for p in png.parent.iterdir() if p != png]  # no temp left


def test_without_matplotlib_the_plot_is_skipped(monkeypatch, tmp_path):
    import builtins
    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)
    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    out = io.StringIO()
    path = tmp_path / "p.png"
    trace = [(0.0, 0.0, 0.0, 0.0), (0.01, 1.0, 1.0, -1.0)]
    result = halsdk.demo._write_plot(trace, str(path), halsdk.demo.Summary(),
                                     out)
    assert result is None and not path.exists()
    assert "matplotlib is not installed" in out.getvalue()


def test_main_parses_its_options(monkeypatch):
    seen = {}

    def fake_run(out_png, realtime=False, out=None):
        seen.update(out_png=out_png, realtime=realtime)
        return halsdk.demo.Summary()
    monkeypatch.setattr(halsdk.demo, "run", fake_run)
    assert halsdk.demo.main([]) == 0
    assert seen == {"out_png": "demo.png", "realtime": False}
    assert halsdk.demo.main(["--realtime", "--out", "x.png"]) == 0
    assert seen == {"out_png": "x.png", "realtime": True}
