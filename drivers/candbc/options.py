"""Command line of ``can-dbc`` and the resolved configuration: which
messages are received or sent, their periods and timeouts."""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Callable, NoReturn, Optional

import can
from cantools.database.can import Database, Message

from .dbc import ConfigError, find_package_dbc, line_of_message, load_dbc
from .names import hal_name

PROGRAM = "can-dbc"
#: limits of the numeric options (and of DBC cycle times)
MAX_NUM = 999
MIN_BITRATE, MAX_BITRATE = 1000, 10_000_000
MAX_LOOP_PERIOD = 1.0
MAX_SECONDS = 3600.0
MAX_TIMEOUT_FACTOR = 100.0


@dataclass
class Config:
    """Everything the driver needs, checked."""

    dbc_path: str
    db: Database
    #: the DBC file as the user named it (for messages)
    dbc_name: str = ""
    interface: str = "socketcan"
    channel: str = "can0"
    bitrate: Optional[int] = None
    name: str = PROGRAM
    num: int = 0
    rx: list[Message] = field(default_factory=list)
    tx: list[Message] = field(default_factory=list)
    #: seconds between cyclic sends (0: only on change / at connect)
    periods: dict[str, float] = field(default_factory=dict)
    #: receive timeout in seconds (0: none)
    timeouts: dict[str, float] = field(default_factory=dict)
    on_change: bool = False
    loop_period: float = 0.005


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, status 1
        raise ConfigError(message)

    def parse_args(self, args=None, namespace=None):
        """Unknown options first, then the missing ``--dbc``."""
        parsed, extra = self.parse_known_args(args, namespace)
        if extra:
            self.error(f"unrecognized arguments: {' '.join(extra)}")
        if parsed.dbc is None:
            self.error("the following arguments are required: --dbc")
        return parsed


def _number(kind: type, low: float, high: float,
            what: str) -> Callable[[str], float]:
    """An argparse type: a ``kind`` number in ``[low, high]``; ``low``
    itself is excluded for floats (periods must be > 0)."""
    def convert(text: str) -> float:
        try:
            value = kind(text)
        except ValueError:
            value = math.nan
        if kind is int:
            ok = low <= value <= high
        else:
            ok = math.isfinite(value) and low < value <= high
        if not ok:
            raise argparse.ArgumentTypeError(f"{text!r}: expected {what}")
        return value
    return convert


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog=PROGRAM, description="CAN signals to HAL pins "
                "through a DBC file.")
    p.add_argument("-n", "--name", default=PROGRAM,
                   help="HAL component name (default %(default)s)")
    p.add_argument("--num", default=0,
                   type=_number(int, 0, MAX_NUM, f"0 to {MAX_NUM}"),
                   help="device number: pins are candbc.NUM.* (default 0)")
    p.add_argument("--interface", default="socketcan",
                   help="python-can interface (default %(default)s)")
    p.add_argument("--channel", default="can0",
                   help="interface channel (default %(default)s)")
    p.add_argument("--bitrate", help="bus bitrate in bit/s",
                   type=_number(int, MIN_BITRATE, MAX_BITRATE,
                                f"bit/s from {MIN_BITRATE} to {MAX_BITRATE}"))
    p.add_argument("--dbc", help="the DBC file (required)")
    p.add_argument("--node", help="the DBC node this driver is: messages "
                   "it sends are transmitted, all others received")
    p.add_argument("--rx", nargs="+", action="extend", default=[],
                   metavar="MSG", help="messages to receive")
    p.add_argument("--tx", nargs="+", action="extend", default=[],
                   metavar="MSG", help="messages to transmit")
    p.add_argument("--period", action="append", default=[],
                   metavar="[MSG=]S", help="transmit period in seconds")
    p.add_argument("--timeout", action="append", default=[],
                   metavar="[MSG=]S", help="receive timeout in seconds")
    p.add_argument("--timeout-factor", default=3.0,
                   type=_number(float, 0, MAX_TIMEOUT_FACTOR,
                                f"> 0 and at most {MAX_TIMEOUT_FACTOR:g}"),
                   help="timeout = cycle time x this (default 3)")
    p.add_argument("--on-change", action="store_true",
                   help="also send a message as soon as one of its pins "
                   "changes")
    p.add_argument("--loop-period", default=0.005,
                   type=_number(float, 0, MAX_LOOP_PERIOD,
                                f"seconds > 0 and at most {MAX_LOOP_PERIOD:g}"),
                   help="seconds between loop cycles (default 0.005)")
    return p


