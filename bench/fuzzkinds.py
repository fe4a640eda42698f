"""The input kinds of the reliability campaign (bench/reliability.py).

Each kind has a corpus of valid inputs taken from the tree (HAL files,
``.comp`` files, G-code, INI files, driver configurations, channel frames),
a mutator that turns corpus entries into odd inputs, and a runner that
feeds one input to the code under test the way a user's input reaches it.
A runner returns normally when the input was taken or refused with the
code's documented error; any other exception is a traceback (the finding
the campaign counts).  Crashes and hangs are seen by the caller, which
runs the runners in worker processes.

The shared-memory kind lives in bench/segment_fuzz.py.
"""

from __future__ import annotations

import glob
import os
import random
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Optional

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)

#: values that have found bugs in parsers before: limits, special floats,
#: odd quoting, long and non-ASCII words
ODD_TOKENS = [
    "", "0", "-0", "1", "-1", "2147483647", "2147483648", "-2147483649",
    "4294967295", "4294967296", "18446744073709551616", "1e308", "1e309",
    "-1e309", "nan", "NaN", "inf", "-inf", "0x", "0x7fffffff", "1.5.5",
    "TRUE", "false", "yes", "\"", "'", "\"\"", "[", "]", "[X]Y", "$",
    "${", "$HOME", "\\", "#", ";", "=", "==", "<=", "->", "=>", "<=>",
    ".", "..", "a" * 200, "é", "\u202e", "\x00", "\t", "\r", "(", ")",
    "*", "%", "/", "-", "+", "O", "o100", "#<_x>", "[1/0]", "[SQRT[-1]]",
]


@dataclass
class Kind:
    """One kind of input: corpus, runner and the errors it may raise."""

    name: str
    corpus: list[str]
    run: Callable[[str, Workspace], None]
    mutate: Callable[[random.Random, list[str]], str]
    setup: Optional[Callable[[Workspace], None]] = None


@dataclass
class Workspace:
    """What a worker keeps between inputs: a temp folder and the objects
    a kind set up (a HAL instance for the HAL kind)."""

    folder: str
    state: dict[str, Any] = field(default_factory=dict)

    def write(self, name: str, text: str) -> str:
        path = os.path.join(self.folder, name)
        with open(path, "w", encoding="utf-8", errors="surrogatepass") as f:
            f.write(text)
        return path


# ------------------------------------------------------------ mutation

def _mutate_lines(rng: random.Random, corpus: list[str]) -> str:
    """Line and token edits of one corpus entry, sometimes spliced with
    lines of another: what a typo, a bad merge or a truncated copy
    makes."""
    lines = rng.choice(corpus).splitlines()
    if rng.random() < 0.3:
        other = rng.choice(corpus).splitlines()
        if other:
            at = rng.randrange(len(lines) + 1)
            lines[at:at] = rng.sample(other, min(len(other),
                                                 rng.randint(1, 5)))
    for _ in range(rng.randint(1, 6)):
        if not lines:
            lines.append(rng.choice(ODD_TOKENS))
            continue
        at = rng.randrange(len(lines))
        op = rng.randrange(8)
        if op == 0:
            del lines[at]
        elif op == 1:
            lines.insert(at, lines[at])
        elif op == 2:
            b = rng.randrange(len(lines))
            lines[at], lines[b] = lines[b], lines[at]
        elif op == 3:
            lines[at] = lines[at][:rng.randint(0, len(lines[at]))]
        else:
            words = lines[at].split(" ")
            w = rng.randrange(len(words))
            if op == 4:
                words[w] = rng.choice(ODD_TOKENS)
            elif op == 5:
                words.insert(w, rng.choice(ODD_TOKENS))
            elif op == 6 and words[w]:
                c = rng.randrange(len(words[w]))
                words[w] = (words[w][:c] + chr(rng.randrange(32, 127))
                            + words[w][c + 1:])
            else:
                words[w] = rng.choice(rng.choice(corpus).split() or [""])
            lines[at] = " ".join(words)
    return "\n".join(lines) + ("\n" if rng.random() < 0.9 else "")


