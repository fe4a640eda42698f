"""Options of the MQTT programs: command line, ``keys=`` and config file."""

from __future__ import annotations

import argparse
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NoReturn, Optional

from .payload import TYPES


class ConfigError(Exception):
    """A bad option or config line; the message names where it is."""


@dataclass
class Subscription:
    """A topic that drives the out pin ``<component>.<pin>``."""

    pin: str
    type: str
    topic: str = ""          # '' -> <prefix>/<pin>/set
    where: str = ""          # file:line or option, for messages


@dataclass
class BridgeConfig:
    """Everything one bridge needs; defaults are the bridge's."""

    name: str = "mqtt-bridge"
    broker: str = "127.0.0.1"
    port: Optional[int] = None           # None: 1883, or 8883 with TLS
    user: str = ""
    password: str = ""
    client_id: str = ""
    keepalive: int = 30
    prefix: str = ""                     # '' -> halsdk/<name>
    qos: int = 0
    retain: bool = False
    tls: bool = False
    tls_ca: str = ""
    tls_cert: str = ""
    tls_key: str = ""
    tls_insecure: bool = False
    on_change: bool = True
    period: float = 0.0                  # seconds; 0: no periodic publish
    flat: bool = False                   # batch payload form
    poll: float = 0.02
    backoff: float = 0.5
    backoff_max: float = 30.0
    dryrun: bool = False
    publisher: bool = False              # mqtt-publisher pins/semantics
    publish: list[tuple[str, str]] = field(default_factory=list)
    subscribe: list[Subscription] = field(default_factory=list)

    @property
    def use_tls(self) -> bool:
        return bool(self.tls or self.tls_ca or self.tls_cert)

    @property
    def broker_port(self) -> int:
        if self.port is not None:
            return self.port
        return 8883 if self.use_tls else 1883

    @property
    def topic_prefix(self) -> str:
        return (self.prefix or f"halsdk/{self.name}").rstrip("/")

    def sub_topic(self, sub: Subscription) -> str:
        return sub.topic or f"{self.topic_prefix}/{sub.pin}/set"


# key (as in the config file) -> (attribute, kind)
KEYS = {
    "broker": ("broker", "str"), "port": ("port", "port"),
    "user": ("user", "str"), "password": ("password", "str"),
    "password-file": ("password", "file"),
    "client-id": ("client_id", "str"), "keepalive": ("keepalive", "int"),
    "prefix": ("prefix", "str"), "qos": ("qos", "qos"),
    "retain": ("retain", "bool"), "tls": ("tls", "bool"),
    "tls-ca": ("tls_ca", "path"), "tls-cert": ("tls_cert", "path"),
    "tls-key": ("tls_key", "path"), "tls-insecure": ("tls_insecure", "bool"),
    "on-change": ("on_change", "bool"), "period": ("period", "seconds"),
    "batch-format": ("flat", "format"), "poll": ("poll", "positive"),
    "backoff": ("backoff", "positive"),
    "backoff-max": ("backoff_max", "positive"),
    "dryrun": ("dryrun", "bool"),
}
#: largest poll and reconnect delays, seconds
MAX_WAIT = 3600.0
#: largest batch period, seconds: the range of the publisher's u32 pin
MAX_PERIOD = 2 ** 32 - 1
#: kind -> (lowest, highest) for the integer kinds
INT_LIMITS = {"int": (1, 65535), "port": (1, 65535), "qos": (0, 2)}
TRUE = ("1", "true", "yes", "on")
FALSE = ("0", "false", "no", "off")
ITEM_KINDS = ("pin", "param", "signal")
NAME_RE = re.compile(r"^[A-Za-z0-9_.\-\[\]:]+$")


def _number_problem(kind: str, value: float, publisher: bool,
                    shown: str = "") -> str:
    """Why a number is not valid for its kind ('' when it is)."""
    shown = shown or repr(value)
    if len(shown) > 40:
        shown = shown[:37] + "..."
    try:
        value = float(value)
    except OverflowError:
        return f"{shown} is too large"
    if not math.isfinite(value):
        return f"{shown} is not a finite number"
    if kind == "positive" and not 0 < value <= MAX_WAIT:
        return f"{shown} must be > 0 and at most {MAX_WAIT:g} s"
    if kind == "seconds":
        if not 0 <= value <= MAX_PERIOD:
            return f"{shown} must be in 0..{MAX_PERIOD} s"
        if publisher and not value.is_integer():
            return (f"{shown} is not a whole number of seconds (the "
                    "publisher's period pin is u32)")
    return ""


