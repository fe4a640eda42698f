# the [PYTHON]TOPLEVEL of the remap programs: it imports the modules the
# interpreter looks in (written for halsdk's tests, not copied)
import namedparams  # noqa: F401
import oword  # noqa: F401
import remap  # noqa: F401


def __init__(self):
    self.params["_init_seen"] = 42
