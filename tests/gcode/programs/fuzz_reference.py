#!/usr/bin/env python3
"""Differential fuzzing: random programs through the reference and ours.

    python3 tests/gcode/programs/fuzz_reference.py [--seed N] [--count N]
        [--reference PATH] [--keep DIR]

Each program is a few random lines of G/M codes and words (a feed rate
first, M2 last). The reference's ``rs274 -g`` runs it in a fresh folder
(one at a time, at most 20 s each) and our rs274 runs it in-process; a
program whose standard output (``-0.0000`` read as ``0.0000``), exit
status or standard error (without our ``FILE:LINE:COL:`` before each
message) differs is printed with the reference's message and saved in
``--keep`` (default rs274-fuzz in the temp folder) as ``misN.ngc``: copy the useful
ones to ``errors/`` and run regenerate.py on them. Run by hand, never by
the test suite (it needs the reference).
"""

from __future__ import annotations

import argparse
import io
import os
import random
import re
import subprocess
import sys
import tempfile

from halsdk.gcode.rs274 import run

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from regenerate import DEFAULT_REFERENCE, run_reference  # noqa: E402

CODES = ["G0", "G1", "G2", "G3", "G17", "G18", "G19", "G20", "G21", "G90",
         "G91", "G54", "G55", "G92", "G92.1", "G28", "G81", "G83", "G80",
         "G43 H1", "G49", "M3", "M5", "M8", "M9", "G61", "G64", "G93", "G94",
         "G10 L2 P2", "G10 L20 P1", "G98", "G99", "T2 M6", "G4 P1",
         "G41 D1", "G42 D2", "G40", "G5", "G5.1", "G7", "G8", "G73",
         "G82 P1", "G85", "G89 P1", "G30", "G92.2", "G92.3", "M70", "M72",
         "G43.2 H2", "G59", "G10 L2 P1 R15", "M19", "G95", "G33",
         "G76 P0.1"]


def program(rnd: random.Random) -> str:
    lines = ["F100"]
    for _ in range(rnd.randint(2, 7)):
        words = rnd.sample(CODES, rnd.randint(0, 2))
        for letter in rnd.sample("XYZIJKRQ", rnd.randint(0, 3)):
            words.append(f"{letter}{rnd.randint(-8, 8) / 2:g}")
        lines.append(" ".join(words))
    return "\n".join(lines + ["M2"]) + "\n"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--count", type=int, default=100)
    p.add_argument("--reference", default=DEFAULT_REFERENCE)
    p.add_argument("--keep", default=os.path.join(tempfile.gettempdir(),
                                                  "rs274-fuzz"))
    a = p.parse_args()
    rnd = random.Random(a.seed)
    os.makedirs(a.keep, exist_ok=True)
    differ = 0
    for n in range(a.count):
        text = program(rnd)
        with tempfile.TemporaryDirectory(prefix="rs274-fuzz-") as tmp:
            os.chmod(tmp, 0o755)
            path = os.path.join(tmp, "p.ngc")
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
            os.chmod(path, 0o644)
            try:
                done = run_reference([a.reference, "rs274", "-g",
                                      "p.ngc"], tmp, 20)
                ref = subprocess.CompletedProcess(
                    done.args, done.returncode,
                    done.stdout.decode("utf-8", "replace"),
                    done.stderr.decode("utf-8", "replace"))
            except subprocess.TimeoutExpired:
                print(f"{n}: the reference timed out")
                continue
        out, err = io.StringIO(), io.StringIO()
        status = run(text, "p.ngc", out.write, err.write)
        ours = out.getvalue().replace("-0.0000", "0.0000")
        theirs = ref.stdout.replace("-0.0000", "0.0000")
        ours_err = re.sub(r"^p\.ngc:\d+:\d+: ", "", err.getvalue(),
                          flags=re.M)
        theirs_err = ref.stderr.removeprefix("executing\n")
        if (ours, status, ours_err) != (theirs, ref.returncode, theirs_err):
            differ += 1
            with open(os.path.join(a.keep, f"mis{n}.ngc"), "w",
                      encoding="utf-8") as f:
                f.write(text)
            message = ref.stderr.replace("executing", "").strip()
            print(f"{n}: differs (ours {status}, reference "
                  f"{ref.returncode}) {message.splitlines()[:1]} "
                  f"{ours_err.splitlines()[:1]}")
    print(f"{a.count - differ} of {a.count} programs match")
    return 0


if __name__ == "__main__":
    sys.exit(main())
