"""Running halcmd and halrun as a user does, and comparing their output
with the reference's recorded output.

:func:`normalize` removes what cannot match between the reference and
halsdk:

1. the reference's ``Note: Using POSIX non-realtime`` lines (printed by
   its realtime start/stop scripts, at a timing-dependent place);
2. the pid in the name and PID column of the ``halcmd<pid>`` component;
3. component ids (``show comp`` ID column, pin/param/funct Owner
   column): the reference's ids have gaps from its helper processes;
4. function code and argument addresses (``show funct``, also in the
   ``-s`` format).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

NOTE = "Note: Using POSIX non-realtime"
#: the tools a HAL file of the streams corpus starts with loadusr
TOOLS = ("halsampler", "halstreamer")

_COMP_ROW = re.compile(r"^ [ \d]{4}\d  (RT  |User)  ")
_ITEM_ROW = re.compile(r"^ [ \d]{4}\d(  (bit  |float|s32  |u32  |s64  |u64  )"
                       r" (IN |OUT|I/O|RO |RW )  )")
_FUNCT_ROW = re.compile(r"^ \d{5}  [0-9a-f ]{12}  [0-9a-f ]{12}  ")
_SCRIPT_FUNCT_ROW = re.compile(r"^(\S+) [0-9a-f]+ [0-9a-f]+ (YES|NO) ")


def normalize(text: str) -> str:
    """Remove what cannot match between the reference and halsdk."""
    out = []
    for line in text.splitlines(True):
        if line.rstrip("\n") == NOTE:
            continue
        if _COMP_ROW.match(line) and len(line) > 67:
            name = re.sub(r"^halcmd\d+", "halcmd<PID>", line[14:61].strip())
            pid = "  PID" if line[8:12] == "User" else line[62:67]
            line = ("    ID" + line[6:14] + f"{name:<47}" + line[61]
                    + pid + line[67:])
            out.append(line)
            continue
        line = re.sub(r"halcmd\d+", "halcmd<PID>", line)
        if _ITEM_ROW.match(line):
            line = "    ID" + line[6:]
        elif _FUNCT_ROW.match(line):
            line = " IDIDI  <code-addr>   <arg-addr>    " + line[36:]
        else:
            line = _SCRIPT_FUNCT_ROW.sub(r"\1 <code-addr> <arg-addr> \2 ",
                                         line)
        out.append(line)
    return "".join(out)


def halcmd_env(tmp_path: Path, name: str) -> dict:
    """The environment of a halcmd/halrun child: its own instance, and the
    variables the corpus substitutes."""
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = f"t3-{os.getpid()}-{name}"
    env["HALTEST_WORD"] = "bar"
    env.pop("HALTEST_NOPE", None)
    return env


def run_cli(args: list[str], cwd: Path, env: dict,
            stdin: str = "") -> subprocess.CompletedProcess:
    """``python -m halsdk.halcmd.cli ARGS`` (halcmd or halrun), stdout and
    stderr together."""
    return subprocess.run(
        [sys.executable, "-m", "halsdk.halcmd.cli", *args], cwd=cwd,
        env=env, input=stdin, stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT, text=True, timeout=60)


def shm_left(env: dict) -> list[str]:
    """The /dev/shm files of the child's instance."""
    tag = env["HALSDK_INSTANCE"]
    return [n for n in os.listdir("/dev/shm") if tag in n]


def tools_env(name: str, tools: Path) -> dict:
    """The environment of a halrun child whose HAL files start
    ``halsampler``/``halstreamer``: its own instance, and this Python's
    tools first on PATH (scripts written into ``tools``)."""
    env = dict(os.environ)
    env["HALSDK_INSTANCE"] = f"tc-{os.getpid()}-{name}"
    # the tools of this Python's halsdk, first on PATH: a halsampler of
    # another installation (an older one on PATH) would not attach
    tools.mkdir(exist_ok=True)
    for tool in TOOLS:
        script = tools / tool
        script.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m '
                          f'halsdk.tools.{tool} "$@"\n')
        script.chmod(0o755)
    env["PATH"] = f"{tools}{os.pathsep}{env.get('PATH', '')}"
    return env
