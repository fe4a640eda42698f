"""``import hal`` for LinuxCNC programs: this module is replaced by
:mod:`halsdk.compat.hal` when imported, so ``hal`` and
``halsdk.compat.hal`` are the same module object."""

import sys

from halsdk.compat import hal as _compat_hal

sys.modules[__name__] = _compat_hal
