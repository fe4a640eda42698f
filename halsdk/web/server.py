"""``halsdk web``: serve the workbench of the running instance, or of a
machine it starts.

    halsdk web [machine.ini] [--instance NAME] [--host 127.0.0.1]
               [--port 0|N] [--read-only] [--token T]

Without an INI file it attaches to the instance (it never creates one).
With one it first starts the machine as ``halsdk run machine.ini`` does,
in a child process of its own (:mod:`halsdk.web.machinehost`), and
attaches to that.  It prints the URL with its token as Jupyter does, and
serves until SIGINT or SIGTERM, or until the instance's host ends; a
machine it started is then stopped (motion disabled, the instance
removed).  It opens no browser.
"""

from __future__ import annotations

import argparse
import contextlib
import ipaddress
import os
import secrets
import signal
import socket
import sys
import threading
from collections.abc import Iterator
from typing import Any, Optional

PROG = "halsdk web"


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=PROG,
        description="Serve the HAL workbench (the Show, Scope, Machine "
                    "and Latency pages) of the running instance in a "
                    "browser, or start the machine of an INI file (as "
                    "`halsdk run machine.ini` does) and serve its "
                    "workbench.  Prints the URL with its access token; "
                    "opens nothing by itself; SIGINT or SIGTERM end it "
                    "(and stop the machine it started).")
    p.add_argument("ini", nargs="?", default=None, metavar="machine.ini",
                   help="start this machine first (its HAL files, motion "
                        "and task controller, as `halsdk run` does), on "
                        "--instance or $HALSDK_INSTANCE; without it, "
                        "attach to a running instance")
    p.add_argument("--instance", metavar="NAME", default=None,
                   help="the instance to attach to, or to start the "
                        "machine on (default: $HALSDK_INSTANCE, else the "
                        "user's instance)")
    p.add_argument("--host", default="127.0.0.1",
                   help="the address to listen on (default 127.0.0.1: "
                        "this computer only)")
    p.add_argument("--port", type=int, default=0,
                   help="the port (default 0: any free port)")
    p.add_argument("--read-only", action="store_true",
                   help="show everything, change nothing (every change "
                        "is refused with 403)")
    p.add_argument("--token", default=None,
                   help="the access token (default: a new random one; "
                        "$HALSDK_WEB_TOKEN also sets it, which keeps it "
                        "off the command line that other users can see)")
    return p


def url_host(host: str) -> str:
    """``host`` as it goes into a URL (an IPv6 address in brackets;
    a wildcard address as this computer's name)."""
    try:
        address = ipaddress.ip_address(host)
    except ValueError:
        return host
    if address.is_unspecified:
        return socket.gethostname()
    return f"[{host}]" if address.version == 6 else host


def listen(host: str, port: int) -> socket.socket:
    """A listening socket on ``host:port`` (OSError with the address)."""
    infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM,
                               flags=socket.AI_PASSIVE)
    family, kind, proto, _, address = infos[0]
    sock = socket.socket(family, kind, proto)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(address)
        sock.listen(64)
    except OSError:
        sock.close()
        raise
    sock.set_inheritable(False)
    return sock


def _loopback(sock: socket.socket) -> bool:
    """True when ``sock`` listens on a loopback address only."""
    try:
        return ipaddress.ip_address(sock.getsockname()[0]).is_loopback
    except ValueError:
        return False


def main(argv: Optional[list[str]] = None) -> int:
    a = parser().parse_args(argv)
    token = a.token or os.environ.get("HALSDK_WEB_TOKEN") or \
        secrets.token_urlsafe(24)
    if not 0 <= a.port <= 65535:
        print(f"{PROG}: --port {a.port} is not 0..65535", file=sys.stderr)
        return 2

    if a.ini is None:
        return _attach(a, token)
    from halsdk.web.machinehost import MachineHost, StartError
    host = MachineHost(a.ini, a.instance, prog=PROG)
    try:
        try:
            host.start()
        except StartError as exc:
            print(f"{PROG}: {exc}", file=sys.stderr)
            return 1
        status = _attach(a, token)
    finally:
        # the workbench has let go of the instance: stop the machine
        gone = host.stop()
    if gone:
        # its host ended by itself (or could not be stopped cleanly)
        print(f"{PROG}: {gone}", file=sys.stderr)
        return 1
    return status


def _attach(a: argparse.Namespace, token: str) -> int:
    from halsdk.errors import HalError
    from halsdk.hal import Hal
    try:
        hal = Hal(a.instance, create=False)
    except HalError as exc:
        # "no HAL instance 'NAME' is running (start one with ...)"
        print(f"{PROG}: {exc}", file=sys.stderr)
        return 1
    try:
        return _serve(hal, a, token)
    finally:
        hal.close()


class _Server:
    """uvicorn's server, with our signal handling: SIGINT and SIGTERM ask
    it to end, and it ends with status 0 (uvicorn's own handling raises
    the signal again once it has stopped)."""

    def __init__(self, config: Any):
        import uvicorn

        class Server(uvicorn.Server):
            @contextlib.contextmanager
            def capture_signals(self) -> Iterator[None]:
                yield

        self.server = Server(config)

    def stop(self, signum: int = 0, frame: Any = None) -> None:
        self.server.should_exit = True


def _serve(hal: Any, a: argparse.Namespace, token: str) -> int:
    import uvicorn

    from halsdk.web.app import create_app
    try:
        sock = listen(a.host, a.port)
    except OSError as exc:
        print(f"{PROG}: cannot listen on {a.host}:{a.port}: "
              f"{exc.strerror or exc}", file=sys.stderr)
        return 1
    port = sock.getsockname()[1]
    app = create_app(hal, token=token, read_only=a.read_only)
    config = uvicorn.Config(app, log_level="warning", access_log=False,
                            lifespan="on", ws="auto")
    server = _Server(config)
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, server.stop)
    # the host's end ends this server too (SIGTERM, as above)
    hal.end_with_host(PROG)
    if not _loopback(sock):
        print(f"{PROG}: listening on {a.host}, not only this computer: "
              "the token travels in plain HTTP (docs/web.rst, Security)",
              file=sys.stderr)
    mode = " (read-only)" if a.read_only else ""
    print(f"HAL workbench of instance '{hal.instance}'{mode}; open:\n"
          f"    http://{url_host(a.host)}:{port}/?token={token}",
          flush=True)
    try:
        server.server.run(sockets=[sock])
    finally:
        sock.close()
    return 0
