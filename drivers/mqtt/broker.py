"""A throwaway Mosquitto broker on loopback, for tests and benchmarks."""

from __future__ import annotations

import os
import pwd
import shutil
import socket
import subprocess
import tempfile
import time
from typing import BinaryIO, Optional

MOSQUITTO = "/usr/sbin/mosquitto"


def find_mosquitto() -> str:
    """Path of the mosquitto program; RuntimeError when it is missing."""
    path = shutil.which("mosquitto") or (
        MOSQUITTO if os.access(MOSQUITTO, os.X_OK) else None)
    if path is None:
        raise RuntimeError("mosquitto not found (install the Debian "
                           "package 'mosquitto'): the MQTT tests and "
                           "bench need a local broker")
    return path


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Mosquitto:
    """``mosquitto`` on 127.0.0.1:``port`` with its own config in
    ``folder``; :meth:`start` waits (bounded) until it accepts."""

    def __init__(self, folder: Optional[str] = None,
                 port: Optional[int] = None, extra: str = ""):
        self.program = find_mosquitto()
        self.folder = folder or tempfile.mkdtemp(prefix="mosquitto-")
        self.port = port or free_port()
        self.extra = extra
        self.proc: Optional[subprocess.Popen] = None
        self.log: Optional[BinaryIO] = None     # mosquitto's output

    def add_user(self, user: str, password: str) -> str:
        """Add to the broker's password file (hashed with mosquitto_passwd
        -U); returns the file's path."""
        path = os.path.join(self.folder, "passwd")
        with open(path, "a", encoding="utf-8") as f:
            f.write(f"{user}:{password}\n")
        os.chmod(path, 0o600)
        tool = shutil.which("mosquitto_passwd") or "/usr/bin/mosquitto_passwd"
        subprocess.run([tool, "-U", path], check=True, timeout=10,
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        return path

    def config(self) -> str:
        # as root, mosquitto would switch to its own user, which cannot
        # read files in private temporary folders: stay who we are
        return (f"listener {self.port} 127.0.0.1\n"
                f"user {pwd.getpwuid(os.getuid()).pw_name}\n"
                "persistence false\n"
                "log_dest stderr\n"
                "log_type error\nlog_type warning\n"
                f"{self.extra or 'allow_anonymous true'}\n")

    def start(self, timeout: float = 10.0) -> None:
        conf = os.path.join(self.folder, "mosquitto.conf")
        with open(conf, "w", encoding="utf-8") as f:
            f.write(self.config())
        self.log = open(os.path.join(self.folder, "mosquitto.log"), "ab")
        self.proc = subprocess.Popen([self.program, "-c", conf],
                                     cwd=self.folder, stdout=self.log,
                                     stderr=subprocess.STDOUT)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"mosquitto exited ({self.proc.returncode}"
                                   f"): {self.log_text()}")
            try:
                socket.create_connection(("127.0.0.1", self.port),
                                         0.2).close()
                return
            except OSError:
                time.sleep(0.02)
        self.stop()
        raise RuntimeError(f"mosquitto did not listen on port {self.port} "
                           f"within {timeout} s")

    def log_text(self) -> str:
        with open(os.path.join(self.folder, "mosquitto.log"), "rb") as f:
            return f.read().decode("utf-8", "replace")

    def stop(self) -> None:
        proc, self.proc = self.proc, None
        if proc is not None and proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(5)
        log, self.log = self.log, None
        if log is not None:
            log.close()

    def __enter__(self) -> Mosquitto:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
