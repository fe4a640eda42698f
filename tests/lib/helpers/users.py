"""Another local user, for the trust tests: files given to a uid that
no account has (only root can give them)."""

from __future__ import annotations

import os
import pwd

import pytest

needs_root = pytest.mark.skipif(os.geteuid() != 0,
                                reason="giving files to another user "
                                       "needs root")


def unused_uid() -> int:
    for uid in range(12345, 12445):
        try:
            pwd.getpwuid(uid)
        except KeyError:
            return uid
    raise RuntimeError("no unused uid in 12345..12444")


OTHER = unused_uid()
