"""The import graph follows the layers of docs/architecture.rst.

Every Python and Cython source of the package is read (not imported) and
each of its imports of halsdk or halcompile is checked against the layer
rules: a lower layer never imports a higher one, only the public layer
imports the core, the shipped components and drivers see only the public
layer (and the driver kit), and nothing installed needs halcompile at run
time.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest
from helpers import REPO

ROOT = REPO

#: the layers, lowest first
CORE, PUBLIC, TOOLS, APPS = "core", "public", "tools", "apps"
COMPONENTS, DRIVERS, COMPILER = "components", "drivers", "halcompile"

#: subpackages of halsdk and their layer (modules at the root of halsdk
#: are the public layer)
SUBPACKAGES = {
    "core": CORE,
    "halcmd": TOOLS, "tools": TOOLS, "compat": TOOLS, "driverkit": TOOLS,
    "channels": TOOLS,
    "machine": APPS, "web": APPS, "motion": APPS, "gcode": APPS, "demo": APPS,
    "components": COMPONENTS, "drivers": DRIVERS,
}

#: what each layer may import (besides itself)
ALLOWED = {
    CORE: set(),
    PUBLIC: {CORE},
    TOOLS: {PUBLIC},
    APPS: {PUBLIC, TOOLS},
    COMPONENTS: {PUBLIC},
    DRIVERS: {PUBLIC, TOOLS},
    COMPILER: {PUBLIC},
}

#: the one call that goes up, and why: Hal.source() and Hal.command()
#: run the HAL language, whose one parser and executor is halcmd's
#: (DESIGN.md section 6); they import it when called
UPWARD = {("halsdk.hal", "halsdk.halcmd"):
          "Hal.source()/Hal.command() run halcmd's executor"}

_PYX_IMPORT = re.compile(
    r"^\s*(?:from\s+(\.*[\w.]*)\s+c?import\s+([\w, ]+)|c?import\s+([\w.]+))",
    re.MULTILINE)


def layer_of(module: str) -> str | None:
    """The layer of a module of ours, None for anything else."""
    parts = module.split(".")
    if parts[0] == "halcompile":
        return COMPILER
    if parts[0] != "halsdk":
        return None
    if len(parts) == 1:
        return PUBLIC
    return SUBPACKAGES.get(parts[1], PUBLIC)


def module_name(path: Path) -> str:
    """The installed name of a source file of the checkout."""
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[0] in ("components", "drivers"):
        parts = ["halsdk", *parts]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def sources() -> list[Path]:
    found: list[Path] = []
    for top in ("halsdk", "components", "drivers", "halcompile"):
        for pattern in ("*.py", "*.pyx", "*.pxd"):
            found += (ROOT / top).rglob(pattern)
    return sorted(p for p in found if "pypath" not in p.parts)


def _absolute(module: str, level: int, name: str, package: str) -> str:
    if level == 0:
        return name
    base = package.split(".")
    base = base[:len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def imports_of(path: Path) -> list[tuple[int, str]]:
    """(line, imported module) of every import in a source file; for
    ``from X import y`` both X and X.y (y may be a submodule)."""
    module = module_name(path)
    package = module if path.stem == "__init__" else \
        module.rpartition(".")[0]
    text = path.read_text(encoding="utf-8")
    found: list[tuple[int, str]] = []
    if path.suffix == ".py":
        for node in ast.walk(ast.parse(text, str(path))):
            if isinstance(node, ast.Import):
                found += [(node.lineno, a.name) for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = _absolute(module, node.level, node.module or "",
                                 package)
                found.append((node.lineno, base))
                found += [(node.lineno, f"{base}.{a.name}")
                          for a in node.names]
        return found
    for m in _PYX_IMPORT.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        if m.group(3):
            found.append((line, m.group(3)))
            continue
        dots = len(m.group(1)) - len(m.group(1).lstrip("."))
        base = _absolute(module, dots, m.group(1).lstrip("."), package)
        found.append((line, base))
        found += [(line, f"{base}.{n.strip()}")
                  for n in m.group(2).split(",") if n.strip()]
    return found


def violations() -> list[str]:
    bad = []
    for path in sources():
        module = module_name(path)
        layer = layer_of(module)
        assert layer is not None, module
        for line, target in imports_of(path):
            other = layer_of(target)
            if other is None or other == layer:
                continue
            where = f"{path.relative_to(ROOT)}:{line}"
            if (module, target) in UPWARD:
                continue
            if other not in ALLOWED[layer]:
                bad.append(f"{where}: {layer} module {module} imports "
                           f"{other} module {target}")
    return bad


def test_every_module_has_a_layer():
    assert {layer_of(module_name(p)) for p in sources()} == {
        CORE, PUBLIC, TOOLS, APPS, COMPONENTS, DRIVERS, COMPILER}


def test_no_layer_imports_a_higher_one():
    assert violations() == []


@pytest.mark.parametrize("source, target, allowed", [
    ("halsdk.core.instance", "halsdk.hal", False),
    ("halsdk.hal", "halsdk.core._core", True),
    ("halsdk.halcmd.commands", "halsdk.core._core", False),
    ("halsdk.halcmd.commands", "halsdk.hal", True),
    ("halsdk.motion.client", "halsdk.halcmd", True),
    ("halsdk.hal", "halsdk.halcmd", False),
    ("halsdk.compat.hal", "halsdk.machine", False),
    ("halsdk.web.show", "halsdk.halcmd", True),
    ("halsdk.web.app", "halsdk.core", False),
    ("halsdk.components.threads", "halsdk.core", False),
    ("halsdk.drivers.mqtt.bridge", "halsdk.driverkit", True),
    ("halsdk.userspace", "halcompile.gen_user", False),
    ("halcompile.cli", "halsdk.build", True),
])
def test_the_rules_themselves(source, target, allowed):
    """The checker would catch a wrong import (and pass a right one)."""
    a, b = layer_of(source), layer_of(target)
    assert (a == b or b in ALLOWED[a]) is allowed
