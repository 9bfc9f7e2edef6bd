"""Is an output folder usable? Checked before a long run, leaving nothing behind."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from gnngarment.io.atomic import FolderLock


def check_output_folder(out: str | Path, what: str = "export") -> None:
    """Before any work: ``out`` is a folder or can be made one, files can be written in
    it, and no other ``what`` holds its :class:`FolderLock`.

    Creates nothing and leaves nothing behind (a refused run must not leave an empty
    folder or a lock file): the run makes the folder when it writes. A run that takes
    the lock itself at once needs only :func:`check_writable_folder`.

    Raises:
        OSError: why not (:class:`~gnngarment.io.atomic.FolderBusyError` when
            another run holds the folder).
    """
    out = Path(out)
    check_writable_folder(out)
    if (out / ".lock").is_file():
        # Only a folder with a lock file can be held; taking it rewrites only that file.
        with FolderLock(out, what):
            pass


def check_writable_folder(out: str | Path) -> None:
    """``out`` is a folder or can be made one, and files can be written in it; creates
    nothing and leaves nothing behind.

    Raises:
        OSError: why not (a file in the way, no permission).
    """
    out = Path(out)
    existing = out
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent  # the folder that the run's mkdir would start from
    if not existing.is_dir():
        raise NotADirectoryError(f"{existing} is a file, not a folder")
    # A probe folder made and removed at once: os.access says yes to root on /proc.
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".probe-", dir=existing))
    except OSError as error:
        raise PermissionError(f"cannot write in {existing} ({error.strerror})") from None


def check_outputs_spare_inputs(files: list[Path], folders: list[Path],
                               inputs: list[Path]) -> None:
    """Before any work: no output file is (or, through symlinks, resolves to) one of the
    command's input files, and no input lies inside an output folder whose contents the
    command replaces — a user's garment must never be overwritten by its own result.

    Raises:
        ValueError: naming the input and the output that would overwrite it.
    """
    for given in inputs:
        if not given.is_file():
            continue
        source = given.resolve()
        for output in files:
            target = output.resolve()
            if target == source or (output.exists() and os.path.samefile(output, given)):
                raise ValueError(f"{given}: the output {output} would overwrite (or remove) "
                                 "this input (choose another --out folder)")
        for folder in folders:
            if source.is_relative_to(folder.resolve()):
                raise ValueError(f"{given}: this input lies in {folder}, whose files the "
                                 "export replaces (choose another --out folder)")
