"""Issue 19, the shared-memory trust boundary: a process uses a segment, a
socket or a runtime folder only when the effective user owns it, of the
private mode (0600 files, 0700 folder), with one link, not a symbolic
link.  Anything else is refused with a message that names the check, the
file and its owner: never a traceback, never a misleading hint.

Another local user is played by files chowned to an unused uid: the suite
runs as root in CI, and root may give files away (root also passes every
permission check, which is why the checks must be explicit).  Tests that
need that are skipped for other users.  Every file made here is removed,
also the ones given away.
"""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Optional

import pytest
from helpers.users import OTHER, needs_root
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import halsdk
from halsdk.core import channel, trust
from halsdk.errors import InstanceError, TrustError

SHM_DIR = "/dev/shm"
BIN = Path(sys.executable).parent



def segment(name: str) -> str:
    return SHM_DIR + halsdk.core.instance.shm_name(name)


def program(name: str) -> str:
    path = BIN / name
    if not path.exists():
        pytest.skip(f"{name} is not installed next to {sys.executable}")
    return str(path)


def run(args: list[str], cwd: Path, instance: str,
        **env: str) -> subprocess.CompletedProcess:
    environ = dict(os.environ, HALSDK_INSTANCE=instance, **env)
    return subprocess.run(args, cwd=cwd, env=environ, capture_output=True,
                          text=True, timeout=60)


def assert_refused(proc: subprocess.CompletedProcess, *words: str) -> str:
    """A refusal: non-zero status, each of ``words`` on stderr, no
    traceback, no misleading hint."""
    text = proc.stdout + proc.stderr
    assert proc.returncode != 0, text
    assert "Traceback" not in text, text
    assert "another halrun running" not in text, text
    for word in words:
        assert word in proc.stderr, text
    return proc.stderr


@pytest.fixture
def name() -> Iterator[str]:
    """A fresh instance name; every file of it (and its link names made
    with ``made``) is removed at the end."""
    made.clear()
    instance = f"trust-{os.getpid()}-{len(_names)}"
    _names.append(instance)
    yield instance
    for path in [segment(instance), *made]:
        try:
            st_ = os.lstat(path)
        except FileNotFoundError:
            continue
        if stat.S_ISDIR(st_.st_mode):
            os.rmdir(path)
        else:
            os.unlink(path)


_names: list[str] = []
made: list[str] = []


@pytest.fixture
def no_connection() -> Iterator[None]:
    assert halsdk.core.instance.current() is None
    yield
    conn = halsdk.core.instance.current()
    if conn is not None:
        halsdk.core.instance._teardown(conn)
        pytest.fail("the test left this process connected")


