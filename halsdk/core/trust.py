"""The trust boundary of the files of an instance that are not in shared
memory: the runtime folder and the Unix sockets in it.

The C core checks the shared-memory segments (``hal_core.c``: owned by the
effective user, mode 0600, one link, a regular file, not a symbolic link;
on the opened descriptor).  This module makes the same kind of checks for
the folder of the sockets and for each socket before it is used, so that
another local user cannot plant a folder, a socket or a link that a HAL
process of this user would then use.  Every refusal is a
:class:`~halsdk.core.errors.TrustError` whose message names the check, the
file and its owner, and says how to fix it.
"""

from __future__ import annotations

import os
import pwd
import stat

from halsdk.core.errors import InstanceError, TrustError

#: the parent of the fallback runtime folder ``halsdk-<uid>`` (a module
#: constant so that tests can point it elsewhere)
FALLBACK_BASE = "/tmp"

#: how to get a runtime folder nobody else can make, for the messages
_FIX = ("set XDG_RUNTIME_DIR (or HALSDK_RUNTIME_DIR) to a private folder "
        "of yours (mode 0700)")


def owner_words(uid: int) -> str:
    """A file owner in words: ``alice (uid 1000)``."""
    try:
        return f"{pwd.getpwuid(uid).pw_name} (uid {uid})"
    except KeyError:
        return f"uid {uid} (no user name)"


def me_words() -> str:
    """The effective user in words."""
    return owner_words(os.geteuid())


def _mode(st: os.stat_result) -> str:
    return f"{stat.S_IMODE(st.st_mode):04o}"


def private_dir_problem(path: str, st: os.stat_result) -> str | None:
    """Why a folder (its ``lstat``) is not a private folder of this user,
    or None when it is: a directory, not a symbolic link, owned by the
    effective user, that no one else may enter (mode 0700)."""
    if stat.S_ISLNK(st.st_mode):
        return "it is a symbolic link"
    if not stat.S_ISDIR(st.st_mode):
        return "it is not a directory"
    if st.st_uid != os.geteuid():
        return f"it is not owned by this user, {me_words()}"
    if stat.S_IMODE(st.st_mode) & 0o077:
        return f"its mode is {_mode(st)}, not 0700"
    return None


def _is_private_dir(path: str) -> bool:
    try:
        return private_dir_problem(path, os.lstat(path)) is None
    except OSError:
        return False


def runtime_dir() -> str:
    """The private folder of this user's HAL sockets, made if needed.

    ``$HALSDK_RUNTIME_DIR`` when set; else ``$XDG_RUNTIME_DIR/halsdk`` when
    ``$XDG_RUNTIME_DIR`` is a private folder of this user (a directory it
    owns, mode 0700); else ``/tmp/halsdk-<uid>``.  The folder must be a
    directory of the effective user of mode 0700 and not a symbolic link:
    anything else raises :class:`TrustError` naming the folder and its
    owner (another user may have made it first, to block or to spy on this
    user's HAL)."""
    override = os.environ.get("HALSDK_RUNTIME_DIR")
    xdg = os.environ.get("XDG_RUNTIME_DIR")
    if override:
        path = os.path.abspath(override)
    elif xdg and os.path.isabs(xdg) and _is_private_dir(xdg):
        path = os.path.join(xdg, "halsdk")
    else:
        path = os.path.join(FALLBACK_BASE, f"halsdk-{os.getuid()}")
    try:
        os.mkdir(path, 0o700)
    except FileExistsError:
        pass
    except OSError as exc:
        raise InstanceError(
            f"cannot make the HAL runtime folder {path}: "
            f"{exc.strerror or exc}; {_FIX}") from None
    try:
        st = os.lstat(path)
    except OSError as exc:
        raise InstanceError(
            f"cannot inspect the HAL runtime folder {path}: "
            f"{exc.strerror or exc}") from None
    why = private_dir_problem(path, st)
    if why is not None:
        if st.st_uid == os.geteuid() and stat.S_ISDIR(st.st_mode):
            fix = f"make it private (chmod 700 {path}) or {_FIX}"
        else:
            fix = (f"remove it (as its owner or root: rm -r {path}) or "
                   f"{_FIX}")
        raise TrustError(
            f"refusing the HAL runtime folder {path} (owner "
            f"{owner_words(st.st_uid)}): {why}; another user may have made "
            f"it to block or spy on this user's HAL; {fix}")
    return path


def socket_problem(st: os.stat_result) -> str | None:
    """Why a file (its ``lstat``) is not a socket this user may trust, or
    None: a socket, not a symbolic link, owned by the effective user."""
    if stat.S_ISLNK(st.st_mode):
        return "it is a symbolic link"
    if not stat.S_ISSOCK(st.st_mode):
        return "it is not a socket"
    if st.st_uid != os.geteuid():
        return f"it is not owned by this user, {me_words()}"
    return None


def check_socket(path: str) -> None:
    """Refuse (TrustError) a file at ``path`` that is not a socket of this
    user; nothing there is left to the caller (connect or bind says)."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise InstanceError(f"cannot inspect the HAL socket {path}: "
                            f"{exc.strerror or exc}") from None
    why = socket_problem(st)
    if why is not None:
        raise TrustError(
            f"refusing the HAL socket {path} (owner "
            f"{owner_words(st.st_uid)}): {why}; remove it by hand if no "
            "HAL of yours uses it")
