"""The paho side: a client whose network loop runs in its own thread and
reports to the HAL side only through a queue of events."""

from __future__ import annotations

import collections
import ssl
import threading
from typing import Any, Optional

import paho.mqtt.client as mqtt
from paho.mqtt.enums import CallbackAPIVersion

from .config import BridgeConfig, ConfigError

#: events: ("up",), ("refused", words), ("fail", words), ("lost", words),
#: ("msg", topic, payload)
Event = tuple


class _Client(mqtt.Client):
    """Remembers why the last connection attempt failed (paho's own
    on_connect_fail callback does not say)."""

    last_error: Optional[BaseException] = None

    def reconnect(self) -> Any:
        try:
            return super().reconnect()
        except OSError as exc:
            self.last_error = exc
            raise


#: received messages waiting for the HAL side; more are dropped (counted)
MAX_PENDING = 10000


class Link:
    """One MQTT connection.  Nothing here blocks the caller: the connection
    is made and remade (with doubling delays) by paho's network thread;
    its callbacks only append to :attr:`events`."""

    def __init__(self, cfg: BridgeConfig, topics: list[str],
                 status_topic: str = ""):
        self.cfg = cfg
        self.topics = topics
        self.status_topic = status_topic
        self.events: collections.deque[Event] = collections.deque()
        self.dropped = 0          # messages over MAX_PENDING, never applied
        self.up = False           # written by the network thread only
        self._refused = False
        client = _Client(CallbackAPIVersion.VERSION2,
                         client_id=cfg.client_id,
                         protocol=mqtt.MQTTv311)
        # paho annotates the delays as int but waits float seconds
        client.reconnect_delay_set(
            cfg.backoff, cfg.backoff_max)  # type: ignore[arg-type]
        client.connect_timeout = 3.0
        client.max_queued_messages_set(10000)
        if cfg.user:
            client.username_pw_set(cfg.user, cfg.password or None)
        if cfg.use_tls:
            self._tls(client)
        if status_topic:
            client.will_set(status_topic, "offline", qos=1, retain=True)
        client.on_connect = self._on_connect
        client.on_connect_fail = self._on_connect_fail
        client.on_disconnect = self._on_disconnect
        client.on_message = self._on_message
        self.client = client

    def _tls(self, client: mqtt.Client) -> None:
        cfg = self.cfg
        try:
            client.tls_set(
                ca_certs=cfg.tls_ca or None,
                certfile=cfg.tls_cert or None, keyfile=cfg.tls_key or None,
                cert_reqs=ssl.CERT_NONE if cfg.tls_insecure
                else ssl.CERT_REQUIRED)
        except (OSError, ValueError) as exc:   # ssl.SSLError is an OSError
            raise ConfigError(f"{cfg.name}: TLS files: {exc}") from None
        if cfg.tls_insecure:
            client.tls_insecure_set(True)

    # -- network thread ----------------------------------------------------
    def _on_connect(self, client, userdata, flags, reason, properties):
        if reason.is_failure:
            self.up = False
            self._refused = True
            self.events.append(("refused", str(reason)))
            return
        self.up = True
        if self.topics:
            client.subscribe([(t, self.cfg.qos) for t in self.topics])
        if self.status_topic:
            client.publish(self.status_topic, "online", qos=1, retain=True)
        self.events.append(("up",))

    def _on_connect_fail(self, client, userdata):
        exc = client.last_error
        words = (exc.strerror or str(exc)) if isinstance(exc, OSError) and \
            exc.strerror else str(exc or "no answer")
        self.events.append(("fail", words))

    def _on_disconnect(self, client, userdata, flags, reason, properties):
        if self.up:
            self.up = False
            self.events.append(("lost", str(reason)))
        elif not self._refused:     # dropped before the broker answered
            self.events.append(("fail", "closed by the broker before it "
                                f"answered ({reason})"))
        self._refused = False

    def _on_message(self, client, userdata, message):
        # a flood of messages must not grow memory without end
        if len(self.events) >= MAX_PENDING:
            self.dropped += 1
            return
        self.events.append(("msg", message.topic, message.payload))

    # -- HAL side ----------------------------------------------------------
    def start(self) -> None:
        """Begin connecting in the background; returns at once."""
        cfg = self.cfg
        self.client.connect_async(cfg.broker, cfg.broker_port, cfg.keepalive)
        self.client.loop_start()

    def publish(self, topic: str, payload: str) -> bool:
        """Queue a message; False when it was not accepted (offline)."""
        if not self.up:
            return False
        info = self.client.publish(topic, payload, self.cfg.qos,
                                   self.cfg.retain)
        return info.rc == mqtt.MQTT_ERR_SUCCESS

    def stop(self, timeout: float = 3.0) -> None:
        """Say goodbye and end the network thread (bounded wait)."""
        client = self.client
        if self.up and self.status_topic:
            # acknowledged before the disconnect: a clean disconnect
            # does not send the last will, so this must not be lost
            info = client.publish(self.status_topic, "offline", qos=1,
                                  retain=True)
            try:
                info.wait_for_publish(min(timeout, 1.0))
            except (RuntimeError, ValueError):
                pass            # not connected: the broker has the will
        client.disconnect()
        ender = threading.Thread(target=client.loop_stop, daemon=True,
                                 name="mqtt-stop")
        ender.start()
        ender.join(timeout)