def junk(path: str, mode: int = 0o600, uid: Optional[int] = None) -> None:
    """A file at ``path`` that is not a halsdk instance."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        os.write(fd, b"not a HAL instance\n" * 100)
        os.fchmod(fd, mode)
        if uid is not None:
            os.fchown(fd, uid, -1)
    finally:
        os.close(fd)


# ------------------------------------------- another user's live instance


@needs_root
def test_hard_linked_foreign_instance_is_refused_by_halcmd(hal, name,
                                                           tmp_path):
    """The attack of the issue: another user hard-links the segment of an
    instance of theirs under this user's instance name.  halcmd neither
    attaches nor shows nor sets anything."""
    hal.newsig("their-secret", "float")
    theirs = segment(hal.instance)
    os.link(theirs, segment(name))
    os.chown(theirs, OTHER, -1)
    try:
        proc = run([program("halcmd"), "show", "sig"], tmp_path, name)
        err = assert_refused(proc, segment(name), f"uid {OTHER}",
                             "not owned by this user")
        assert "their-secret" not in proc.stdout
        assert err.count("\n") == 1             # one line
        proc = run([program("halcmd"), "sets", "their-secret", "1"],
                   tmp_path, name)
        assert_refused(proc, f"uid {OTHER}")
        assert hal.signal("their-secret").value == 0.0
    finally:
        os.chown(theirs, os.geteuid(), -1)
        os.unlink(segment(name))


def test_hard_linked_own_segment_is_refused(hal, name, tmp_path):
    """Even this user's own instance is not used under a second name:
    a segment has one link."""
    os.link(segment(hal.instance), segment(name))
    try:
        proc = run([program("halcmd"), "show", "pin"], tmp_path, name)
        assert_refused(proc, segment(name), "2 hard links",
                       f"uid {os.geteuid()}")
        # the instance itself is refused as well while the second name
        # exists: nobody can tell which name is the real one
        proc = run([program("halcmd"), "show", "pin"], tmp_path,
                   hal.instance)
        assert_refused(proc, segment(hal.instance), "2 hard links")
    finally:
        os.unlink(segment(name))
    proc = run([program("halcmd"), "show", "pin"], tmp_path, hal.instance)
    assert proc.returncode == 0, proc.stderr


@needs_root
def test_instance_owned_by_another_user_is_refused(hal, tmp_path):
    path = segment(hal.instance)
    os.chown(path, OTHER, -1)
    try:
        proc = run([program("halcmd"), "show", "pin"], tmp_path,
                   hal.instance)
        assert_refused(proc, path, f"owner uid {OTHER} (no user name)",
                       "not owned by this user")
    finally:
        os.chown(path, os.geteuid(), -1)


def test_instance_of_mode_0644_is_refused(hal, tmp_path):
    path = segment(hal.instance)
    os.chmod(path, 0o644)
    try:
        proc = run([program("halcmd"), "show", "pin"], tmp_path,
                   hal.instance)
        assert_refused(proc, path, "its mode is 0644, not 0600")
    finally:
        os.chmod(path, 0o600)
    proc = run([program("halcmd"), "show", "pin"], tmp_path, hal.instance)
    assert proc.returncode == 0, proc.stderr


def test_symlink_to_an_instance_is_refused(hal, name, tmp_path):
    os.symlink(segment(hal.instance), segment(name))
    try:
        proc = run([program("halcmd"), "show", "pin"], tmp_path, name)
        assert_refused(proc, segment(name), "symbolic link")
    finally:
        os.unlink(segment(name))


# ------------------------------------------------- the Python interface


def _bad_segment(path: str, kind: str) -> str:
    """Make a segment file at ``path`` that fails one check; the words
    the refusal must contain."""
    if kind == "other-user":
        junk(path, uid=OTHER)
        return f"uid {OTHER}"
    if kind == "mode":
        junk(path, mode=0o640)
        return "its mode is 0640, not 0600"
    if kind == "symlink":
        target = path + "-target"
        junk(target)
        made.append(target)
        os.symlink(target, path)
        return "symbolic link"
    if kind == "fifo":
        os.mkfifo(path, 0o600)
        return "not a regular file"
    if kind == "directory":
        os.mkdir(path, 0o700)
        return "not a regular file"
    if kind == "two-links":
        junk(path)
        os.link(path, path + "-second")
        made.append(path + "-second")
        return "2 hard links"
    raise AssertionError(kind)


KINDS = ["mode", "symlink", "fifo", "directory", "two-links",
         pytest.param("other-user", marks=needs_root)]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("create", [False, None, True])
def test_untrusted_segment_is_refused_by_hal(no_connection, name, kind,
                                             create):
    """Attach, create and create-or-attach all refuse, with the check and
    the owner in the message, and leave the file alone (a FIFO does not
    hang the open)."""
    path = segment(name)
    words = _bad_segment(path, kind)
    before = os.lstat(path)
    with pytest.raises(TrustError) as err:
        halsdk.Hal(name, create=create)
    message = str(err.value)
    assert isinstance(err.value, InstanceError)
    assert path in message and words in message
    assert "owner " in message and "(uid " in message
    assert halsdk.core.instance.current() is None
    assert os.lstat(path).st_ino == before.st_ino     # left in place


@needs_root
def test_halrun_does_not_create_over_a_foreign_segment(name, tmp_path):
    path = segment(name)
    junk(path, uid=OTHER)
    (tmp_path / "a.hal").write_text("newsig a bit\n")
    proc = run([program("halrun"), "-f", "a.hal"], tmp_path, name)
    assert_refused(proc, path, f"uid {OTHER}", "cannot create")
    assert os.stat(path).st_uid == OTHER          # left in place


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mode=st.integers(0, 0o7777), links=st.integers(1, 3),
       foreign=st.booleans() if os.geteuid() == 0 else st.just(False))
def test_only_a_private_single_link_own_segment_is_trusted(
        no_connection, mode, links, foreign):
    """Property: a segment passes the checks exactly when it is ours, of
    mode 0600, with one link; otherwise the refusal names the first check
    that failed and the owner."""
    name = f"trust-{os.getpid()}-prop"
    path = segment(name)
    extra = [f"{path}-link{k}" for k in range(1, links)]
    uid = OTHER if foreign else os.geteuid()
    try:
        junk(path, mode=mode, uid=OTHER if foreign else None)
        for link in extra:
            os.link(path, link)
        mode = stat.S_IMODE(os.lstat(path).st_mode)  # chown drops setgid
        trusted = not foreign and mode == 0o600 and links == 1
        if trusted:
            # it passes the checks, and is then found to be junk
            with pytest.raises(InstanceError,
                               match="not a halsdk instance"):
                halsdk.Hal(name, create=False)
        else:
            with pytest.raises(TrustError) as err:
                halsdk.Hal(name, create=False)
            message = str(err.value)
            assert f"(owner {trust.owner_words(uid)})" in message
            if foreign:
                assert "not owned by this user" in message
            elif mode != 0o600:
                assert f"its mode is {mode:04o}, not 0600" in message
            else:
                assert f"it has {links} hard links" in message
    finally:
        for p in [path, *extra]:
            try:
                os.unlink(p)
            except FileNotFoundError:
                pass


# ---------------------------------------------------- the runtime folder


@pytest.fixture
def runtime(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A scratch folder for runtime folders; nothing of this test uses the
    real ``/tmp/halsdk-<uid>`` (other test runs share it)."""
    base = tmp_path / "run"
    base.mkdir(mode=0o700)
    monkeypatch.delenv("HALSDK_RUNTIME_DIR", raising=False)
    monkeypatch.delenv("XDG_RUNTIME_DIR", raising=False)
    monkeypatch.setattr(trust, "FALLBACK_BASE", str(base))
    yield base
    for path in base.rglob("*"):          # give back what was given away
        os.lchown(path, os.geteuid(), -1)


