"""can-dbc: CAN signals mapped to HAL pins through a DBC file."""

from .dbc import ConfigError, SignalPin, load_dbc
from .driver import CanDbcDriver
from .names import hal_name
from .options import Config, parse_args

__all__ = ["CanDbcDriver", "Config", "ConfigError", "SignalPin",
           "hal_name", "load_dbc", "parse_args"]
