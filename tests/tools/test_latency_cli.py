"""``halsdk latency``: the latency test in a terminal, through the
installed console script (its own instance, the summary, the CSV and PNG
histograms, the reference's layout, the options it refuses, SIGTERM),
and its pieces: the time parser, the CSV rows and the PNG writer."""

from __future__ import annotations

import csv
import os
import re
import signal
import struct
import subprocess
import sys
import zlib
from types import SimpleNamespace

import pytest
from hypothesis import given
from hypothesis import strategies as st

from halsdk.tools import histplot, latency_cli
from halsdk.tools.latency import Histogram, ThreadSetup, bin_of, bin_range

HALSDK = os.path.join(os.path.dirname(sys.executable), "halsdk")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
ROW = re.compile(r"^(base|servo)\s+(\S+)\s+(\d+)\s+(-?[\d.]+)\s+(-?[\d.]+)"
                 r"\s+([\d.]+)\s+(-?[\d.]+)\s+([\d.]+)\s+(\d+)$")


def latency(tmp_path, *args: str, timeout: float = 60
            ) -> subprocess.CompletedProcess:
    return subprocess.run([HALSDK, "latency", *args], cwd=tmp_path,
                          capture_output=True, text=True, timeout=timeout,
                          stdin=subprocess.DEVNULL)


def segments(pid: int) -> list[str]:
    """The /dev/shm entries of the instance of process ``pid``."""
    return [n for n in os.listdir("/dev/shm") if f"latency-{pid}" in n]


def summary_rows(out: str) -> dict[str, tuple[str, ...]]:
    """The summary's table rows, by thread."""
    tail = out.split("\nsummary:", 1)[1]
    return {m.group(1): m.groups() for line in tail.splitlines()
            if (m := ROW.match(line))}


