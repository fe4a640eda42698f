"""A test component for the netlist checker: ``loadrt iopin``.

Makes ``iopin.data`` (bit, io), ``iopin.out`` (bit, out) and the
function ``iopin`` (does nothing).
"""

from __future__ import annotations

from halsdk.core import _core

_comp_id = -1


def setup(**params: object) -> None:
    global _comp_id
    _comp_id = _core.comp_new("iopin", _core.COMP_RT)
    _core.pin_new("iopin.data", _core.BIT, _core.IO, _comp_id)
    _core.pin_new("iopin.out", _core.BIT, _core.OUT, _comp_id)
    _core.export_python("iopin", lambda period: None, _comp_id)
    _core.comp_ready(_comp_id, True)
