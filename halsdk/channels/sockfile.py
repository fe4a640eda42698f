"""The trust check of the command channel's socket file, made by the
server before it replaces a stale socket and by a client before it
connects: the file must be a socket (not a symbolic link) of the effective
user, so that a process never talks to a socket that another local user
planted (the folder it lies in is checked by the public layer:
``Hal.private_socket_path``)."""

from __future__ import annotations

import os
import pwd
import stat
from typing import Optional


def owner_words(uid: int) -> str:
    """A file owner in words: ``alice (uid 1000)``."""
    try:
        return f"{pwd.getpwuid(uid).pw_name} (uid {uid})"
    except KeyError:
        return f"uid {uid} (no user name)"


def refusal(path: str) -> Optional[str]:
    """Why the file at ``path`` is not a socket this user may trust, with
    its owner, or None (also when nothing is there)."""
    try:
        st = os.lstat(path)
    except OSError:
        return None
    if stat.S_ISLNK(st.st_mode):
        why = "it is a symbolic link"
    elif not stat.S_ISSOCK(st.st_mode):
        why = "it is not a socket"
    elif st.st_uid != os.geteuid():
        why = (f"it is not owned by this user, "
               f"{owner_words(os.geteuid())}")
    else:
        return None
    return (f"refusing the socket {path} (owner {owner_words(st.st_uid)}): "
            f"{why}; remove it by hand if no machine of yours uses it")
