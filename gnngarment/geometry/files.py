"""Atomic ``.npz`` files: written to a temporary file and renamed, read with errors
that name the file. Shared by every cache of the library."""

from __future__ import annotations

import contextlib
import os
import secrets
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

import numpy as np

#: Suffix of in-progress files; a crash can leave one behind, readers ignore them.
TEMP_SUFFIX = ".tmp"


def atomic_write(path: str | Path, write: Callable[[BinaryIO], None]) -> Path:
    """Call ``write(stream)`` on a temporary file beside ``path``, then rename it over.

    The temporary file lives in the same folder, so :func:`os.replace` is a rename
    within one file system, which POSIX and Windows make atomic. If ``write`` raises
    (or the process is killed before the rename) the previous ``path``, if any, is
    untouched and the temporary file is removed (or, after kill -9, left under a hidden
    ``.tmp`` name that no reader looks at).

    Args:
        path: destination file; missing parent folders are created.
        write: fills the binary stream it is given.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # A hidden name with our suffix: globs over "*.npz", "*.obj" or "*.pc2" never see it.
    temp = path.with_name(f".{path.name}.{secrets.token_hex(4)}{TEMP_SUFFIX}")
    # os.open with 0o666 lets the umask decide permissions, like a plain open() would
    # (tempfile's 0o600 would make shared outputs unreadable to others).
    descriptor = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0),
                         0o666)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            write(stream)
            stream.flush()
            os.fsync(stream.fileno())
        if path.exists():  # replacing a file keeps its permissions, as an in-place write would
            os.chmod(temp, path.stat().st_mode & 0o777)
        os.replace(temp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temp)
        raise
    return path


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_write`)."""
    return atomic_write(path, lambda stream: stream.write(data))


def save_npz_atomic(path: str | Path, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` to ``path`` so that readers see the old file or the complete
    new one, never a truncated file."""
    atomic_write(path, lambda stream: np.savez(stream, **arrays))


def load_npz(path: str | Path, required: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
    """Read every array of an ``.npz`` into memory.

    Raises:
        ValueError: missing, truncated or corrupt file, or a ``required`` key absent;
            the message names the file.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
    except (OSError, EOFError, ValueError, KeyError, zipfile.BadZipFile) as error:
        raise ValueError(f"{path}: truncated or corrupt file ({error})") from error
    missing = [key for key in required if key not in arrays]
    if missing:
        raise ValueError(f"{path}: missing arrays {missing}")
    return arrays