def _mutate_bytes(rng: random.Random, corpus: list[str]) -> str:
    """Byte-level edits of a frame (the channel kind)."""
    data = bytearray(rng.choice(corpus).encode("latin-1"))
    for _ in range(rng.randint(1, 8)):
        op = rng.randrange(4)
        at = rng.randrange(len(data) + 1)
        if op == 0 and data:
            data[min(at, len(data) - 1)] = rng.randrange(256)
        elif op == 1:
            data[at:at] = bytes(rng.randrange(256)
                                for _ in range(rng.randint(1, 4)))
        elif op == 2:
            del data[at:at + rng.randint(1, 4)]
        else:
            word = rng.choice(ODD_TOKENS).encode("utf-8", "surrogatepass")
            data[at:at] = word
    return data.decode("latin-1")


def _files(*patterns: str) -> list[str]:
    texts = []
    for pattern in patterns:
        for path in sorted(glob.glob(os.path.join(REPO, pattern),
                                     recursive=True)):
            with open(path, encoding="utf-8", errors="replace") as f:
                texts.append(f.read())
    return texts


# ------------------------------------------------------------ HAL files

#: commands that would start programs or wait for something outside the
#: input: the campaign feeds HAL text, not a shell
_HAL_SKIPPED = ("loadusr", "waitusr", "unloadusr")


def _hal_corpus() -> list[str]:
    texts = _files("tests/data/halfiles/*.hal", "tests/lcnc-format/*/test.hal",
                   "tests/data/halfiles_lcnc/*.hal", "examples/**/*.hal")
    return [t for t in texts if t.strip()]


def _hal_setup(ws: Workspace) -> None:
    import halsdk
    hal = halsdk.Hal(create=True, size=16 * 1024 * 1024)
    ws.state["hal"] = hal


def _hal_run(text: str, ws: Workspace) -> None:
    from halsdk import halcmd
    hal = ws.state["hal"]
    lines = [ln for ln in text.splitlines()
             if not ln.lstrip().lower().startswith(_HAL_SKIPPED)]
    runner = halcmd.CommandRunner(hal, register=False, keep_going=True,
                                  out=lambda s: None, err=lambda s: None)
    try:
        runner.run_lines(lines, "fuzz.hal", keep_going=True)
    except halcmd.Quit:
        pass
    # back to an empty instance for the next input; the instance must
    # still be whole after whatever the input did
    for line in ("unlock all", "stop", "unload all", "delsig all"):
        runner.run_line(line)
    for thread in hal.threads():        # they outlive `unload all`
        hal.delthread(thread.name)
    hal.check()
    left = hal.components()
    if left:
        raise AssertionError(f"unload all left {left}")


# ------------------------------------------------------------ .comp

def _comp_run(text: str, ws: Workspace) -> None:
    from halcompile.gen_cython import CythonSourceError
    from halcompile.parser import CompError
    from halcompile.sources import generate_source
    path = ws.write("fuzz.comp", text)
    try:
        generate_source(path, os.path.join(ws.folder, "gen"))
    except (CompError, CythonSourceError):
        pass


# ------------------------------------------------------------ G-code

def _gcode_run(text: str, ws: Workspace) -> None:
    from halsdk.gcode import GCodeError, Program
    from halsdk.gcode import canon as C
    from halsdk.gcode.interp import Interpreter
    from halsdk.gcode.params import Parameters
    params = Parameters()
    interp = Interpreter(params, None, C.RecordingCanon())
    try:
        interp.run(Program(text, file="fuzz.ngc", params=params))
    except GCodeError:
        pass


# ------------------------------------------------------------ INI files

def _ini_run(text: str, ws: Workspace) -> None:
    from halsdk.ini import IniFile
    from halsdk.machine.inicheck import check_ini
    ini = IniFile(ws.write("fuzz.ini", text))
    check_ini(ini)
    ini.repeats()


# ------------------------------------------------------------ drivers

def _driver_corpus() -> list[str]:
    out = []
    for tag, patterns in (("mb2hal", ("examples/modbus/*.ini",
                                      "tests/lcnc-format/mb2hal-*/*.ini")),
                          ("cia402", ("examples/cia402/drives.ini",)),
                          ("mqtt", ("examples/mqtt/*.conf",)),
                          ("candbc", ("examples/candbc/*.dbc",
                                      "drivers/candbc/*.dbc"))):
        out += [f"#kind {tag}\n{text}" for text in _files(*patterns)]
    return out


