"""Atomic writes: a file is written to a hidden temporary beside it, fsynced and renamed
over, so a reader sees the old file or the complete new one, never a truncated one; and
:class:`FolderLock`, one run at a time per output folder. Caches, checkpoints, exports
and reports are written through :func:`atomic_write`."""

from __future__ import annotations

import contextlib
import os
import re
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
    _record_temporary(temp)
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


#: The name of a temporary file :func:`atomic_write` makes: ``.<name>.<8 hex>.tmp``.
TEMP_NAME = re.compile(r"^\..+\.[0-9a-f]{8}" + re.escape(TEMP_SUFFIX) + r"$")


#: The locks this process holds, by resolved folder: a temporary made inside one is
#: recorded in its lock file before it exists, so that after a kill -9 the next run
#: removes what this run made, and nothing else.
_HELD: dict[Path, FolderLock] = {}


def _record_temporary(temp: Path) -> None:
    resolved = temp.parent.resolve() / temp.name
    for folder, lock in _HELD.items():
        if resolved.is_relative_to(folder):
            lock.record(resolved.relative_to(folder))
            return


class FolderBusyError(OSError):
    """Another process holds the output folder's lock (the message names it)."""


class FolderLock:
    """An exclusive, advisory lock on an output folder for the life of a run.

    A second run into the same folder is refused at once (its message names the holder's
    pid) instead of interleaving its files with the first one's. The lock is a
    ``.lock`` file's ``flock``: the kernel releases it when the holder dies, even by
    kill -9, so a stale lock never blocks the next run.

    Use as a context manager; :meth:`remove_stale_temporaries` is safe only while held.
    While it is held, every temporary :func:`atomic_write` makes in the folder (or below
    it) is recorded in the lock file before it is created; the next holder removes
    exactly those a killed run left, never a file of the same look that this library
    did not make (a user's, or one reached through a symlink).
    """

    def __init__(self, folder: str | Path, what: str = "run") -> None:
        self.folder = Path(folder)
        self.what = what
        self._stream: BinaryIO | None = None

    def __enter__(self) -> FolderLock:
        import fcntl

        self.folder.mkdir(parents=True, exist_ok=True)
        path = self.folder / ".lock"
        stream = open(path, "a+b")
        try:
            fcntl.flock(stream.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            stream.seek(0)
            first = stream.read().decode(errors="replace").strip().splitlines()[:1]
            holder = first[0] if first else "another process"
            stream.close()
            raise FolderBusyError(f"{self.folder}: another {self.what} ({holder}) is writing "
                                  "here; wait for it to finish or choose another output "
                                  "folder") from None
        stream.seek(0)
        self._stale = [line[len("temp "):] for line in
                       stream.read().decode(errors="replace").splitlines()
                       if line.startswith("temp ")]
        stream.seek(0)
        stream.truncate()
        stream.write(f"pid {os.getpid()}\n".encode())
        stream.flush()
        self._stream = stream
        self._resolved = self.folder.resolve()
        _HELD[self._resolved] = self
        return self

    def __exit__(self, *exc_info: object) -> None:
        if self._stream is not None:
            _HELD.pop(self._resolved, None)
            # Every temporary of this run is renamed or removed by now (atomic_write's
            # own cleanup): the record is of no further use.
            self._stream.seek(0)
            self._stream.truncate()
            self._stream.write(f"pid {os.getpid()}\n".encode())
            self._stream.close()  # closing releases the flock
            self._stream = None

    def record(self, relative: Path) -> None:
        """Note a temporary (relative to the folder) before it is created."""
        if self._stream is not None:
            self._stream.seek(0, os.SEEK_END)
            self._stream.write(f"temp {relative.as_posix()}\n".encode())
            # Flushed to the kernel, which keeps it when the process is killed (no fsync:
            # a power cut loses the temporaries' data too, and readers ignore them).
            self._stream.flush()

    def remove_stale_temporaries(self, subfolders: tuple[str, ...]) -> int:
        """Delete the temporary files a killed earlier run of this library recorded in
        the lock file, in ``subfolders`` (``"."``: the folder itself, not below; others
        recursively). Only a regular file (not a symlink) inside the resolved folder whose
        name :func:`atomic_write` makes; any other file, hidden or not, is the user's and
        stays. Returns how many were removed."""
        if self._stream is None:
            raise RuntimeError("remove_stale_temporaries needs the lock held")
        removed = 0
        for relative in self._stale:
            parts = Path(relative).parts
            inside = any((name == "." and len(parts) == 1) or
                         (name != "." and len(parts) > 1 and parts[0] == name)
                         for name in subfolders)
            if not inside or ".." in parts or Path(relative).is_absolute():
                continue
            path = self._resolved / relative
            if (TEMP_NAME.match(path.name) and not path.is_symlink() and path.is_file()
                    and path.parent.resolve().is_relative_to(self._resolved)):
                path.unlink(missing_ok=True)
                removed += 1
        return removed
