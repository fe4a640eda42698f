"""mb2hal: a userspace HAL component that exchanges values with Modbus
devices (TCP or RTU), configured by a reference-compatible INI file."""

from .config import (
    FUNCTIONS,
    Config,
    ConfigError,
    Link,
    Transaction,
    load_config,
)
from .engine import Mb2hal

__all__ = ["FUNCTIONS", "Config", "ConfigError", "Link", "Transaction",
           "load_config", "Mb2hal"]
