"""Issue 19: ``halrun -U`` and files it must not trust.

Another local user can put junk under this user's instance names in
/dev/shm (or a link, or a folder in the socket folder's place).  ``halrun
-U`` names each such file with its owner, leaves it in place, removes what
is really its own, and ends with status 1; never a ``PermissionError``
traceback.  Another user is played by an unused uid (root may give files
away); every file made here is removed at the end.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.users import OTHER, needs_root

import halsdk

BIN = Path(sys.executable).parent
SHM_DIR = "/dev/shm"



def halrun(args: list[str], cwd: Path,
           **env: str) -> subprocess.CompletedProcess:
    program = BIN / "halrun"
    if not program.exists():
        pytest.skip(f"halrun is not installed next to {sys.executable}")
    return subprocess.run([str(program), *args], cwd=cwd,
                          env=dict(os.environ, **env), capture_output=True,
                          text=True, timeout=60)


def segment(name: str) -> str:
    return SHM_DIR + halsdk.core.instance.shm_name(name)


@needs_root
def test_halrun_U_names_foreign_files_and_removes_its_own(tmp_path):
    tag = f"trustU-{os.getpid()}"
    foreign, link, own = (segment(f"{tag}-foreign"), segment(f"{tag}-link"),
                          segment(f"{tag}-own"))
    made = [foreign, link, own]
    try:
        for path, uid in ((foreign, OTHER), (own, os.geteuid())):
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            os.write(fd, b"junk\n" * 100)
            os.fchown(fd, uid, -1)
            os.close(fd)
        os.symlink(foreign, link)
        # its own junk is old (not an instance being created): removed;
        # the others stay young, so that a concurrent test run of an older
        # halsdk (which removed any old junk) leaves them alone
        past = time.time() - 60
        os.utime(own, (past, past))
        proc = halrun(["-U"], tmp_path)
        text = proc.stdout + proc.stderr
        assert proc.returncode == 1, text
        assert "Traceback" not in text, text
        assert f"{foreign} (owner uid {OTHER} (no user name)): it is not " \
               "owned by this user" in proc.stderr
        assert f"{link} (owner " in proc.stderr
        assert "symbolic link" in proc.stderr
        assert os.path.lexists(foreign) and os.path.lexists(link)
        assert not os.path.lexists(own)     # its own dead junk: removed
    finally:
        for path in made:
            try:
                os.unlink(path)
            except FileNotFoundError:
                pass


@needs_root
def test_halrun_U_names_a_foreign_runtime_folder(tmp_path):
    folder = tmp_path / "rt"
    folder.mkdir(mode=0o700)
    os.chown(folder, OTHER, -1)
    try:
        proc = halrun(["-U"], tmp_path, HALSDK_RUNTIME_DIR=str(folder))
        text = proc.stdout + proc.stderr
        assert proc.returncode == 1, text
        assert "Traceback" not in text, text
        assert f"refusing the HAL runtime folder {folder} (owner uid " \
               f"{OTHER} (no user name)): it is not owned by this user" \
               in proc.stderr
        assert "XDG_RUNTIME_DIR" in proc.stderr
    finally:
        os.chown(folder, os.geteuid(), -1)


def test_halrun_U_is_quiet_and_0_when_all_is_well(tmp_path):
    rt = tmp_path / "rt"
    proc = halrun(["-U"], tmp_path, HALSDK_RUNTIME_DIR=str(rt))
    # other test runs may leave foreign files meanwhile; none of ours
    assert "Traceback" not in proc.stderr
    assert str(rt) not in proc.stderr
    if proc.returncode == 0:
        assert proc.stderr == ""
