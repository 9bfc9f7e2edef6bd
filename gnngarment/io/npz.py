"""``.npz`` files: written atomically, read with errors that name the file. Shared by
every cache of the library (prepared cache, pooling hierarchies, attribution results)."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from gnngarment.io.atomic import atomic_write


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
