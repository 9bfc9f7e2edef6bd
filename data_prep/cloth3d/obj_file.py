"""The two OBJ operations the CLOTH3D layout needs beyond ``gnngarment.geometry.load_mesh``.

Reading goes through :func:`gnngarment.geometry.load_mesh` (file order kept, quads
split ``(0, 1, 2), (0, 2, 3)``), so CLOTH3D and our own files take the same path.
"""

from __future__ import annotations

import io
import re
from pathlib import Path
from typing import BinaryIO

import numpy as np

from gnngarment.geometry.files import atomic_write

# A vertex line as gnngarment's OBJ reader sees one: first word exactly "v".
_VERTEX_LINE = re.compile(rb"^[ \t]*v[ \t]", re.MULTILINE)


def count_obj_vertices(path: str | Path) -> int:
    """Number of ``v`` lines in an OBJ, without parsing numbers (cheap dataset scans).

    Raises:
        OSError: the file cannot be read.
    """
    return len(_VERTEX_LINE.findall(Path(path).read_bytes()))


def write_obj(path: str | Path, pos: np.ndarray, faces: np.ndarray) -> Path:
    """Write a triangle mesh as OBJ (``v`` and 1-based ``f`` lines only), atomically.

    Vertex order is kept, nothing is welded. Coordinates get 9 significant digits,
    enough to give float32 values back exactly.

    Shapes:
        pos ``(N, 3)`` metres, faces ``(F, 3)`` indices into ``pos``.

    Raises:
        ValueError: wrong shapes, non-finite positions or face indices out of range.
    """
    path = Path(path)
    pos = np.asarray(pos, dtype=np.float64)
    faces = np.asarray(faces)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"{path}: pos has shape {pos.shape}, expected (N, 3)")
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"{path}: faces have shape {faces.shape} and dtype {faces.dtype}, "
                         f"expected (F, 3) integers")
    if not np.isfinite(pos).all():
        raise ValueError(f"{path}: pos contains NaN or inf")
    if faces.size and (faces.min() < 0 or faces.max() >= len(pos)):
        raise ValueError(f"{path}: face indices span [{faces.min()}, {faces.max()}], "
                         f"outside [0, {len(pos) - 1}]")

    def write(stream: BinaryIO) -> None:
        text = io.StringIO()
        np.savetxt(text, pos, fmt="v %.9g %.9g %.9g")
        np.savetxt(text, faces.astype(np.int64) + 1, fmt="f %d %d %d")
        stream.write(text.getvalue().encode("ascii"))

    return atomic_write(path, write)
