"""CANopen CiA 402 drive driver for halsdk (program ``cia402``), with a
simulated drive (:mod:`halsdk.drivers.cia402.sim`)."""

import os

#: the generic CiA 402 EDS shipped with the driver
DEFAULT_EDS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                           "cia402.eds")
