"""Writing a file as a whole or not at all.

Machine files (the tool table, the parameter file) are rewritten while a
machine runs; a crash or a full disk in the middle must not leave half a
file.  :func:`write_atomic` writes a temporary file in the same folder,
flushes it to disk and renames it over the old one, which is atomic on
POSIX file systems.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from typing import Union


def write_atomic(path: str, data: Union[str, bytes], *,
                 backup: bool = False) -> None:
    """Write ``data`` (text as UTF-8) to ``path`` atomically.

    The new file keeps the permissions of the file it replaces (a new file
    gets the usual ones: 0666 less the umask).  With ``backup`` the old
    file is kept as ``path.bak``.  On any error the temporary file is
    removed and ``path`` is left as it was.
    """
    folder = os.path.dirname(os.path.abspath(path))
    name = os.path.basename(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", dir=folder)
    try:
        with os.fdopen(fd, "wb") as stream:
            stream.write(data.encode("utf-8") if isinstance(data, str)
                         else data)
            stream.flush()
            os.fsync(stream.fileno())
        if os.path.exists(path):
            shutil.copymode(path, tmp)
            if backup:
                shutil.copyfile(path, path + ".bak")
        else:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
