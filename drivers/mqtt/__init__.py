"""MQTT bridge for HAL: publish pins, params and signals as JSON and drive
pins from subscribed topics (programs ``mqtt-publisher`` and
``mqtt-bridge``)."""

from halsdk.drivers.mqtt.bridge import Bridge
from halsdk.drivers.mqtt.config import BridgeConfig, ConfigError
from halsdk.drivers.mqtt.payload import PayloadError

__all__ = ["Bridge", "BridgeConfig", "ConfigError", "PayloadError"]
