"""Writing files so that a failure never leaves a half-written one (:func:`write_atomic`, used by
every writer: result files, pictures, pages; re-exported by :mod:`softarm.io`)."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from pathlib import Path

__all__ = ["write_atomic"]


@contextlib.contextmanager
def write_atomic(path: str | os.PathLike, mode: str = "w"):
    """Open a temporary file beside ``path``; rename it to ``path`` only if the block succeeds.

    A failure (a full disk, a file-size limit, an interrupt) removes the temporary file and
    leaves any old ``path`` as it was. A symbolic link as ``path`` is written through: its
    target is replaced and the link kept. A folder as ``path`` is an IsADirectoryError before
    anything is written.
    """
    path = Path(path)
    if path.is_symlink():  # write through the link (to its final target)
        path = Path(os.path.realpath(path))
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a folder, not a file", str(path))
    try:
        handle, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                                       dir=path.parent if str(path.parent) else ".")
    except OSError as error:  # e.g. a read-only folder: name the file asked for
        raise OSError(error.errno, error.strerror, str(path)) from None
    try:
        # mkstemp makes the file private (0600); give it the permissions of a normal new file
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        with os.fdopen(handle, mode, **({"newline": ""} if "b" not in mode else {})) as stream:
            yield stream
        os.replace(tmp, path)
    except OSError as error:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if error.filename is None and error.errno is not None:  # name the file being written
            raise OSError(error.errno, error.strerror, str(path)) from None
        raise
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
