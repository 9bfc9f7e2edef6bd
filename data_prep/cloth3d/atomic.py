"""Write a file so readers see either the old content or the new, never a torn one."""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

#: Suffix of in-progress files; a crash can leave one behind, readers ignore them.
TEMP_SUFFIX = ".tmp"


def atomic_write(path: str | Path, write: Callable[[BinaryIO], None]) -> Path:
    """Call ``write(stream)`` on a temporary file beside ``path``, then rename it over.

    The temporary file lives in the same folder, so :func:`os.replace` is a rename
    within one file system, which POSIX and Windows make atomic. If ``write`` raises
    (or the process is interrupted before the rename) the previous ``path``, if any, is
    untouched and the temporary file is removed.

    Args:
        path: destination file; its folder must exist.
        write: fills the binary stream it is given.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.
    """
    path = Path(path)
    # A hidden name with our suffix: scans and globs over "*.pc16" never pick it up.
    temp = path.with_name(f".{path.name}.{secrets.token_hex(4)}{TEMP_SUFFIX}")
    # os.open with 0o666 lets the umask decide permissions, like a plain open() would
    # (tempfile's 0o600 would make shared datasets unreadable to others).
    descriptor = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0),
                         0o666)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            write(stream)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temp)
        raise
    return path
