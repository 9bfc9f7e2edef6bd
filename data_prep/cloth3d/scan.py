"""Find the usable sequences of a CLOTH3D download without reading payloads."""

from __future__ import annotations

from pathlib import Path

from data_prep.cloth3d.errors import Cloth3DError
from data_prep.cloth3d.sequence import INFO_FILE, inspect_sequence


def scan_dataset(root: str | Path) -> tuple[list[Path], list[tuple[Path, str]]]:
    """Check every sequence folder directly under ``root``.

    Each folder goes through :func:`~data_prep.cloth3d.sequence.inspect_sequence`:
    ``info.mat`` is loaded (it is small), caches are checked by header and file size,
    OBJs by vertex count; payloads and faces are not read, so
    :func:`~data_prep.cloth3d.sequence.read_sequence` can still fail on a folder listed
    as good (e.g. a malformed face line) and callers should catch :class:`Cloth3DError`.

    Args:
        root: folder whose subfolders are sequences (CLOTH3D's ``train/``, ``val/``,
            ``test/``); hidden folders are skipped.

    Returns:
        ``(good, bad)``: sorted good sequence folders, and ``(folder, message)`` for each
        bad one, the message naming the file and the problem.

    Raises:
        Cloth3DError: ``root`` is missing, or is itself a sequence folder.
    """
    root = Path(root)
    if not root.is_dir():
        raise Cloth3DError(f"{root}: dataset folder not found")
    if (root / INFO_FILE).is_file():
        raise Cloth3DError(f"{root}: holds {INFO_FILE}, so it is a sequence folder; "
                           f"scan its parent, or read it with read_sequence")
    good: list[Path] = []
    bad: list[tuple[Path, str]] = []
    for folder in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")):
        try:
            inspect_sequence(folder)
        except Cloth3DError as error:
            bad.append((folder, str(error)))
        else:
            good.append(folder)
    return good, bad
