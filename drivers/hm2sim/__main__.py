"""``hm2-sim``: a simulated Mesa Ethernet card on a UDP port."""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from collections.abc import Sequence
from typing import Optional, TextIO

from . import lbp16
from .profiles import PROFILES
from .server import Hm2Sim, SimError

CONTROL_HELP = """\
commands (one a line, with --control):
  drop N | drop pP          drop the next N replies, or each with probability P
  lose N | lose pP          lose datagrams to the card (reads and writes)
  duplicate N | duplicate pP
  truncate N | truncate pP
  delay SECONDS N | delay SECONDS pP
  clear                     no faults
  away | back               the card stops answering / comes back (reset)
  input PIN 0|1             the field level of an I/O pin
  encoder N COUNTS          move encoder N
  index N                   an index pulse of encoder N
  status                    positions, outputs and counters
  quit
"""


class UsageError(Exception):
    """A bad command line (one line, exit status 2)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:     # type: ignore[override]
        raise UsageError(message)


def _probability(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected 0..1")
    return value


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"{text!r}: expected 0..65535")
    return value


def _switch(text: str) -> tuple[int, int, float, bool, bool]:
    """``PIN:STEPGEN:>=STEPS[:low]`` (pin, stepgen, at, above, on_level)."""
    parts = text.split(":")
    try:
        if len(parts) not in (3, 4) or parts[2][:2] not in (">=", "<="):
            raise ValueError
        if len(parts) == 4 and parts[3] != "low":
            raise ValueError
        return (int(parts[0]), int(parts[1]), float(parts[2][2:]),
                parts[2].startswith(">="), len(parts) == 3)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected PIN:STEPGEN:>=STEPS or PIN:STEPGEN:<=STEPS, "
            "optionally :low") from None


def _couple(text: str) -> tuple[int, int, float]:
    """``ENCODER:STEPGEN[:COUNTS_PER_STEP]``."""
    parts = text.split(":")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        ratio = float(parts[2]) if len(parts) == 3 else 1.0
        return int(parts[0]), int(parts[1]), ratio
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected ENCODER:STEPGEN[:COUNTS_PER_STEP]") from None


def parse_args(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    p = _Parser(
        prog="hm2-sim",
        description="A simulated Mesa HostMot2 Ethernet card: answers LBP16 "
                    "on UDP as the board's standard firmware does.",
        epilog=CONTROL_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--board", default="7i96s", type=str.lower,
                   choices=sorted(PROFILES),
                   help="the board profile (default 7i96s)")
    p.add_argument("--address", default="127.0.0.1",
                   help="IP address to listen on (default 127.0.0.1)")
    p.add_argument("--port", default=lbp16.PORT, type=_port,
                   help=f"UDP port (default {lbp16.PORT}, LBP16's)")
    p.add_argument("--log", metavar="FILE",
                   help="write every datagram, decoded, to FILE")
    p.add_argument("--drop", type=_probability, default=0.0, metavar="P",
                   help="drop each reply with probability P")
    p.add_argument("--lose", type=_probability, default=0.0, metavar="P",
                   help="lose each datagram to the card with probability P")
    p.add_argument("--duplicate", type=_probability, default=0.0,
                   metavar="P", help="send each reply twice with probability P")
    p.add_argument("--truncate", type=_probability, default=0.0,
                   metavar="P", help="cut each reply in half with probability P")
    p.add_argument("--delay", type=float, default=0.0, metavar="SECONDS",
                   help="delay replies by SECONDS (with --delay-probability)")
    p.add_argument("--delay-probability", type=_probability, default=1.0,
                   metavar="P", help="probability of --delay (default 1)")
    p.add_argument("--seed", type=int, help="seed of the fault dice")
    p.add_argument("--switch", action="append", default=[], type=_switch,
                   metavar="PIN:STEPGEN:>=STEPS[:low]",
                   help="a home or limit switch on input PIN, on when "
                        "stepgen STEPGEN's axis is at or above (>=) or at "
                        "or below (<=) STEPS; ':low' when on reads 0 "
                        "(repeatable)")
    p.add_argument("--couple", action="append", default=[], type=_couple,
                   metavar="ENCODER:STEPGEN[:COUNTS_PER_STEP]",
                   help="drive an encoder from a stepgen's axis "
                        "(repeatable)")
    p.add_argument("--control", action="store_true",
                   help="read commands from standard input (see below)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="print nothing but errors")
    return p.parse_args(argv)


def _status(sim: Hm2Sim) -> str:
    card = sim.card
    lines = [f"board {sim.profile.key} on {sim.address}:{sim.port}",
             f"stats {sim.stats}",
             f"watchdog {'bitten' if sim.watchdog_bitten else 'ok'}"]
    for n in range(len(card.stepgens)):
        lines.append(f"stepgen {n} position {sim.axis_position(n):.4f} steps")
    for n in range(len(card.encoders)):
        lines.append(f"encoder {n} {sim.encoder(n)}")
    for n in range(len(card.pwm_value)):
        lines.append(f"pwmgen {n} duty {sim.pwm_duty(n):.4f}")
    levels = "".join("1" if sim.pin(i) else "0" for i in range(card.npins))
    lines.append(f"pins {levels}")
    return "\n".join(lines)


def _fault_args(words: list[str]) -> tuple[int, float]:
    """(next, probability) of ``N`` or ``pP``."""
    if len(words) != 1:
        raise ValueError("expected N or pP")
    w = words[0]
    if w.startswith("p"):
        return 0, float(w[1:])
    return int(w), 0.0


def command(sim: Hm2Sim, line: str, out: TextIO) -> bool:
    """Run one control command; False for ``quit``."""
    words = line.split()
    if not words:
        return True
    verb, args = words[0], words[1:]
    f = sim.faults
    try:
        if verb == "quit":
            return False
        if verb in ("drop", "lose", "duplicate", "truncate"):
            n, p = _fault_args(args)
            getattr(f, verb)(next=n, probability=p)
        elif verb == "delay":
            if not args:
                raise ValueError("expected SECONDS [N | pP]")
            n, p = _fault_args(args[1:] or ["1"])
            f.delay(float(args[0]), next=n, probability=p)
        elif verb == "clear":
            f.clear()
        elif verb == "away":
            sim.go_away()
        elif verb == "back":
            sim.come_back()
        elif verb == "input" and len(args) == 2:
            sim.set_input(int(args[0]), args[1] not in ("0", "false"))
        elif verb == "encoder" and len(args) == 2:
            sim.set_encoder(int(args[0]), int(args[1]))
        elif verb == "index" and len(args) == 1:
            sim.pulse_index(int(args[0]))
        elif verb == "status":
            print(_status(sim), file=out)
        else:
            raise ValueError("unknown command (see hm2-sim --help)")
    except (ValueError, IndexError, TypeError) as exc:
        print(f"hm2-sim: {line.strip()}: {exc}", file=out)
    out.flush()
    return True


def main(argv: Optional[Sequence[str]] = None) -> int:
    try:
        args = parse_args(argv)
    except UsageError as exc:
        print(f"hm2-sim: error: {exc}", file=sys.stderr)
        return 2
    if not 0 <= args.delay <= 60:
        print("hm2-sim: error: --delay: expected 0..60 seconds",
              file=sys.stderr)
        return 2
    sim = Hm2Sim(args.board, args.address, args.port, log=args.log,
                 seed=args.seed)
    sim.faults.drop(probability=args.drop)
    sim.faults.lose(probability=args.lose)
    sim.faults.duplicate(probability=args.duplicate)
    sim.faults.truncate(probability=args.truncate)
    if args.delay:
        sim.faults.delay(args.delay, probability=args.delay_probability)
    try:
        for pin, stepgen, at, above, on_level in args.switch:
            sim.add_switch(pin, stepgen, at, above, on_level)
        for encoder, stepgen, ratio in args.couple:
            sim.couple(encoder, stepgen, ratio)
    except IndexError as exc:
        print(f"hm2-sim: error: {exc}", file=sys.stderr)
        return 2
    done = threading.Event()

    def _stop(signum: int, frame: object) -> None:
        done.set()

    try:
        sim.start()
    except (SimError, OSError) as exc:
        print(f"hm2-sim: error: {exc}", file=sys.stderr)
        return 1
    old = {s: signal.signal(s, _stop) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        if not args.quiet:
            print(f"hm2-sim: {sim.profile.description} on UDP "
                  f"{sim.address}:{sim.port}", flush=True)
        if args.control:
            reader = threading.Thread(target=_control, args=(sim, done),
                                      daemon=True)
            reader.start()
        while not done.wait(0.2):
            if not sim.running:
                print(f"hm2-sim: error: the server stopped: {sim.error}",
                      file=sys.stderr)
                return 1
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        sim.stop()
    return 0


def _control(sim: Hm2Sim, done: threading.Event) -> None:
    for line in sys.stdin:
        if not command(sim, line, sys.stdout):
            break
    done.set()


if __name__ == "__main__":
    sys.exit(main())