def test_runtime_folder_choice(runtime, monkeypatch):
    uid = os.getuid()
    assert trust.runtime_dir() == str(runtime / f"halsdk-{uid}")
    xdg = runtime / "xdg"
    xdg.mkdir(mode=0o700)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(xdg))
    assert trust.runtime_dir() == str(xdg / "halsdk")
    assert stat.S_IMODE(os.stat(xdg / "halsdk").st_mode) == 0o700
    # an XDG_RUNTIME_DIR that others may enter is not used
    xdg.chmod(0o755)
    assert trust.runtime_dir() == str(runtime / f"halsdk-{uid}")
    own = runtime / "own"
    monkeypatch.setenv("HALSDK_RUNTIME_DIR", str(own))
    assert trust.runtime_dir() == str(own)
    assert channel.socket_dir() == str(own)


@pytest.mark.parametrize("kind", [
    pytest.param("other-user", marks=needs_root), "symlink", "file",
    "mode"])
def test_runtime_folder_made_by_someone_else_is_refused(runtime, kind):
    path = runtime / f"halsdk-{os.getuid()}"
    if kind == "other-user":
        path.mkdir(mode=0o700)
        os.chown(path, OTHER, -1)
        words = [f"uid {OTHER}", "not owned by this user", "rm -r"]
    elif kind == "symlink":
        target = runtime / "elsewhere"
        target.mkdir(mode=0o700)
        path.symlink_to(target)
        words = ["symbolic link", "rm -r"]
    elif kind == "file":
        path.write_text("")
        words = ["not a directory"]
    else:
        path.mkdir(mode=0o755)
        words = ["its mode is 0755, not 0700", f"chmod 700 {path}"]
    with pytest.raises(TrustError) as err:
        trust.runtime_dir()
    message = str(err.value)
    assert str(path) in message and "XDG_RUNTIME_DIR" in message
    assert f"owner {trust.owner_words(os.lstat(path).st_uid)}" in message
    for word in words:
        assert word in message


@needs_root
def test_xdg_runtime_folder_made_by_someone_else_is_refused(runtime,
                                                            monkeypatch):
    xdg = runtime / "xdg"
    xdg.mkdir(mode=0o700)
    (xdg / "halsdk").mkdir(mode=0o700)
    os.chown(xdg / "halsdk", OTHER, -1)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(xdg))
    with pytest.raises(TrustError) as err:
        channel.socket_dir()
    assert f"{xdg / 'halsdk'} (owner uid {OTHER} (no user name))" in \
        str(err.value)


@needs_root
def test_programs_name_a_foreign_runtime_folder(hal, tmp_path):
    """halcmd and halrun (host and -U) with a runtime folder made by
    another user: one clear message naming it and its owner."""
    folder = tmp_path / "rt"
    folder.mkdir(mode=0o700)
    os.chown(folder, OTHER, -1)
    env = {"HALSDK_RUNTIME_DIR": str(folder)}
    try:
        (tmp_path / "a.hal").write_text("newsig a bit\n")
        proc = run([program("halrun"), "-f", "a.hal"], tmp_path,
                   f"trust-{os.getpid()}-rt", **env)
        assert_refused(proc, str(folder), f"uid {OTHER}")
        # halcmd reaches the host through the folder: refused too
        proc = run([program("halcmd"), "loadrt", "siggen"], tmp_path,
                   hal.instance, **env)
        assert_refused(proc, str(folder), f"uid {OTHER}")
        assert hal.find("component", "siggen") is None
        proc = run([program("halrun"), "-U"], tmp_path, hal.instance, **env)
        assert_refused(proc, str(folder), f"uid {OTHER}")
    finally:
        os.chown(folder, os.geteuid(), -1)
    assert not list(Path(SHM_DIR).glob(f"*trust-{os.getpid()}-rt*"))