def _convert(key: str, text: str, where: str, label: str = "",
             publisher: bool = False):
    kind = KEYS[key][1]
    label = label or key
    try:
        if kind in ("str", "path"):
            if kind == "path" and text and not os.path.isfile(text):
                raise ValueError(f"no such file {text!r}")
            return text
        if kind == "file":
            with open(text, encoding="utf-8") as f:
                return f.readline().rstrip("\r\n")
        if kind == "bool":
            if text.lower() in TRUE:
                return True
            if text.lower() in FALSE:
                return False
            raise ValueError(f"{text!r} is not yes/no")
        if kind == "format":
            if text not in ("flat", "full"):
                raise ValueError(f"{text!r} is not 'flat' or 'full'")
            return text == "flat"
        if kind in INT_LIMITS:
            whole = int(text)
            low, high = INT_LIMITS[kind]
            if not low <= whole <= high:
                raise ValueError(f"{whole} is not in {low}..{high}")
            return whole
        value = float(text)
        problem = _number_problem(kind, value, publisher, text)
        if problem:
            raise ValueError(problem)
        return value
    except OSError as exc:
        raise ConfigError(f"{where}: {label}: cannot read {text!r}: "
                          f"{exc.strerror}") from None
    except ValueError as exc:
        text = str(exc)
        if text.startswith(("could not convert", "invalid literal")):
            text = f"not a number: {text.split(': ', 1)[-1]}"
        raise ConfigError(f"{where}: {label}: {text}") from None


def parse_item(spec: str, where: str) -> tuple[str, str]:
    """``[pin:|param:|signal:]NAME`` -> (kind or '', name)."""
    kind, sep, name = spec.partition(":")
    if not sep or kind not in ITEM_KINDS:
        kind, name = "", spec
    if not name or not NAME_RE.match(name):
        raise ConfigError(f"{where}: bad HAL name {spec!r}")
    return kind, name


def parse_subscription(spec: str, where: str) -> Subscription:
    """``PIN:TYPE[:TOPIC]`` (the topic may contain ':')."""
    parts = spec.split(":", 2)
    if len(parts) < 2:
        raise ConfigError(f"{where}: {spec!r}: expected PIN:TYPE[:TOPIC]")
    return _subscription(parts[0], parts[1], parts[2] if len(parts) > 2
                         else "", where)


def _subscription(pin: str, type_: str, topic: str,
                  where: str) -> Subscription:
    pin, type_, topic = pin.strip(), type_.strip().lower(), topic.strip()
    if not pin or not NAME_RE.match(pin):
        raise ConfigError(f"{where}: bad pin name {pin!r}")
    if type_ not in TYPES:
        raise ConfigError(f"{where}: type {type_!r} is not one of "
                          f"{', '.join(TYPES)}")
    if any(c in topic for c in "+#"):
        raise ConfigError(f"{where}: topic {topic!r}: wildcards are not "
                          "allowed")
    return Subscription(pin, type_, topic, where)