def _driver_run(text: str, ws: Workspace) -> None:
    """The configuration readers of the drivers, with their documented
    error (each driver's ConfigError)."""
    first, _, body = text.partition("\n")
    tag = first.split()[-1] if first.startswith("#kind") else "mb2hal"
    if tag == "mb2hal":
        from halsdk.drivers.mb2hal import config as mb
        try:
            mb.load_config(ws.write("fuzz.ini", body))
        except mb.ConfigError:
            pass
    elif tag == "cia402":
        from halsdk.drivers.cia402 import config as co
        try:
            co.load(ws.write("fuzz.ini", body))
        except co.ConfigError:
            pass
    elif tag == "mqtt":
        from halsdk.drivers.mqtt import config as mq
        try:
            mq.read_file(ws.write("fuzz.conf", body), mq.BridgeConfig())
        except mq.ConfigError:
            pass
    else:
        from halsdk.drivers.candbc import dbc
        try:
            dbc.load_dbc(ws.write("fuzz.dbc", body))
        except dbc.ConfigError:
            pass


def _mutate_driver(rng: random.Random, corpus: list[str]) -> str:
    entry = rng.choice(corpus)
    first, _, _ = entry.partition("\n")
    same = [c for c in corpus if c.startswith(first + "\n")]
    text = _mutate_lines(rng, [c.partition("\n")[2] for c in same])
    return f"{first}\n{text}"


# ------------------------------------------------------------ channels

def _channel_corpus() -> list[str]:
    from halsdk.channels import cmdproto
    frames = [
        cmdproto.encode(cmdproto.client_hello(1234, "fuzz")),
        cmdproto.encode({"serial": 1, "command": "state", "args":
                         {"state": 2}}),
        cmdproto.encode({"serial": 2, "command": "mdi", "args":
                         {"line": "G0 X1"}}),
        cmdproto.encode({"serial": 3, "command": "jog", "args":
                         {"kind": 1, "joint_flag": True, "index": 0,
                          "speed": 1.5}}),
        cmdproto.encode({"serial": 4, "command": "program_open",
                         "args": {"path": "/tmp/x.ngc"}}),
    ]
    return [b.decode("latin-1") for b in frames]


def _channel_run(text: str, ws: Workspace) -> None:
    """A task command stream as the task reads it: frames cut from the
    bytes, the hello checked, each command validated."""
    from halsdk.channels import cmdproto
    from halsdk.errors import HalError
    reader = cmdproto.FrameReader()
    data = text.encode("latin-1")
    try:
        # arrives in pieces, as a socket delivers it
        for at in range(0, len(data), 7):
            reader.feed(data[at:at + 7])
            for frame in reader.frames():
                if "pid" in frame and "command" not in frame:
                    cmdproto.parse_client_hello(frame)
                else:
                    cmdproto.validate(frame.get("command"),
                                      frame.get("args"))
    except HalError:
        pass


def kinds() -> dict[str, Kind]:
    return {k.name: k for k in (
        Kind("hal", _hal_corpus(), _hal_run, _mutate_lines, _hal_setup),
        Kind("comp", _files("components/*.comp"), _comp_run,
             _mutate_lines),
        Kind("gcode", _files("tests/data/gcode/*.ngc", "examples/**/*.ngc",
                             "tests/gcode/programs/*.ngc"),
             _gcode_run, _mutate_lines),
        Kind("ini", _files("examples/**/*.ini", "tests/data/machine/*.ini",
                           "halsdk/demo/mill/*.ini"),
             _ini_run, _mutate_lines),
        Kind("driver", _driver_corpus(), _driver_run, _mutate_driver),
        Kind("channel", _channel_corpus(), _channel_run, _mutate_bytes),
    )}


def make_input(kind: Kind, seed: int, index: int) -> str:
    rng = random.Random(seed * 1_000_003 + index)
    return kind.mutate(rng, kind.corpus)


def new_workspace() -> Workspace:
    return Workspace(tempfile.mkdtemp(prefix="halsdk-fuzz-"))


__all__ = ["Kind", "Workspace", "kinds", "make_input", "new_workspace",
           "ODD_TOKENS"]
