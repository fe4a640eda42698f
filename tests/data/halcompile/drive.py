"""Drive compiled realtime components the same way and print what they do.

    python drive.py OUT.json NAME[:LOADARGS] ...

Every module is loaded from HALSDK_PATH into a private halsdk instance of
this process, one after the other (each module only once, so the C
globals of each start fresh).  For each: the pins, params (value after the
load) and functions it made; then its functions are added, sorted by name,
to a 1 ms thread and stepped three times, every unconnected ``in`` pin
being set before each step to a value made from the step and its place;
the values of all its pins and params after each step are recorded.  The
function timing pins and params are left out.

Used by tests/golden/test_halcompile_corpus.py on our builds of the ``.comp``
files, and by make_goldens.py on builds of the C the reference's
halcompile generates for the same files.
"""

from __future__ import annotations

import json
import os
import sys

import halsdk

PERIOD = 1_000_000
STEPS = 3
TIMING = (".time", ".tmax", ".tmax-increased")
TYPES = {1: "bit", 2: "float", 3: "s32", 4: "u32", 6: "s64", 7: "u64"}
DIRS = {16: "in", 32: "out", 48: "io", 64: "ro", 192: "rw"}


def _input(type_: int, step: int, place: int):
    if type_ == 1:
        return (step + place) % 2 == 1
    if type_ == 2:
        return (step + 1) * 0.75 - place * 0.5
    if type_ in (3, 6):
        return step * 3 - place
    return step * 5 + place


def _own(handles, before: set) -> list:
    return [h for h in handles if h.name not in before
            and not h.name.endswith(TIMING)]


def drive(hal: halsdk.Hal, name: str, args: list[str]) -> dict:
    pins0 = {p.name for p in hal.pins()}
    params0 = {p.name for p in hal.params()}
    functs0 = {f.name for f in hal.functions()}
    hal.loadrt(name, *args)
    pins = _own(hal.pins(), pins0)
    params = _own(hal.params(), params0)
    functs = sorted(f.name for f in hal.functions()
                    if f.name not in functs0)
    out = {
        "pins": [[p.name, TYPES[p.type], DIRS[p.direction], p.value]
                 for p in pins],
        "params": [[p.name, TYPES[p.type], DIRS[p.direction], p.value]
                   for p in params],
        "functions": functs,
        "steps": [],
    }
    hal.newthread("drive", PERIOD)
    for f in functs:
        hal.addf(f, "drive")
    inputs = [p for p in pins if p.direction == 16 and not p.linked]
    for step in range(STEPS):
        for place, p in enumerate(inputs):
            hal.setp(p.name, _input(p.type, step, place))
        hal.step()
        out["steps"].append({p.name: p.value for p in pins + params})
    hal.delthread("drive")
    hal.unloadrt(name)
    return out


def main(argv: list[str]) -> int:
    result = {}
    with halsdk.Hal(instance=f"drive{os.getpid()}", create=True) as hal:
        for word in argv[1:]:
            name, _, args = word.partition(":")
            result[word] = drive(hal, name, args.split())
    with open(argv[0], "w", encoding="utf-8") as f:
        json.dump(result, f, indent=1, sort_keys=True)
        f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
