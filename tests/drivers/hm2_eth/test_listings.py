"""hm2_eth makes the pins, params and functions of the reference's
hm2_eth: our ``show pin/param/funct`` against the reference's listings
of the same HAL file with the same simulated card (tests/data/hm2/<board>,
recorded by the hm2sim branch's regen.sh).

Normalised as helpers.hm2.listing documents: owner ids, pin values, the
run's times and the reference's io_error state, and function addresses
are not compared; names, types, directions, param values (the defaults),
and each function's FP flag and users are."""

from __future__ import annotations

import os
import re

import pytest
from helpers.hm2 import golden_folder, hm2sim, listing

from halsdk import halcmd
from halsdk.errors import HalError

RUN_ONLY = ("start", "stop", "loadusr", "show")


def our_listing(hal, folder: str, port: int, tmp_path) -> list[str]:
    """Run the golden's load.hal against the simulated card on ``port``
    (without running the thread), and list what it made."""
    with open(f"{folder}/load.hal", encoding="utf-8") as f:
        lines = [re.sub(r"board_ip=\S+", f"board_ip=127.0.0.1:{port}", line)
                 for line in f if not line.split()
                 or line.split()[0] not in RUN_ONLY]
    hal_file = tmp_path / "load.hal"
    hal_file.write_text("".join(lines), encoding="utf-8")
    assert halcmd.source(hal, str(hal_file)) == 0
    out: list[str] = []
    for what in ("pin", "param", "funct"):
        assert halcmd.command(hal, f"show {what}", out=out.append)
    return "\n".join(out).splitlines()


def golden_listing(folder: str) -> list[str]:
    lines: list[str] = []
    for what in ("pin", "param", "funct"):
        with open(f"{folder}/show-{what}.txt", encoding="utf-8") as f:
            lines += f.read().splitlines()
    return lines


@pytest.mark.parametrize("board", ["7i96s", "7i92"])
def test_listing_equals_the_reference(hal, board, tmp_path):
    folder = golden_folder(board)
    with hm2sim().Hm2Sim(board, port=0, realtime=False) as sim:
        ours = listing(our_listing(hal, folder, sim.port, tmp_path))
    theirs = listing(golden_listing(folder))
    assert any(k[1].startswith(f"hm2_{board}.0.gpio.") for k in theirs)
    missing = sorted(set(theirs) - set(ours))
    extra = sorted(set(ours) - set(theirs))
    differ = sorted(k for k in set(ours) & set(theirs)
                    if ours[k] != theirs[k])
    assert (missing, extra, differ) == ([], [], [])


def test_listing_normalisation():
    lines = ["Component Pins:",
             "Owner   Type  Dir         Value  Name",
             "     7  bit   I/O          TRUE  hm2_7i92.0.watchdog.has_bit",
             "Parameters:",
             "Owner   Type  Dir         Value  Name",
             "     7  bit   RW           TRUE  hm2_7i92.0.io_error",
             "     7  s32   RW             80  hm2_7i92.0.packet-read-timeout",
             "     7  s32   RW        1234567  hm2_7i92.0.read.tmax",
             "Exported Functions:",
             "Owner   CodeAddr  Arg       FP   Users  Name",
             " 00007  7fc9673ee908  5586d188ad70  YES      1   hm2_7i92.0.read"]
    assert listing(lines) == {
        ("pin", "hm2_7i92.0.watchdog.has_bit"): ("bit", "I/O"),
        ("param", "hm2_7i92.0.io_error"): ("bit", "RW", ""),
        ("param", "hm2_7i92.0.packet-read-timeout"): ("s32", "RW", "80"),
        ("param", "hm2_7i92.0.read.tmax"): ("s32", "RW", ""),
        ("funct", "hm2_7i92.0.read"): ("YES", "1"),
    }


def reference_configs(folder: str) -> list[tuple[str, bool]]:
    """The config strings the reference was loaded with (configs.txt of
    the goldens) and whether it accepted each."""
    out = []
    with open(f"{folder}/configs.txt", encoding="utf-8") as f:
        for line in f:
            m = re.match(r'=== config="(.*)" \(exit status (\d+)\)', line)
            if m:
                out.append((m.group(1), m.group(2) == "0"))
    return out


@pytest.mark.parametrize("board", ["7i96s", "7i92"])
def test_config_strings_accepted_as_the_reference(hal, board):
    """Each config string of the goldens loads with hm2_eth exactly when
    it loaded with the reference's."""
    folder = golden_folder(board)
    cases = reference_configs(folder) if os.path.isfile(
        f"{folder}/configs.txt") else []
    if not cases:
        pytest.skip("the goldens have no configs.txt")
    with hm2sim().Hm2Sim(board, port=0, realtime=False) as sim:
        for config, accepted in cases:
            try:
                hal.loadrt("hm2_eth", f"board_ip=127.0.0.1:{sim.port}",
                           f'config="{config}"')
            except HalError as exc:
                assert not accepted, f"{config!r} refused: {exc}"
            else:
                assert accepted, f"{config!r} accepted"
                hal.unloadrt("hm2_eth")
