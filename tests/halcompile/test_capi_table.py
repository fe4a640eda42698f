"""The table of LinuxCNC header names in docs/compat.md ("The LinuxCNC
headers, name by name") against halsdk's headers (issue 18): each name
the table calls provided (or provided with a difference) is declared by
the header of its row, each name it calls not provided is not, and a
header not provided at all does not exist.  One probe is compiled per
name (provided names of one header share a file, and are probed one by
one only when that file fails)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from concurrent.futures import ThreadPoolExecutor

import pytest

from halsdk.build import include_dir

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
COMPAT = os.path.join(ROOT, "docs", "compat.md")
ROW = re.compile(r"^\| `([^`]+)` \| `([^`]+)` \| (provided|differs|"
                 r"not provided) \|")
WHOLE = "(whole header)"

pytestmark = pytest.mark.skipif(shutil.which("cc") is None,
                                reason="no C compiler")


def table() -> list[tuple[str, str, str]]:
    with open(COMPAT, encoding="utf-8") as f:
        text = f.read()
    start = text.index("### The LinuxCNC headers, name by name")
    rows = []
    for line in text[start:].splitlines():
        if line.startswith("## "):
            break
        m = ROW.match(line)
        if m:
            rows.append((m.group(1), m.group(2), m.group(3)))
    return rows


def probe(name: str, index: int) -> str:
    """C that compiles only if ``name`` (a macro, function, variable,
    constant, type or ``struct``/``union``/``enum`` tag) is declared."""
    ident = name.split()[-1]
    # a tag must be complete: naming an unknown one declares it
    use = f"(void)sizeof({name});" if " " in name else \
        f"__typeof__({name}) *p = 0;\n    (void)p;"
    return (f"#ifndef {ident}\n"
            f"void halsdk_probe_{index}(void)\n{{\n"
            f"    {use}\n}}\n"
            "#endif\n")


def compiles(header: str, body: str, tmp: str, tag: str) -> tuple[bool,
                                                                   str]:
    path = os.path.join(tmp, f"probe-{tag}.c")
    with open(path, "w", encoding="utf-8") as f:
        f.write(f'#include "{header}"\n{body}')
    proc = subprocess.run(
        ["cc", "-fsyntax-only", "-std=gnu11", "-DRTAPI",
         "-Werror=implicit-function-declaration", "-I", include_dir(),
         path], capture_output=True, text=True)
    return proc.returncode == 0, proc.stderr


def test_the_table_lists_every_reference_header():
    headers = {h for h, _, _ in table()}
    assert {"hal.h", "rtapi.h", "rtapi_app.h", "rtapi_mutex.h",
            "rtapi_string.h", "rtapi_pci.h"} <= headers
    assert len(table()) > 300


def test_provided_names_are_declared(tmp_path):
    by_header: dict[str, list[str]] = {}
    for header, name, status in table():
        if status != "not provided":
            by_header.setdefault(header, []).append(name)

    def check(item: tuple[str, list[str]]) -> list[str]:
        header, names = item
        tag = header.replace(".", "_")
        body = "".join(probe(n, i) for i, n in enumerate(names))
        ok, _ = compiles(header, body, str(tmp_path), tag)
        if ok:
            return []
        missing = []
        for i, n in enumerate(names):
            ok, err = compiles(header, probe(n, i), str(tmp_path),
                               f"{tag}-{i}")
            if not ok:
                missing.append(f"{header}: {n}: {err.strip()[:300]}")
        return missing

    with ThreadPoolExecutor(max_workers=2) as pool:
        missing = sum(pool.map(check, sorted(by_header.items())), [])
    assert not missing, "\n".join(missing)


def test_names_not_provided_are_not_declared(tmp_path):
    rows = [(h, n) for h, n, s in table() if s == "not provided"]
    whole = {h for h, n in rows if n == WHOLE}
    for header in whole:
        assert not os.path.exists(os.path.join(include_dir(), header)), \
            f"{header} exists but the table says it is not provided"

    def check(item: tuple[int, tuple[str, str]]) -> str:
        i, (header, name) = item
        if name == WHOLE:
            return ""
        ok, _ = compiles(header, probe(name, i), str(tmp_path), f"n{i}")
        return f"{header}: {name} is declared" if ok else ""

    with ThreadPoolExecutor(max_workers=2) as pool:
        found = [r for r in pool.map(check, enumerate(rows)) if r]
    assert not found, "\n".join(found)