def read_csv(path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def png_size(path) -> tuple[int, int]:
    data = open(path, "rb").read()
    assert data[:8] == PNG_MAGIC
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


# ------------------------------------------------------------ the command

def test_help():
    r = subprocess.run([HALSDK, "latency", "--help"], capture_output=True,
                       text=True, timeout=30)
    assert r.returncode == 0
    for option in ("--base", "--servo", "--seconds", "--csv", "--png",
                   "--no-realtime", "--reference-style"):
        assert option in r.stdout
    top = subprocess.run([HALSDK, "--help"], capture_output=True,
                         text=True, timeout=30)
    assert "latency" in top.stdout


@pytest.mark.parametrize("args, message", [
    (["--base", "25xs"], "--base: '25xs' is not a time"),
    (["--servo", "1.5ns"], "not a whole number of nanoseconds"),
    (["--seconds", "0"], "--seconds: '0' must be more than 0"),
    (["--seconds", "soon"], "'soon' is not a number"),
    (["--bins", "0"], "--bins: '0' is not from 1"),
    (["--base", "1ms", "--servo", "1ms"], "must be shorter than the servo"),
    (["--servo", "1us"], "thread 'latency-servo': period 1000"),
    (["--base", "1us"], "thread 'latency-base': period 1000"),
    (["--frobnicate"], "unrecognized arguments: --frobnicate"),
])
def test_bad_options(tmp_path, args, message):
    r = latency(tmp_path, *args)
    assert r.returncode == 2
    assert "halsdk latency: error:" in r.stderr
    assert message in r.stderr
    assert "Traceback" not in r.stderr
    assert r.stdout == ""


def test_a_run_prints_a_summary_and_writes_the_histograms(tmp_path):
    r = latency(tmp_path, "--seconds", "1", "--csv", "h.csv",
                "--png", "h.png")
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    lines = r.stdout.splitlines()
    pid = int(re.search(r"instance 'latency-(\d+)'", lines[0]).group(1))
    assert segments(pid) == []
    assert lines[1].startswith("scheduling: ")
    assert re.match(r"scheduling: (realtime \(SCHED_FIFO|normal, not "
                    r"realtime)", lines[1])
    # not a terminal: plain periodic lines before the summary
    assert any(re.match(r"^\s+[\d.]+ s  base: max ", x) for x in lines)
    assert re.search(r"^summary: [\d.]+ s, ", r.stdout, re.M)
    rows = summary_rows(r.stdout)
    assert set(rows) == {"base", "servo"}
    assert rows["base"][1] == "25µs" and rows["servo"][1] == "1ms"
    for row in rows.values():
        samples, lo, hi, jitter = (int(row[2]), float(row[3]),
                                   float(row[4]), float(row[5]))
        assert samples > 0
        assert lo <= hi and jitter == max(abs(lo), abs(hi))
    assert "histogram written: h.csv" in r.stdout
    assert "histogram written: h.png" in r.stdout
    # the CSV: counts of each thread sum to its samples, the bins hold
    # what their limits say
    table = read_csv(tmp_path / "h.csv")
    assert table and set(table[0]) == {"thread", "period_ns", "bin",
                                       "low_ns", "high_ns", "count"}
    for role in ("base", "servo"):
        mine = [x for x in table if x["thread"] == role]
        assert sum(int(x["count"]) for x in mine) == int(rows[role][2])
        for x in mine:
            assert int(x["count"]) > 0
            assert int(x["low_ns"]) <= int(x["high_ns"])
            if x["bin"] not in ("below", "above"):
                assert (int(x["low_ns"]), int(x["high_ns"])) == \
                    bin_range(int(x["bin"]), 100)
    assert {x["period_ns"] for x in table} <= {"25000", "1000000"}
    assert png_size(tmp_path / "h.png") == (800, 520)


def test_reference_style_without_realtime(tmp_path):
    r = latency(tmp_path, "--seconds", "1", "--no-realtime",
                "--reference-style", "--base", "50us", "--servo", "2ms",
                "--csv", "", "--png", "")
    assert r.returncode == 0, r.stderr
    assert "scheduling: normal, not realtime (--no-realtime)" in r.stdout
    tail = r.stdout.split("\nsummary:", 1)[1].splitlines()
    assert "(--no-realtime)" in tail[0]
    head = tail[1].split("  ")
    assert [h.strip() for h in head if h.strip()] == [
        "Max Interval (ns)", "Max Jitter (ns)", "Last interval (ns)"]
    servo = re.match(r"^Servo thread \(2ms\):\s+(\d+)\s+(\d+)\s+(\d+)$",
                     tail[2])
    base = re.match(r"^Base thread \(50µs\):\s+(\d+)\s+(\d+)\s+(\d+)$",
                    tail[3])
    assert servo and base, tail
    for m in (servo, base):
        interval_max, jitter, last = map(int, m.groups())
        # read while the threads run: no relation between the three
        # is exact, each is a measured interval or deviation
        assert interval_max > 0 and jitter >= 0 and last > 0
    assert not (tmp_path / "latency.csv").exists()
    assert not (tmp_path / "latency.png").exists()
    # the live lines use the same figures
    assert re.search(r"base: max interval \d+ ns, max jitter \d+ ns",
                     r.stdout)


def test_servo_thread_only(tmp_path):
    r = latency(tmp_path, "--seconds", "1", "--base", "0", "--csv", "h.csv",
                "--png", "h.png")
    assert r.returncode == 0, r.stderr
    assert set(summary_rows(r.stdout)) == {"servo"}
    assert {x["thread"] for x in read_csv(tmp_path / "h.csv")} == {"servo"}
    assert png_size(tmp_path / "h.png") == (800, 260)


def test_an_unwritable_file_is_an_error_after_the_summary(tmp_path):
    r = latency(tmp_path, "--seconds", "1", "--csv",
                str(tmp_path / "no" / "such" / "h.csv"), "--png", "")
    assert r.returncode == 1
    assert "\nsummary:" in r.stdout
    assert "halsdk latency: cannot write" in r.stderr
    assert "Traceback" not in r.stderr


@pytest.mark.parametrize("signum, why", [(signal.SIGTERM, "SIGTERM"),
                                         (signal.SIGINT, "interrupted")])
def test_a_signal_ends_it_with_the_summary(tmp_path, signum, why):
    proc = subprocess.Popen([HALSDK, "latency", "--interval", "0.2"],
                            cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL)
    try:
        assert proc.stdout is not None
        seen = []
        for line in proc.stdout:
            seen.append(line)
            if " s  base: max " in line:
                break
        proc.send_signal(signum)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    out = "".join(seen) + out
    assert proc.returncode == 0, err
    assert re.search(rf"^summary: [\d.]+ s \({why}\), ", out, re.M)
    assert set(summary_rows(out)) == {"base", "servo"}
    assert (tmp_path / "latency.csv").exists()
    assert (tmp_path / "latency.png").read_bytes()[:8] == PNG_MAGIC
    assert "Traceback" not in err
    assert segments(proc.pid) == []


def test_a_running_instance_is_left_alone(hal, tmp_path):
    hal.newthread("servo", 1_000_000)
    hal.loadrt("and2", count=1)
    hal.addf("and2.0", "servo")
    before = sorted(t.name for t in hal.threads())
    r = latency(tmp_path, "--seconds", "0.5", "--csv", "", "--png", "")
    assert r.returncode == 0, r.stderr
    assert f"note: HAL instance '{hal.instance}' ($HALSDK_INSTANCE) is " \
        "running; the test does not touch it" in r.stderr
    assert "instance 'latency-" in r.stdout
    assert sorted(t.name for t in hal.threads()) == before
    assert hal.find("component", "timedelta") is None


# ------------------------------------------------------------ the pieces

@given(st.integers(0, 10**6), st.sampled_from(sorted(latency_cli._UNITS)))
def test_a_time_with_its_unit(n, unit):
    assert latency_cli.parse_time(f"{n}{unit}") == \
        n * latency_cli._UNITS[unit]
    assert latency_cli.parse_time(f"{n} {unit}") == \
        n * latency_cli._UNITS[unit]


@given(st.integers(1, 999), st.integers(0, 9))
def test_a_period_written_as_the_reference_does_reads_back(k, e):
    ns = k * 10 ** e
    text = latency_cli.human(ns)
    assert re.match(r"^\d+(\.\d+)?(ns|µs|ms|s)$", text)
    assert latency_cli.parse_time(text) == ns


@given(st.lists(st.integers(-30_000, 30_000), min_size=1, max_size=200),
       st.integers(1, 500), st.integers(1, 40))
def test_the_csv_counts_every_latency_once(tmp_path_factory, lats, binsize,
                                           bins):
    h = Histogram(binsize, bins)
    for lat in lats:
        b = bin_of(lat, binsize, bins)
        if b is None:
            if lat > 0:
                h.above += 1
            else:
                h.below += 1
        else:
            h.counts[b] = h.counts.get(b, 0) + 1
    s = ThreadSetup("servo", 1_000_000, binsize, bins)
    test = SimpleNamespace(threads=[s])
    figures = {"threads": [{"role": "servo", "min": min(lats),
                            "max": max(lats)}]}
    path = tmp_path_factory.mktemp("csv") / "h.csv"
    latency_cli.write_csv(str(path), test, {"servo": h}, figures)
    rows = read_csv(path)
    assert sum(int(x["count"]) for x in rows) == len(lats)
    # each latency lies within the limits of exactly one row
    for lat in set(lats):
        holding = [x for x in rows
                   if int(x["low_ns"]) <= lat <= int(x["high_ns"])]
        assert len(holding) == 1


def _decode(path) -> tuple[int, int, list[bytes]]:
    """A PNG written by histplot: its size and its rows of RGB bytes."""
    data = open(path, "rb").read()
    assert data[:8] == PNG_MAGIC
    pos, idat, size = 8, b"", (0, 0)
    while pos < len(data):
        n, = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        crc, = struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF
        if kind == b"IHDR":
            size = struct.unpack(">II", body[:8])
            assert body[8:10] == b"\x08\x02"     # 8-bit RGB
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h = size
    raw = zlib.decompress(idat)
    assert len(raw) == h * (1 + 3 * w)
    rows = [raw[i * (1 + 3 * w):(i + 1) * (1 + 3 * w)] for i in range(h)]
    assert all(r[0] == 0 for r in rows)
    return w, h, [r[1:] for r in rows]


@given(st.dictionaries(st.integers(-50, 50), st.integers(0, 10**6),
                       max_size=30))
def test_a_histogram_picture(tmp_path_factory, counts):
    path = tmp_path_factory.mktemp("png") / "h.png"
    histplot.plot(str(path), [histplot.Panel("servo", 100, counts)],
                  width=300, panel_height=120)
    w, h, rows = _decode(path)
    assert (w, h) == (300, 120)
    blue = bytes(histplot.COLOURS[0])
    has_bars = any(blue in r for r in rows)
    assert has_bars == any(c > 0 for c in counts.values())


def test_write_png_refuses_rows_of_the_wrong_size(tmp_path):
    with pytest.raises(ValueError):
        histplot.write_png(str(tmp_path / "x.png"), 2, 1, [b"\x00" * 5])