# --------------------------------------------------------------- sockets


@needs_root
def test_foreign_request_socket_is_refused(hal, tmp_path, monkeypatch):
    """The host's request socket given to another user: a client does not
    send it a request."""
    path = channel.socket_path(halsdk.core.instance.shm_name(hal.instance))
    os.lchown(path, OTHER, -1)
    try:
        proc = run([program("halcmd"), "loadrt", "siggen"], tmp_path,
                   hal.instance)
        assert_refused(proc, path, f"uid {OTHER}", "not owned by this user")
        assert hal.find("component", "siggen") is None
    finally:
        os.lchown(path, os.geteuid(), -1)
    proc = run([program("halcmd"), "loadrt", "siggen"], tmp_path,
               hal.instance)
    assert proc.returncode == 0, proc.stderr


def test_task_socket_must_be_ours(tmp_path):
    """The command channel's client and server check the socket file."""
    from halsdk.channels.cmdclient import CommandClient
    from halsdk.channels.errors import ChannelError

    path = tmp_path / "halsdk-0-x.task.sock"
    path.symlink_to(tmp_path / "elsewhere.sock")
    with pytest.raises(ChannelError, match="symbolic link"):
        CommandClient(str(path))
    path.unlink()
    path.write_text("")
    with pytest.raises(ChannelError, match="not a socket"):
        CommandClient(str(path))


@needs_root
def test_foreign_task_socket_is_refused(tmp_path):
    import socket

    from halsdk.channels.cmdclient import CommandClient
    from halsdk.channels.cmdserver import CommandServer
    from halsdk.channels.errors import ChannelError

    path = str(tmp_path / "t.sock")
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(path)
    listener.listen(1)
    os.lchown(path, OTHER, -1)
    try:
        with pytest.raises(ChannelError) as err:
            CommandClient(path, timeout=1)
        assert f"uid {OTHER}" in str(err.value)
        listener.close()
        with pytest.raises(ChannelError) as err:
            CommandServer(path, lambda *a: None, lambda s: None, task_pid=1)
        assert f"uid {OTHER}" in str(err.value)
        assert os.path.exists(path)             # not removed
    finally:
        listener.close()
        os.unlink(path)


@needs_root
def test_request_from_another_user_is_refused_with_a_reply(
        no_connection, name, tmp_path, monkeypatch):
    """The host checks the peer's uid (SO_PEERCRED): a process of another
    user that reaches the socket is answered with a refusal and served
    nothing.  (Normally the 0700 folder keeps it out; here the folder and
    the socket are opened up on purpose, in a folder of this test.)"""
    import shutil
    import tempfile

    folder = tempfile.mkdtemp(prefix="halsdk-trust-", dir="/tmp")
    monkeypatch.setenv("HALSDK_RUNTIME_DIR", folder)
    code = (
        "import json, os, socket, sys\n"
        f"os.setuid({OTHER})\n"
        "s = socket.socket(socket.AF_UNIX)\n"
        "s.settimeout(10)\n"
        "s.connect(sys.argv[1])\n"
        "try:\n"
        "    s.sendall(b'{\"op\": \"loadrt\", \"args\": [\"siggen\"]}"
        "\\n')\n"
        "except OSError:\n"
        "    pass                # refused before it was read\n"
        "print(s.makefile().readline(), end='')\n")
    try:
        with halsdk.Hal(name, create=True) as hal:
            path = channel.socket_path(hal._conn.shm)
            os.chmod(folder, 0o711)
            os.chmod(path, 0o777)
            proc = subprocess.run([sys.executable, "-c", code, path],
                                  cwd=tmp_path, capture_output=True,
                                  text=True, timeout=60)
            os.chmod(folder, 0o700)
            assert proc.returncode == 0, proc.stderr
            assert '"class": "TrustError"' in proc.stdout, proc.stdout
            assert f"uid {OTHER}" in proc.stdout
            assert hal.find("component", "siggen") is None
    finally:
        shutil.rmtree(folder, ignore_errors=True)