def _lookup(db: Database, path: str, name: str, option: str) -> Message:
    """A message by DBC name or by its HAL-style name."""
    for message in db.messages:
        if name in (message.name, hal_name(message.name)):
            return message
    raise ConfigError(f"{path}: no message named {name!r} ({option})")


def _seconds(text: str, option: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0 <= value <= MAX_SECONDS):
        raise ConfigError(f"{option} {text!r}: expected seconds from 0 to "
                          f"{MAX_SECONDS:g}")
    return value


def _split_values(db: Database, path: str, items: Sequence[str],
                  option: str) -> tuple[Optional[float], dict[str, float]]:
    """``--period 0.1 --period Msg=0.02`` → (0.1, {"Msg": 0.02})."""
    default: Optional[float] = None
    per_message: dict[str, float] = {}
    for item in items:
        if "=" in item:
            name, _, value = item.partition("=")
            message = _lookup(db, path, name.strip(), option)
            per_message[message.name] = _seconds(value.strip(), option)
        else:
            default = _seconds(item, option)
    return default, per_message


def _check_cycle_time(path: str, shown: str, message: Message) -> None:
    """A cycle time (``GenMsgCycleTime``, ms) from 0 to MAX_SECONDS."""
    cycle = message.cycle_time or 0
    if 0 <= cycle <= MAX_SECONDS * 1000:
        return
    line = line_of_message(path, message.name) or 1
    raise ConfigError(f"{shown}:{line}: message {message.name}: cycle time "
                      f"{cycle} ms is not from 0 to {int(MAX_SECONDS * 1000)}")


def parse_args(argv: Optional[Sequence[str]] = None) -> Config:
    """Parse and check the command line (and load the DBC file)."""
    args = _parser().parse_args(argv)
    if args.interface not in can.VALID_INTERFACES:
        raise ConfigError(f"unknown interface {args.interface!r} (one of "
                          f"{', '.join(sorted(can.VALID_INTERFACES))})")
    if not args.name.strip():
        raise ConfigError("-n/--name: the component name is empty")
    shown = args.dbc
    path = shown
    if not os.path.exists(path):
        path = find_package_dbc(path) or path
    db = load_dbc(path, shown)
    for message in db.messages:
        _check_cycle_time(path, shown, message)
    rx = {_lookup(db, shown, n, "--rx").name for n in args.rx}
    tx = {_lookup(db, shown, n, "--tx").name for n in args.tx}
    if args.node is not None:
        if args.node not in [node.name for node in db.nodes]:
            raise ConfigError(f"{shown}: no node named {args.node!r} (--node)")
        for message in db.messages:
            if message.name in rx or message.name in tx:
                continue
            if args.node in message.senders:
                tx.add(message.name)
            else:
                rx.add(message.name)
    elif not rx and not tx:
        rx = {message.name for message in db.messages}
    both = sorted(rx & tx)
    if both:
        raise ConfigError(f"{shown}: message {both[0]!r} is both received "
                          "and transmitted")
    default_period, periods = _split_values(db, shown, args.period,
                                            "--period")
    default_timeout, timeouts = _split_values(db, shown, args.timeout,
                                              "--timeout")
    config = Config(dbc_path=path, db=db, dbc_name=shown, interface=args.interface,
                    channel=args.channel, bitrate=args.bitrate,
                    name=args.name, num=args.num,
                    on_change=args.on_change, loop_period=args.loop_period)
    for message in db.messages:
        cycle = (message.cycle_time or 0) / 1000.0
        if message.name in tx:
            config.tx.append(message)
            period = periods.get(message.name)
            if period is None:
                period = cycle or (0.1 if default_period is None
                                   else default_period)
            config.periods[message.name] = period
        elif message.name in rx:
            config.rx.append(message)
            timeout = timeouts.get(message.name)
            if timeout is None:
                timeout = cycle * args.timeout_factor if cycle else (
                    default_timeout or 0.0)
            config.timeouts[message.name] = timeout
    return config