def read_file(path: str, cfg: BridgeConfig) -> None:
    """Apply a config file (sections [mqtt], [publish], [subscribe])."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise ConfigError(f"{path}: not a UTF-8 text file") from None
    section = ""
    sections: dict[str, str] = {}     # section -> where it starts
    keys: dict[str, tuple[str, str]] = {}   # attribute -> (key, where)
    published: dict[str, str] = {}          # item name -> where
    for num, line in enumerate(lines, 1):
        where = f"{path}:{num}"
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        if text.startswith("["):
            if not text.endswith("]"):
                raise ConfigError(f"{where}: unclosed section header")
            section = text[1:-1].strip().lower()
            if section not in ("mqtt", "publish", "subscribe"):
                raise ConfigError(f"{where}: unknown section [{section}] "
                                  "(expected mqtt, publish or subscribe)")
            if section in sections:
                raise ConfigError(f"{where}: section [{section}] given "
                                  f"twice (first at {sections[section]})")
            sections[section] = where
            continue
        if section == "publish":
            kind, name = parse_item(text, where)
            if name in published:
                raise ConfigError(f"{where}: item {name!r} published "
                                  f"twice (first at {published[name]})")
            published[name] = where
            cfg.publish.append((kind, name))
        elif section == "subscribe":
            pin, sep, rest = text.partition("=")
            if not sep:
                raise ConfigError(f"{where}: expected PIN = TYPE [TOPIC]")
            words = rest.split(None, 1) or [""]
            cfg.subscribe.append(_subscription(
                pin, words[0], words[1] if len(words) > 1 else "", where))
        elif section == "mqtt":
            key, sep, value = text.partition("=")
            key, value = key.strip().lower(), value.strip()
            if not sep:
                raise ConfigError(f"{where}: expected KEY = VALUE")
            if key not in KEYS:
                raise ConfigError(f"{where}: unknown key {key!r}")
            attr = KEYS[key][0]
            if attr in keys:
                first, at = keys[attr]
                same = "given twice" if first == key else \
                    f"sets the same as {first!r}"
                raise ConfigError(f"{where}: key {key!r} {same} (first at "
                                  f"{at})")
            keys[attr] = (key, where)
            setattr(cfg, attr, _convert(key, value, where,
                                        publisher=cfg.publisher))
        else:
            raise ConfigError(f"{where}: line outside a section")


class _Typed(argparse.Action):
    """Stores the value and remembers the option as the user typed it."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        typed = namespace.__dict__.setdefault("typed_options", {})
        typed[self.dest] = option_string


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # no usage dump, status 1
        raise ConfigError(f"{self.prog}: {message}")


def _parser(prog: str) -> argparse.ArgumentParser:
    p = _Parser(prog=prog, add_help=True, description=(
        "Publish HAL pins, params and signals to an MQTT broker as JSON"
        " and drive pins from subscribed topics."))

    def add(*names: str, **kw) -> None:
        if names[0].startswith("-") and "action" not in kw:
            kw["action"] = _Typed
        p.add_argument(*names, **kw)
    add("-n", "--name", help="component name (and pin prefix)")
    add("-c", "--config", help="config file ([mqtt], [publish], "
        "[subscribe])")
    add("--mqtt-broker", "--broker", dest="broker", help="broker host")
    add("--mqtt-port", "--port", dest="port", help="broker port")
    add("--mqtt-user", "--user", dest="user", help="user name")
    add("--mqtt-password", "--password", dest="password", help="password")
    add("--password-file", help="read the password from this file")
    add("--mqtt-prefix", "--prefix", dest="prefix", help="topic prefix")
    add("--client-id", help="MQTT client id (default: random)")
    add("--keepalive", help="keep-alive interval, seconds (30)")
    add("--qos", help="quality of service 0, 1 or 2 (0)")
    add("--retain", action="store_const", const="yes",
        help="ask the broker to retain published messages")
    add("--tls", action="store_const", const="yes",
        help="connect with TLS, checking the broker against system CAs")
    add("--tls-ca", help="CA certificate file (implies --tls)")
    add("--tls-cert", help="client certificate file (implies --tls)")
    add("--tls-key", help="client private key file")
    add("--tls-insecure", action="store_const", const="yes",
        help="do not verify the broker's certificate (tests only)")
    add("--on-change", action="store_const", const="yes",
        help="publish an item when its value changes")
    add("--no-on-change", dest="on_change", action="store_const",
        const="no", help="do not publish on change")
    add("--period", help="seconds between batch publishes (0: none)")
    add("--batch-format", choices=("flat", "full"),
        help="periodic payload form")
    add("--poll", help="seconds between scans of the HAL values (0.02)")
    add("--backoff", help="first reconnect delay, seconds (0.5)")
    add("--backoff-max", help="largest reconnect delay, seconds (30)")
    add("--publish", "-p", action="append", default=[],
        help="items to publish, comma separated (repeatable)")
    add("--subscribe", "-s", action="append", default=[],
        help="PIN:TYPE[:TOPIC] to create and drive from MQTT")
    add("--dryrun", action="store_const", const="yes",
        help="no broker: print the messages on standard output")
    add("-v", "--verbose", action="store_true", help="log more")
    add("keys", nargs="*", help="keys=item1,item2 (as mqtt-publisher)")
    return p


