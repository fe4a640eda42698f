"""halsdk.atomicfile.write_atomic: a file is replaced whole or not at
all, keeps its permissions, and can keep a backup."""

from __future__ import annotations

import os
import stat

import pytest

from halsdk.atomicfile import write_atomic


def mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def test_replaces_keeping_the_mode_and_a_backup(tmp_path):
    path = tmp_path / "tool.tbl"
    path.write_text("old\n")
    os.chmod(path, 0o640)
    write_atomic(str(path), "new\n", backup=True)
    assert path.read_text() == "new\n"
    assert mode(path) == 0o640
    assert (tmp_path / "tool.tbl.bak").read_text() == "old\n"
    assert sorted(os.listdir(tmp_path)) == ["tool.tbl", "tool.tbl.bak"]


def test_a_new_file_gets_the_usual_permissions(tmp_path):
    umask = os.umask(0o022)
    try:
        write_atomic(str(tmp_path / "x.png"), b"\x89PNG")
    finally:
        os.umask(umask)
    assert mode(tmp_path / "x.png") == 0o644
    assert (tmp_path / "x.png").read_bytes() == b"\x89PNG"


def test_a_failed_write_leaves_the_old_file_and_no_temporary(
        tmp_path, monkeypatch):
    path = tmp_path / "m.var"
    path.write_text("5221 1\n")

    def full(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(OSError, match="No space"):
        write_atomic(str(path), "5221 2\n", backup=True)
    assert path.read_text() == "5221 1\n"
    assert os.listdir(tmp_path) == ["m.var"]
