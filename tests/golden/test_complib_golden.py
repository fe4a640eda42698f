"""Differential tests of the component library against the reference.

Every ``tests/data/complib/NAME.hal`` runs with our ``halrun -f`` in a folder
holding its inputs; the reference's results of the same run (made by
``tests/data/complib/golden.py``) are the goldens:

- ``NAME.out``: standard output, compared byte for byte after
  :func:`helpers.halrun.normalize` (component ids, addresses and halcmd's
  pid cannot match);
- ``NAME.rc``: a non-zero exit status (absent: 0); zero/non-zero must
  match;
- ``NAME.err``: standard error; each line that carries a message of the
  component itself must appear in ours (the lines of the reference's
  rtapi_app/insmod machinery and its HAL library's own wording do not).

The files drive inputs with ``streamer``/``halstreamer`` and record
outputs with ``sampler``/``halsampler -n N`` in a realtime thread, which is
deterministic: the functions see the thread's nominal period, and a
sample k is taken in cycle k.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import data_path, repo_path
from helpers.halrun import normalize
from helpers.halrun import tools_env as _env

COMPLIB = data_path("complib")
GOLDEN = (".out", ".err", ".rc")
#: goldens compared with a tolerance by their own test, not byte for byte
#: (limit3-runaway: tests/components/test_limit3_properties.py)
APPROXIMATE = {"limit3-runaway"}
CASES = sorted(p for p in COMPLIB.glob("*.hal")
               if p.with_suffix(".out").exists()
               and p.stem not in APPROXIMATE)
#: stderr lines of the reference's loading machinery, not of a component
_MACHINERY = re.compile(
    r"waitpid failed|exited without becoming ready|: rtapi_app_main: |"
    r"^HAL: ERROR: |^Note: Using POSIX non-realtime$")


def _inputs(name: str) -> list[Path]:
    return [p for p in COMPLIB.iterdir()
            if (p.name.startswith(name + ".") or p.name.startswith(name + "-"))
            and p.suffix not in GOLDEN and p.suffix != ".py"]


def component_messages(err: str) -> list[str]:
    """The lines of a golden stderr that a component printed."""
    return [line for line in err.splitlines()
            if line.strip() and not _MACHINERY.search(line)]


@pytest.mark.parametrize("hal_file", CASES, ids=lambda p: p.stem)
def test_matches_reference(hal_file: Path, tmp_path: Path):
    name = hal_file.stem
    work = tmp_path / "work"
    work.mkdir()
    for p in _inputs(name):
        shutil.copy(p, work / p.name)
    env = _env(name, tmp_path / "bin")
    proc = subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", "halrun", "-f",
         hal_file.name], cwd=work, env=env, capture_output=True, text=True,
        timeout=120)
    expected = hal_file.with_suffix(".out").read_text()
    assert normalize(proc.stdout) == normalize(expected), proc.stderr
    rc_file = hal_file.with_suffix(".rc")
    expected_rc = int(rc_file.read_text()) if rc_file.exists() else 0
    assert (proc.returncode != 0) == (expected_rc != 0), proc.stderr
    err_file = hal_file.with_suffix(".err")
    if err_file.exists():
        for line in component_messages(err_file.read_text()):
            assert line in proc.stderr, \
                f"the reference's message {line!r} is missing:\n{proc.stderr}"
    left = [n for n in os.listdir("/dev/shm") if env["HALSDK_INSTANCE"] in n]
    assert left == []


# ------------------------------------------- the library, name by name

#: the components issue 5 requires, by group
REQUIRED = {
    "logic": "and2 or2 xor2 not logic lut5 maj3 match8 mux2 mux4 mux8 mux16 "
             "mux_generic select8 demux edge flipflop oneshot toggle "
             "toggle2nist debounce dbounce timedelay tof ton multiclick "
             "multiswitch estop_latch tristate_bit tristate_float bitslice "
             "bitwise bin2gray gray2bin",
    "math": "abs abs_s32 sum2 scale mult2 div2 invert ddt integ lowpass "
            "ilowpass biquad limit1 limit2 limit3 hypot near comp wcomp "
            "deadzone minmax sample_hold offset weighted_sum scaled_s32_sums "
            "lincurve modmath updown counter blend knob2float constant "
            "clarke2 clarke3 clarkeinv",
    "conversion": "conv_bit_float conv_bit_s32 conv_bit_u32 conv_float_s32 "
                  "conv_float_u32 conv_s32_bit conv_s32_float conv_s32_u32 "
                  "conv_u32_bit conv_u32_float conv_u32_s32",
    "motor": "siggen pwmgen stepgen encoder encoder_ratio pid charge_pump "
             "sim_encoder sim_home_switch sim_spindle sim_axis_hardware "
             "watchdog",
    "timing": "threadtest time timedelta latencybins",
}
ALL_REQUIRED = sorted(n for group in REQUIRED.values() for n in group.split())
#: the load line of a first load, where the default load is refused
LOAD_ARGS = {
    "mux_generic": "config=bb4", "stepgen": "step_type=0",
    "pwmgen": "output_type=0", "modmath": "mod_dir=1", "debounce": "cfg=1",
    "weighted_sum": "wsum_sizes=1", "watchdog": "num_inputs=1",
}
COMPONENTS = repo_path("components")


def _cases_of(name: str) -> list[Path]:
    return [p for p in CASES
            if p.stem == name or p.stem.startswith(name + "-")]


@pytest.mark.parametrize("name", ALL_REQUIRED)
def test_required_component_is_shipped(name: str, hal):
    """A .comp source, an installed module that loads by name, and at
    least one differential test."""
    assert (COMPONENTS / f"{name}.comp").is_file(), f"no {name}.comp"
    hal.loadrt(name, LOAD_ARGS.get(name, ""))
    made = hal.components(name)
    assert made and made[0].ready
    pins = [p.name for p in hal.pins()]
    assert pins or hal.functions()
    hal.unloadrt(name)
    assert hal.components(name) == []
    # a second load in the same process starts afresh, as in the reference
    hal.loadrt(name, LOAD_ARGS.get(name, ""))
    assert [p.name for p in hal.pins()] == pins
    hal.unloadrt(name)
    assert _cases_of(name), f"no differential test for {name}"
