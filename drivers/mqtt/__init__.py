"""MQTT bridge for HAL: publish pins, params and signals as JSON and drive
pins from subscribed topics (programs ``mqtt-publisher`` and
``mqtt-bridge``)."""

from .bridge import Bridge
from .config import BridgeConfig, ConfigError
from .payload import PayloadError

__all__ = ["Bridge", "BridgeConfig", "ConfigError", "PayloadError"]
