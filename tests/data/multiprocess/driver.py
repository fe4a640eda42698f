"""Attached test process driven by the test over stdin/stdout.

Attaches to the HAL instance named by ``$HALSDK_INSTANCE`` (it must
exist: ``create=False``), prints one JSON line
``{"ready": true, "pid": ..., "is_host": ...}`` and then serves commands,
one JSON object per line on stdin, with one JSON reply line each:

``{"call": method, "args": [...], "kwargs": {...}}``
    call ``Hal.<method>``; reply ``{"ok": true, "result": ...}`` or
    ``{"ok": false, "class": exception class name, "error": message}``.
    Handles in results are replaced by their names.
``{"call": "add_python_function", "args": [name]}``
    try to export a do-nothing Python function (host only).
``{"hold_lock": seconds}``
    print ``{"locking": pid}``, then hold the instance mutex for that long
    (the test kills this process meanwhile).
``{"exit": true}``
    close the instance and exit.
"""

import json
import os
import sys

import halsdk
from halsdk.core import _core


def plain(value):
    """A JSON-friendly form of a result."""
    if isinstance(value, _core.Item):
        return value.name
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)


def reply(obj) -> None:
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def main() -> int:
    hal = halsdk.Hal(create=False)
    reply({"ready": True, "pid": os.getpid(), "is_host": hal.is_host,
           "instance": hal.instance})
    for line in sys.stdin:
        cmd = json.loads(line)
        if cmd.get("exit"):
            break
        if "hold_lock" in cmd:
            reply({"locking": os.getpid()})
            _core.hold_lock_for_test(float(cmd["hold_lock"]))
            reply({"ok": True, "result": None})
            continue
        method = cmd["call"]
        args = cmd.get("args", [])
        kwargs = cmd.get("kwargs", {})
        try:
            if method == "add_python_function":
                result = hal.add_python_function(args[0], lambda period: None,
                                                 *args[1:], **kwargs)
            else:
                result = getattr(hal, method)(*args, **kwargs)
        except Exception as exc:
            reply({"ok": False, "class": type(exc).__name__,
                   "error": str(exc)})
        else:
            reply({"ok": True, "result": plain(result)})
    hal.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
