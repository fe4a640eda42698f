"""``import linuxcnc`` for LinuxCNC scripts: this module is replaced by
:mod:`halsdk.compat.linuxcnc` when imported, so ``linuxcnc`` and
``halsdk.compat.linuxcnc`` are the same module object."""

import sys

from halsdk.compat import linuxcnc as _linuxcnc

sys.modules[__name__] = _linuxcnc
