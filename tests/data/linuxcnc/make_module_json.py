"""Remake module.json: the names and constant values of the reference's
``linuxcnc`` Python module, the attributes of its ``stat`` (with the type
and tuple length each has before the first poll), the methods of
``command``, ``error_channel`` and ``ini``, and the fields of a tool
table entry.  tests/compat/test_linuxcnc_module.py checks ours against it.

    cd tests/data/linuxcnc
    ../../../../shared/tools/reference python3 make_module_json.py

(the reference tool runs in a copy of the current folder and copies the
files written back; $HALSDK_REFERENCE may name another command).  Run by
the reference's Python: no halsdk import here.
"""

import json

import linuxcnc


def kind(value):
    if isinstance(value, tuple):
        inner = type(value[0]).__name__ if value else ""
        return f"tuple[{len(value)}]" + (f" of {inner}" if inner else "")
    return type(value).__name__


def public(obj):
    return sorted(n for n in dir(obj) if not n.startswith("_"))


constants, strings, others = {}, [], []
for name in public(linuxcnc):
    value = getattr(linuxcnc, name)
    if isinstance(value, int):
        constants[name] = value
    elif isinstance(value, str):
        strings.append(name)
    else:
        others.append(name)
s = linuxcnc.stat()
stat = {n: kind(getattr(s, n)) for n in public(s) if n != "poll"}
tool_fields = [f for f in public(linuxcnc.tool)
               if f not in ("count", "index", "n_fields",
                            "n_sequence_fields", "n_unnamed_fields")]
data = {
    "constants": constants,
    "strings": strings,
    "objects": others,
    "stat": stat,
    "stat_methods": ["poll"],
    "command": public(linuxcnc.command),
    "error_channel": public(linuxcnc.error_channel),
    "ini": public(linuxcnc.ini),
    "tool_result": tool_fields,
}
with open("module.json", "w") as f:
    json.dump(data, f, indent=1, sort_keys=True)
    f.write("\n")