def parse_args(argv: Sequence[str], publisher: bool = False
               ) -> tuple[BridgeConfig, bool]:
    """Build the configuration; returns it and the verbose flag."""
    prog = "mqtt-publisher" if publisher else "mqtt-bridge"
    args = _parser(prog).parse_args(list(argv))
    cfg = BridgeConfig(name=prog, publisher=publisher)
    if publisher:
        cfg.prefix = "devices/linuxcnc/machine"
        cfg.on_change = False
        cfg.flat = True
        cfg.period = 10.0
    if args.config:
        read_file(args.config, cfg)
    typed = getattr(args, "typed_options", {})
    for key, (attr, _kind) in KEYS.items():
        dest = key.replace("-", "_")
        value = getattr(args, dest, None)
        if value is not None:
            label = typed.get(dest) or f"--{key}"
            setattr(cfg, attr, _convert(key, value, prog, label, publisher))
    if args.name is not None:
        if not args.name or not NAME_RE.match(args.name):
            raise ConfigError(f"{prog}: bad component name {args.name!r}")
        cfg.name = args.name
    for text in args.keys:
        if not text.startswith("keys="):
            raise ConfigError(f"{prog}: unexpected argument {text!r} "
                              "(expected keys=item1,item2)")
        args.publish.append(text[5:])
    for text in args.publish:
        for spec in text.split(","):
            if spec.strip():
                cfg.publish.append(parse_item(spec.strip(), prog))
    for spec in args.subscribe:
        cfg.subscribe.append(parse_subscription(spec, f"{prog}: "
                                                "--subscribe"))
    check(cfg, prog)
    return cfg, args.verbose


def check(cfg: BridgeConfig, prog: str) -> None:
    """Checks that need the whole configuration."""
    if not cfg.publish and not cfg.subscribe:
        raise ConfigError(f"{prog}: nothing to do: give keys=..., "
                          "--publish or --subscribe")
    if cfg.tls_key and not cfg.tls_cert:
        raise ConfigError(f"{prog}: --tls-key needs --tls-cert")
    if cfg.password and not cfg.user:
        raise ConfigError(f"{prog}: a password needs a user name")
    check_numbers(cfg, prog)
    items: dict[str, str] = {}
    for kind, name in cfg.publish:
        shown = f"{kind}:{name}" if kind else name
        if name in items:
            raise ConfigError(f"{prog}: item {shown!r} published twice "
                              f"(also as {items[name]!r})")
        items[name] = shown
    seen: dict[str, str] = {}
    for sub in cfg.subscribe:
        if sub.pin in seen:
            raise ConfigError(f"{sub.where}: pin {sub.pin!r} subscribed "
                              f"twice (first at {seen[sub.pin]})")
        seen[sub.pin] = sub.where
    for sub in cfg.subscribe:
        topic = cfg.sub_topic(sub)
        if any(topic == cfg.sub_topic(o) for o in cfg.subscribe
               if o is not sub):
            raise ConfigError(f"{sub.where}: topic {topic!r} used twice")


def check_numbers(cfg: BridgeConfig, prog: str) -> None:
    """Range checks of the numeric settings (for configurations built in
    Python rather than parsed)."""
    for attr, kind in KEYS.values():
        value = getattr(cfg, attr)
        if kind in INT_LIMITS and value is not None:
            low, high = INT_LIMITS[kind]
            if isinstance(value, bool) or not isinstance(value, int) or \
                    not low <= value <= high:
                raise ConfigError(f"{prog}: {attr}: {value!r} is not an "
                                  f"integer in {low}..{high}")
        elif kind in ("positive", "seconds"):
            if isinstance(value, bool) or \
                    not isinstance(value, (int, float)):
                raise ConfigError(f"{prog}: {attr}: {value!r} is not a "
                                  "number")
            problem = _number_problem(kind, value, cfg.publisher)
            if problem:
                raise ConfigError(f"{prog}: {attr}: {problem}")
